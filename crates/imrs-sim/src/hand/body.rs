//! The hand's rapier world: a table, objects resting on it under gravity, a palm moved by
//! its wrist, and four fingers of two phalanges each on motorised multibody joints.
//!
//! Everything the hand's sensors report is read back from rapier: joint angles from the
//! bodies' poses, touch from the narrow phase's contacts, object poses from their bodies.

use std::collections::BTreeMap;

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use rapier3d::prelude::*;

use super::layout::{
    FINGER_BASES, FINGER_LIMIT, JOINTS, PALM_HALF, PALM_HOME, PHALANX_LENGTHS, PHALANX_RADIUS,
    WRIST_SPEED, finger_joints,
};
use super::object::{Detection, Object, Shape};

/// Each joint is driven by a spring toward its target (rapier integrates multibody springs
/// implicitly, so they stay stable on light links where an explicit motor diverges), with
/// joint damping near critical. A finger stopped by an object presses gently: 0.5 N·m per
/// radian of error.
const FINGER_SPRING: (f32, f32) = (0.5, 0.016);
/// The wrist's springs: stiff, so that the palm follows its ramped target closely.
const WRIST_LINEAR_SPRING: (f32, f32) = (2000.0, 80.0);
const WRIST_ANGULAR_SPRING: (f32, f32) = (20.0, 0.4);
/// Reflected rotor inertia on every joint, which keeps the light finger links well
/// conditioned.
const ARMATURE: f32 = 1e-4;

/// How thick a fingertip's tactile pad is: a surface this close presses on it. A finger
/// held where it first touched stays within it, so the touch does not flicker on and off.
const SKIN: f32 = 0.0015;

/// What a fingertip touches.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Touch {
    /// The object with this index among the table's objects.
    Object(usize),
    /// The table.
    Table,
}

struct Finger {
    links: [RigidBodyHandle; 2],
    joints: [MultibodyJointHandle; 2],
    tip: ColliderHandle,
}

struct Item {
    object: Object,
    body: RigidBodyHandle,
    collider: ColliderHandle,
}

pub(crate) struct HandWorld {
    world: PhysicsWorld,
    palm: RigidBodyHandle,
    /// The wrist's joints, in the numbering's order: x, y, z, roll, pitch, yaw.
    wrist: [MultibodyJointHandle; 6],
    fingers: Vec<Finger>,
    items: Vec<Item>,
    table: ColliderHandle,
    /// Where the wrist's springs pull now: each follows its target at the wrist's speed.
    setpoints: [f32; 6],
    /// Each joint's live commands, by the source that gave them.
    commands: Vec<BTreeMap<u64, f32>>,
    /// The value each joint is driven to: the mean of its commands, or where it was left.
    targets: [f32; JOINTS],
}

pub(crate) fn to_rapier(pose: &Isometry3<f32>) -> Pose {
    let t = pose.translation.vector;
    let q = pose.rotation.quaternion();
    Pose::from_parts(
        Vector::new(t.x, t.y, t.z),
        Rotation::from_xyzw(q.i, q.j, q.k, q.w),
    )
}

pub(crate) fn from_rapier(pose: &Pose) -> Isometry3<f32> {
    let (t, q) = (pose.translation, pose.rotation);
    Isometry3::from_parts(
        Translation3::new(t.x, t.y, t.z),
        UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q.w, q.x, q.y, q.z)),
    )
}

fn v(x: Vector3<f32>) -> Vector {
    Vector::new(x.x, x.y, x.z)
}

/// A light link of the wrist's chain, with no shape of its own.
fn carriage(world: &mut PhysicsWorld, at: &Isometry3<f32>) -> RigidBodyHandle {
    world.bodies.insert(
        RigidBodyBuilder::dynamic()
            .pose(to_rapier(at))
            .gravity_scale(0.0)
            .can_sleep(false)
            .additional_mass_properties(MassProperties::new(
                Vector::ZERO,
                0.1,
                Vector::new(1e-4, 1e-4, 1e-4),
            )),
    )
}

impl HandWorld {
    pub(crate) fn new(objects: &[Object]) -> Self {
        let mut world = PhysicsWorld::new();
        world.gravity = Vector::new(0.0, 0.0, -9.81);
        world.integration_parameters.dt = super::layout::HAND_STEP.as_secs_f32();
        // Rapier's tolerances scale with the size of the things it simulates: here a
        // decimetre, not a metre.
        world.integration_parameters.length_unit = 0.1;
        let table = world.colliders.insert(
            ColliderBuilder::cuboid(0.5, 0.5, 0.02)
                .translation(Vector::new(0.0, 0.0, -0.02))
                .friction(0.8),
        );
        let (palm, wrist) = add_wrist(&mut world);
        let home = Isometry3::translation(PALM_HOME[0], PALM_HOME[1], PALM_HOME[2]);
        let fingers = FINGER_BASES
            .iter()
            .map(|&base| add_finger(&mut world, palm, &home, base))
            .collect();
        let items = objects
            .iter()
            .map(|&object| add_object(&mut world, object))
            .collect();
        // The hand's links never touch each other: the fingers stand apart, and a link
        // overlapping its neighbour at a joint must not push it.
        if let Some((multibody, _)) = world.multibody_joints.get_mut(wrist[0]) {
            multibody.set_self_contacts_enabled(false);
        }
        let setpoints = [PALM_HOME[0], PALM_HOME[1], PALM_HOME[2], 0.0, 0.0, 0.0];
        let mut targets = [0.0; JOINTS];
        targets[..6].copy_from_slice(&setpoints);
        Self {
            world,
            palm,
            wrist,
            fingers,
            items,
            table,
            setpoints,
            commands: vec![BTreeMap::new(); JOINTS],
            targets,
        }
    }

    /// Sets `source`'s command for `joint` (1-based); the joint is driven to the mean of all
    /// its sources' commands.
    pub(crate) fn command(&mut self, joint: usize, source: u64, value: f32) {
        self.commands[joint - 1].insert(source, value);
        self.retarget(joint);
    }

    /// Forgets `source`'s command for `joint`; with none left the joint holds its target.
    pub(crate) fn release(&mut self, joint: usize, source: u64) {
        self.commands[joint - 1].remove(&source);
        self.retarget(joint);
    }

    fn retarget(&mut self, joint: usize) {
        let commands = &self.commands[joint - 1];
        if !commands.is_empty() {
            let mean = commands.values().sum::<f32>() / commands.len() as f32;
            self.targets[joint - 1] = if joint > 6 {
                mean.clamp(-FINGER_LIMIT, FINGER_LIMIT)
            } else {
                mean
            };
        }
    }

    pub(crate) fn step(&mut self) {
        let dt = self.world.integration_parameters.dt;
        let joints = &mut self.world.multibody_joints;
        for (axis, &handle) in self.wrist.iter().enumerate() {
            let speed = WRIST_SPEED[axis / 3] * dt;
            let gap = self.targets[axis] - self.setpoints[axis];
            self.setpoints[axis] += gap.clamp(-speed, speed);
            let (index, spring, rest) = if axis < 3 {
                (
                    0,
                    WRIST_LINEAR_SPRING,
                    self.setpoints[axis] - PALM_HOME[axis],
                )
            } else {
                (3, WRIST_ANGULAR_SPRING, self.setpoints[axis])
            };
            drive(joints, handle, index, spring, rest);
        }
        for (f, finger) in self.fingers.iter().enumerate() {
            for (phalanx, &handle) in finger.joints.iter().enumerate() {
                let target = self.targets[finger_joints(f + 1)[phalanx] - 1];
                drive(joints, handle, 3, FINGER_SPRING, target);
            }
        }
        self.world.step();
    }

    /// The value joint `joint` is driven to now.
    pub(crate) fn target(&self, joint: usize) -> f32 {
        self.targets[joint - 1]
    }

    /// Joint `joint`'s position: the wrist's coordinate, or a finger joint's angle as
    /// rapier's bodies have it.
    pub(crate) fn position(&self, joint: usize) -> f32 {
        if joint <= 6 {
            let palm = self.palm();
            let (roll, pitch, yaw) = palm.rotation.euler_angles();
            let t = palm.translation.vector;
            return [t.x, t.y, t.z, roll, pitch, yaw][joint - 1];
        }
        let (finger, phalanx) = ((joint - 7) / 2, (joint - 7) % 2);
        self.world
            .multibody_joints
            .get(self.fingers[finger].joints[phalanx])
            .and_then(|(multibody, link)| multibody.link(link))
            // A hinge's free coordinate is its angle about its axis (the angular x).
            .map_or(f32::NAN, |link| link.joint.coords()[3])
    }

    /// What finger `finger`'s tip touches, measured from rapier's contacts.
    pub(crate) fn touch(&self, finger: usize) -> Option<Touch> {
        let tip = self.fingers[finger - 1].tip;
        self.world
            .narrow_phase
            .contact_pairs_with(tip)
            .filter(|pair| {
                // Rapier keeps speculative contacts before shapes meet: a touch is a
                // contact point within the pad's skin.
                pair.manifolds()
                    .iter()
                    .flat_map(|manifold| &manifold.points)
                    .any(|point| point.dist <= SKIN)
            })
            .find_map(|pair| {
                let other = if pair.collider1 == tip {
                    pair.collider2
                } else {
                    pair.collider1
                };
                if other == self.table {
                    Some(Touch::Table)
                } else {
                    self.items
                        .iter()
                        .position(|item| item.collider == other)
                        .map(Touch::Object)
                }
            })
    }

    /// The palm's pose.
    pub(crate) fn palm(&self) -> Isometry3<f32> {
        from_rapier(self.world.bodies[self.palm].position())
    }

    /// Finger `finger`'s tip, the far end of its distal phalanx.
    pub(crate) fn fingertip(&self, finger: usize) -> Point3<f32> {
        let distal = self.fingers[finger - 1].links[1];
        let pose = from_rapier(self.world.bodies[distal].position());
        pose * Point3::new(0.0, 0.0, -PHALANX_LENGTHS[1])
    }

    /// How fast finger `finger`'s links move, the faster of the two (m/s).
    pub(crate) fn finger_speed(&self, finger: usize) -> f32 {
        self.fingers[finger - 1]
            .links
            .iter()
            .map(|&link| self.world.bodies[link].linvel().length())
            .fold(0.0, f32::max)
    }

    /// Every object as it is now, in table order.
    pub(crate) fn objects(&self) -> Vec<Detection> {
        self.items
            .iter()
            .map(|item| {
                let pose = from_rapier(self.world.bodies[item.body].position());
                Detection {
                    position: pose.translation.vector.into(),
                    orientation: pose.rotation,
                    shape: item.object.shape,
                    size: item.object.size,
                }
            })
            .collect()
    }

    /// Moves object `index` to rest at `at` (x, y): someone pushed it.
    pub(crate) fn push(&mut self, index: usize, at: [f32; 2]) {
        let item = &self.items[index];
        let z = item.object.height() / 2.0;
        let body = &mut self.world.bodies[item.body];
        body.set_translation(Vector::new(at[0], at[1], z), true);
        body.set_linvel(Vector::ZERO, true);
        body.set_angvel(Vector::ZERO, true);
    }
}

/// Pulls joint `handle`'s coordinate `index` toward `rest` with `spring` (stiffness,
/// damping).
fn drive(
    joints: &mut MultibodyJointSet,
    handle: MultibodyJointHandle,
    index: usize,
    (stiffness, damping): (f32, f32),
    rest: f32,
) {
    let Some((multibody, link)) = joints.get_mut(handle) else {
        return;
    };
    let Some(dof) = multibody.link(link).map(|link| link.assembly_id()) else {
        return;
    };
    if let Some(link) = multibody.link_mut(link) {
        link.joint.set_spring(index, stiffness, rest);
    }
    // Set at every step: the generalized coordinates are renumbered once the fixed base
    // stops counting as a free root (after the first step).
    if dof < multibody.damping().len() {
        multibody.damping_mut()[dof] = damping;
        multibody.armature_mut()[dof] = ARMATURE;
    }
}

/// The wrist: a fixed base, three slides and three hinges (yaw, pitch, roll, so that the
/// palm's rotation is `Rz(yaw) Ry(pitch) Rx(roll)`), the palm last. Returns the palm and
/// the joints in the numbering's order (x, y, z, roll, pitch, yaw).
fn add_wrist(world: &mut PhysicsWorld) -> (RigidBodyHandle, [MultibodyJointHandle; 6]) {
    let home = Isometry3::translation(PALM_HOME[0], PALM_HOME[1], PALM_HOME[2]);
    let base = world.bodies.insert(RigidBodyBuilder::fixed());
    let axes: [(bool, Vector); 6] = [
        (true, Vector::X),
        (true, Vector::Y),
        (true, Vector::Z),
        (false, Vector::Z),
        (false, Vector::Y),
        (false, Vector::X),
    ];
    let mut parent = base;
    let mut handles = Vec::new();
    let mut palm = base;
    for (i, &(slide, axis)) in axes.iter().enumerate() {
        let link = if i == 5 {
            let palm = carriage(world, &home);
            let [hx, hy, hz] = PALM_HALF;
            world.colliders.insert_with_parent(
                ColliderBuilder::cuboid(hx, hy, hz).density(1000.0),
                palm,
                &mut world.bodies,
            );
            palm
        } else {
            carriage(world, &home)
        };
        let anchor = if i == 0 {
            v(home.translation.vector)
        } else {
            Vector::ZERO
        };
        let joint: GenericJoint = if slide {
            PrismaticJointBuilder::new(axis)
                .local_anchor1(anchor)
                .local_anchor2(Vector::ZERO)
                .into()
        } else {
            RevoluteJointBuilder::new(axis)
                .local_anchor1(anchor)
                .local_anchor2(Vector::ZERO)
                .into()
        };
        let handle = world
            .multibody_joints
            .insert(parent, link, joint, true)
            .expect("the wrist is a chain");
        handles.push(handle);
        parent = link;
        palm = link;
    }
    // Numbered x, y, z, roll, pitch, yaw; built x, y, z, yaw, pitch, roll.
    let wrist = [
        handles[0], handles[1], handles[2], handles[5], handles[4], handles[3],
    ];
    (palm, wrist)
}

fn add_finger(
    world: &mut PhysicsWorld,
    palm: RigidBodyHandle,
    home: &Isometry3<f32>,
    base: [f32; 2],
) -> Finger {
    let base = Vector3::new(base[0], base[1], -PALM_HALF[2]);
    // Bending a finger by a positive angle curls its tip toward the palm's axis.
    let inward = -Vector3::new(base.x, base.y, 0.0).normalize();
    let axis = inward.cross(&Vector3::z());
    let mut parent = (palm, base);
    let mut frame = home * Translation3::from(base);
    let mut links = Vec::new();
    let mut joints = Vec::new();
    let mut tip = None;
    for &length in &PHALANX_LENGTHS {
        let link = world.bodies.insert(
            RigidBodyBuilder::dynamic()
                .pose(to_rapier(&frame))
                .gravity_scale(0.0)
                .can_sleep(false),
        );
        let collider = world.colliders.insert_with_parent(
            ColliderBuilder::capsule_z(length / 2.0, PHALANX_RADIUS)
                .translation(Vector::new(0.0, 0.0, -length / 2.0))
                .density(1000.0)
                .friction(1.0),
            link,
            &mut world.bodies,
        );
        let joint = RevoluteJointBuilder::new(v(axis))
            .local_anchor1(v(parent.1))
            .local_anchor2(Vector::ZERO)
            .limits([-FINGER_LIMIT, FINGER_LIMIT]);
        let handle = world
            .multibody_joints
            .insert(parent.0, link, joint, true)
            .expect("a finger joint makes a tree");
        links.push(link);
        joints.push(handle);
        tip = Some(collider);
        parent = (link, Vector3::new(0.0, 0.0, -length));
        frame *= Translation3::new(0.0, 0.0, -length);
    }
    Finger {
        links: [links[0], links[1]],
        joints: [joints[0], joints[1]],
        tip: tip.expect("two phalanges"),
    }
}

fn add_object(world: &mut PhysicsWorld, object: Object) -> Item {
    let half = object.size / 2.0;
    let body = world
        .bodies
        .insert(RigidBodyBuilder::dynamic().translation(Vector::new(
            object.at[0],
            object.at[1],
            object.height() / 2.0,
        )));
    let shape = match object.shape {
        Shape::Cube => ColliderBuilder::cuboid(half, half, half),
        Shape::Ball => ColliderBuilder::ball(half),
        // Rapier's cylinders stand along y: turned a quarter about x to stand on the table.
        Shape::Cylinder => ColliderBuilder::cylinder(object.height() / 2.0, half)
            .rotation(Vector::new(std::f32::consts::FRAC_PI_2, 0.0, 0.0)),
    };
    let collider = world.colliders.insert_with_parent(
        shape.density(400.0).friction(0.8),
        body,
        &mut world.bodies,
    );
    Item {
        object,
        body,
        collider,
    }
}
