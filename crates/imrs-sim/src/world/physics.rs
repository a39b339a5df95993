//! The rapier world: kinematic arm links, pallets, and the fixed feeder-zone sensor.
//!
//! Nothing here is dynamic: every body is placed by the simulation, and rapier's broad and
//! narrow phases say what overlaps what.

use rapier3d::prelude::*;

use crate::layout::{ARM_Z, LINK_RADIUS, PALLET_HALF, ZONE_CENTRE, ZONE_HALF};
use crate::scene::{BoxPose, LinkPose};

/// Arm links collide with each other and are seen by the zone sensor; pallets with nothing.
const ARMS: Group = Group::GROUP_1;
const ZONE: Group = Group::GROUP_2;

pub(crate) struct Physics {
    world: PhysicsWorld,
    zone: ColliderHandle,
}

impl Physics {
    pub(crate) fn new() -> Self {
        let mut world = PhysicsWorld::new();
        // For `detect`: nothing falls, and contacts are exact.
        world.gravity = Vector::ZERO;
        // The broad phase's tree holds a dozen leaves (the arm links and the zone): its
        // incremental re-balancing, which keeps queries fast in trees of thousands, cost
        // more here than every query it could speed up. Without it the tree stays exact,
        // only less balanced.
        world.broad_phase =
            BroadPhaseBvh::with_optimization_strategy(BvhOptimizationStrategy::None);
        world.integration_parameters.normalized_prediction_distance = 0.0;
        let zone = world.colliders.insert(
            ColliderBuilder::cuboid(ZONE_HALF[0], ZONE_HALF[1], ZONE_HALF[2])
                .translation(Vector::new(ZONE_CENTRE[0], ZONE_CENTRE[1], ZONE_HALF[2]))
                .sensor(true)
                .collision_groups(InteractionGroups::new(ZONE, ARMS, InteractionTestMode::And))
                .active_events(ActiveEvents::COLLISION_EVENTS)
                .active_collision_types(
                    ActiveCollisionTypes::default() | ActiveCollisionTypes::FIXED_FIXED,
                ),
        );
        Self { world, zone }
    }

    /// A capsule of length `length` lying along its x axis: one link of an arm.
    ///
    /// A collider with no body, placed by [`Physics::place_link`]: nothing here is dynamic,
    /// so a body would only give rapier's solver work (integrating its velocity from each
    /// new pose) that the detection does not use. Parentless colliders count as fixed, so
    /// the fixed-fixed pairs are switched on for the links.
    pub(crate) fn add_link(&mut self, length: f32) -> ColliderHandle {
        self.world.colliders.insert(
            ColliderBuilder::capsule_x(length / 2.0, LINK_RADIUS)
                .collision_groups(InteractionGroups::new(
                    ARMS,
                    ARMS | ZONE,
                    InteractionTestMode::And,
                ))
                .active_collision_types(
                    ActiveCollisionTypes::default() | ActiveCollisionTypes::FIXED_FIXED,
                ),
        )
    }

    /// A pallet: a collider of its own, with no body, which takes part in no collision.
    ///
    /// Not a kinematic body, and disabled: the pallets outnumber the arm links several times,
    /// and as moving bodies (integrated by the solver) or enabled colliders (refitted in the
    /// broad phase at every step) they made most of the chip cell's simulation time, for
    /// pairs the collision groups then threw away. A disabled collider stays in the world
    /// with its shape and pose, for whoever draws the scene, and costs the steps nothing.
    pub(crate) fn add_pallet(&mut self, at: [f32; 3]) -> ColliderHandle {
        self.world.colliders.insert(
            ColliderBuilder::cuboid(PALLET_HALF[0], PALLET_HALF[1], PALLET_HALF[2])
                .translation(Vector::new(at[0], at[1], at[2]))
                .collision_groups(InteractionGroups::none())
                .enabled(false),
        )
    }

    pub(crate) fn remove_pallet(&mut self, pallet: ColliderHandle) {
        let world = &mut self.world;
        world.colliders.remove(
            pallet,
            &mut world.islands,
            &mut world.bodies,
            &mut world.soft_bodies,
            false,
        );
    }

    /// Places a link between two points of the arms' plane.
    pub(crate) fn place_link(&mut self, link: ColliderHandle, from: [f32; 2], to: [f32; 2]) {
        let middle = Vector::new((from[0] + to[0]) / 2.0, (from[1] + to[1]) / 2.0, ARM_Z);
        let angle = (to[1] - from[1]).atan2(to[0] - from[0]);
        let pose = Pose::from_parts(middle, Rotation::from_rotation_z(angle));
        self.world.colliders[link].set_position(pose);
    }

    pub(crate) fn place_pallet(&mut self, pallet: ColliderHandle, at: [f32; 3]) {
        self.world.colliders[pallet].set_translation(Vector::new(at[0], at[1], at[2]));
    }

    /// Where rapier has a link: its pose and its capsule.
    pub(crate) fn link_pose(&self, link: ColliderHandle) -> LinkPose {
        let collider = &self.world.colliders[link];
        let (at, rotation) = (collider.translation(), collider.rotation());
        // A link turns only about z: its x axis, rotated, gives the turn.
        let axis = rotation * Vector::X;
        let (half, radius) = collider.shape().as_capsule().map_or((0.0, 0.0), |capsule| {
            (capsule.half_height(), capsule.radius)
        });
        LinkPose {
            centre: [at.x, at.y, at.z],
            yaw: axis.y.atan2(axis.x),
            length: 2.0 * half,
            radius,
        }
    }

    /// The feeder zone's box, as the sensor has it.
    pub(crate) fn zone_box(&self) -> BoxPose {
        let zone = &self.world.colliders[self.zone];
        let at = zone.translation();
        let half = zone
            .shape()
            .as_cuboid()
            .map_or(Vector::ZERO, |cuboid| cuboid.half_extents);
        BoxPose {
            centre: [at.x, at.y, at.z],
            half: [half.x, half.y, half.z],
        }
    }

    pub(crate) fn position_of(&self, pallet: ColliderHandle) -> [f32; 3] {
        let at = self.world.colliders[pallet].translation();
        [at.x, at.y, at.z]
    }

    /// Runs collision detection for the colliders as they are placed now.
    ///
    /// Through the physics pipeline, not the collision-only one: rapier 0.36's collision-only
    /// pipeline appends the contact pairs of every moved collider to a list that only the
    /// physics pipeline's graph maintenance drains (about 2 MB per simulated hour of the chip
    /// cell, for ever). The world holds no bodies, only colliders placed by `set_position`,
    /// so a physics step moves nothing: it runs the broad and narrow phases, as the
    /// collision-only step did (the chip cell's reports are byte for byte the same).
    pub(crate) fn detect(&mut self) {
        self.world.step();
    }

    /// Whether `collider` overlaps the feeder zone.
    /// How far apart two colliders are (0 when they touch), by parry3d.
    pub(crate) fn distance(&self, a: ColliderHandle, b: ColliderHandle) -> f32 {
        let (a, b) = (&self.world.colliders[a], &self.world.colliders[b]);
        rapier3d::parry::query::distance(a.position(), a.shape(), b.position(), b.shape())
            .map_or(0.0, |d| d.distance)
    }

    pub(crate) fn in_zone(&self, collider: ColliderHandle) -> bool {
        self.world
            .narrow_phase
            .intersection_pair(self.zone, collider)
            == Some(true)
    }

    /// Where two colliders touch or overlap, if they do.
    pub(crate) fn touching(&self, a: ColliderHandle, b: ColliderHandle) -> Option<[f32; 3]> {
        let pair = self.world.narrow_phase.contact_pair(a, b)?;
        let (_, contact) = pair.find_deepest_contact()?;
        if contact.dist > 0.0 {
            return None;
        }
        let point = self.world.colliders[pair.collider1]
            .position()
            .transform_point(contact.local_p1);
        Some([point.x, point.y, point.z])
    }
}
