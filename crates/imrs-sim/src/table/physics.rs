//! The table's rapier world: the arms' links, a gripper ball at each tool, the zones as
//! sensors, and the tool.
//!
//! As in the chip cell's world, every collider is placed by the simulation and nothing is
//! dynamic: rapier's broad and narrow phases say which links touch and which grippers are in
//! which zone.

use nalgebra::{Isometry3, Point2, Point3};
use rapier3d::parry::query;
use rapier3d::prelude::*;

use crate::scara::link_pose;

/// Links touch links; grippers are seen by the zones.
const LINKS: Group = Group::GROUP_1;
const GRIPPERS: Group = Group::GROUP_2;
const ZONES: Group = Group::GROUP_3;

/// The radius of a link's capsule.
pub const LINK_RADIUS: f32 = 0.035;
/// The radius of the gripper's ball, at the tool's point.
pub const GRIPPER_RADIUS: f32 = 0.02;
/// The height of the arms' working plane.
pub const WORK_Z: f32 = 0.3;

pub(crate) struct TablePhysics {
    world: PhysicsWorld,
}

fn to_rapier(pose: &Isometry3<f32>) -> Pose {
    let (t, q) = (pose.translation.vector, pose.rotation.quaternion());
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

fn fixed_fixed() -> ActiveCollisionTypes {
    ActiveCollisionTypes::default() | ActiveCollisionTypes::FIXED_FIXED
}

impl TablePhysics {
    pub(crate) fn new() -> Self {
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::ZERO;
        world.integration_parameters.normalized_prediction_distance = 0.0;
        Self { world }
    }

    /// A link of `length`: a capsule along its x axis.
    pub(crate) fn add_link(&mut self, length: f32) -> ColliderHandle {
        self.world.colliders.insert(
            ColliderBuilder::capsule_x(length / 2.0, LINK_RADIUS)
                .collision_groups(InteractionGroups::new(
                    LINKS,
                    LINKS,
                    InteractionTestMode::And,
                ))
                .active_collision_types(fixed_fixed()),
        )
    }

    /// The gripper: a ball at the tool's point.
    pub(crate) fn add_gripper(&mut self) -> ColliderHandle {
        self.world.colliders.insert(
            ColliderBuilder::ball(GRIPPER_RADIUS)
                .sensor(true)
                .collision_groups(InteractionGroups::new(
                    GRIPPERS,
                    ZONES,
                    InteractionTestMode::And,
                ))
                .active_collision_types(fixed_fixed()),
        )
    }

    /// A zone: a box sensor centred at `centre` with half extents `half`.
    pub(crate) fn add_zone(&mut self, centre: Point3<f32>, half: [f32; 3]) -> ColliderHandle {
        self.world.colliders.insert(
            ColliderBuilder::cuboid(half[0], half[1], half[2])
                .translation(Vector::new(centre.x, centre.y, centre.z))
                .sensor(true)
                .collision_groups(InteractionGroups::new(
                    ZONES,
                    GRIPPERS,
                    InteractionTestMode::And,
                ))
                .active_collision_types(fixed_fixed()),
        )
    }

    /// The tool: a small ball that takes part in no collision, placed where it lies.
    pub(crate) fn add_tool(&mut self, at: Point2<f32>) -> ColliderHandle {
        self.world.colliders.insert(
            ColliderBuilder::ball(0.015)
                .translation(Vector::new(at.x, at.y, WORK_Z))
                .collision_groups(InteractionGroups::none()),
        )
    }

    pub(crate) fn place_link(
        &mut self,
        link: ColliderHandle,
        from: &Point2<f32>,
        to: &Point2<f32>,
    ) {
        self.world.colliders[link].set_position(to_rapier(&link_pose(from, to, WORK_Z)));
    }

    pub(crate) fn place_ball(&mut self, ball: ColliderHandle, at: &Point2<f32>) {
        self.world.colliders[ball].set_translation(Vector::new(at.x, at.y, WORK_Z));
    }

    /// Where a collider is, in the working plane.
    pub(crate) fn position(&self, collider: ColliderHandle) -> Point2<f32> {
        let at = self.world.colliders[collider].translation();
        Point2::new(at.x, at.y)
    }

    /// Runs collision detection for the colliders as they are placed now.
    pub(crate) fn detect(&mut self) {
        self.world.step();
    }

    /// Whether `gripper` is in `zone`, as the narrow phase has it.
    pub(crate) fn inside(&self, zone: ColliderHandle, gripper: ColliderHandle) -> bool {
        self.world.narrow_phase.intersection_pair(zone, gripper) == Some(true)
    }

    /// Whether two links touch or overlap, as the narrow phase has it.
    pub(crate) fn touching(&self, a: ColliderHandle, b: ColliderHandle) -> bool {
        self.world
            .narrow_phase
            .contact_pair(a, b)
            .and_then(|pair| pair.find_deepest_contact())
            .is_some_and(|(_, contact)| contact.dist <= 0.0)
    }

    /// How far apart two colliders are (0 when they touch), by parry3d.
    pub(crate) fn distance(&self, a: ColliderHandle, b: ColliderHandle) -> f32 {
        let (a, b) = (&self.world.colliders[a], &self.world.colliders[b]);
        query::distance(a.position(), a.shape(), b.position(), b.shape())
            .map_or(0.0, |d| d.distance)
    }
}
