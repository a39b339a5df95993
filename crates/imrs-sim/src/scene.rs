//! What the cell looks like at one moment, read from the rapier world: for whoever draws it
//! (a recorder, a viewer), never for deciding what the modules do.

use imrs_ports::Instant;

use crate::ids::{FeederId, Line, PalletId, RobotId};

/// The cell at one moment.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// When, on the simulation's clock.
    pub at: Instant,
    /// Every robot's arm.
    pub arms: Vec<ArmPose>,
    /// Every pallet on the conveyors.
    pub pallets: Vec<PalletPose>,
    /// The feeders of the shared zone.
    pub feeders: Vec<FeederView>,
    /// The shared feeder zone: the sensor's box.
    pub zone: BoxPose,
}

/// One arm: its two links as rapier places them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmPose {
    /// The robot.
    pub robot: RobotId,
    /// The link from the base to the elbow, then the link from the elbow to the tool.
    pub links: [LinkPose; 2],
    /// Whether rapier sees a link of it inside the feeder zone.
    pub in_zone: bool,
}

/// One link: a capsule lying along its own x axis, turned about z.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkPose {
    /// The capsule's centre, metres.
    pub centre: [f32; 3],
    /// Its turn about the z axis, radians.
    pub yaw: f32,
    /// The length of its segment, between the centres of its end caps.
    pub length: f32,
    /// Its radius.
    pub radius: f32,
}

/// A pallet on a conveyor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PalletPose {
    /// Its line.
    pub line: Line,
    /// Which pallet.
    pub pallet: PalletId,
    /// Its box.
    pub pose: BoxPose,
    /// Whether a card lies on it.
    pub card: bool,
    /// The chips inserted in its card so far.
    pub chips: u32,
}

/// A box, axis-aligned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoxPose {
    /// Its centre, metres.
    pub centre: [f32; 3],
    /// Its half extents.
    pub half: [f32; 3],
}

/// A feeder of the shared zone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeederView {
    /// Which feeder.
    pub id: FeederId,
    /// The chip number it holds.
    pub chip: u32,
    /// The chips it has left.
    pub stock: u32,
    /// Where it stands, on the floor of the zone.
    pub at: [f32; 3],
}
