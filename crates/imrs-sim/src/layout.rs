//! Every dimension, speed and time of the simulated cell, in one place.
//!
//! A 1985 SCARA-class cell: two-link arms of about 0.75 m reach moving their tools at up to
//! 1 m/s, a roller conveyor at 0.2 m/s, pallets 0.3 m long. Metres, seconds, radians.
//! The x axis runs along the conveyors, y across them, z up.

use std::time::Duration;

/// The fixed physics step: 50 Hz, fine enough that a tool at full speed moves 2 cm a step.
pub const STEP: Duration = Duration::from_millis(20);

/// Where the second line runs, beside the first (the first runs along y = 0).
pub const LINE_GAP: f32 = 1.2;
/// Where pallets come onto the conveyor, at the gate.
pub const GATE_X: f32 = 0.0;
/// The load station, where LOAD_CARD and SCREW_IN_CARD work.
pub const LOAD_X: f32 = 2.0;
/// The chip station, where CHIP_IT works.
pub const CHIP_X: f32 = 4.0;
/// Where pallets leave the line, done.
pub const EXIT_X: f32 = 5.5;
/// The roller conveyor's speed.
pub const CONVEYOR_SPEED: f32 = 0.2;
/// The least distance between two pallets' centres (a pallet is 0.3 m long).
pub const PALLET_PITCH: f32 = 0.35;
/// A pallet's half extents.
pub const PALLET_HALF: [f32; 3] = [0.15, 0.1, 0.02];

/// A card's size: along the conveyor, then across it. The card lies centred on its pallet;
/// places on it are measured from its corner nearest the gate and line A.
pub const CARD_SIZE: [f32; 2] = [0.08, 0.10];

/// The two links of every arm.
pub const LINK_1: f32 = 0.4;
/// The second link, to the tool.
pub const LINK_2: f32 = 0.35;
/// The radius of a link's collider.
pub const LINK_RADIUS: f32 = 0.035;
/// The height of the arms' working plane.
pub const ARM_Z: f32 = 0.3;
/// The tool's top speed.
pub const TOOL_SPEED: f32 = 1.0;
/// The tool's acceleration.
pub const TOOL_ACCEL: f32 = 4.0;

/// Where the shared feeder zone is centred, between the chip stations.
pub const ZONE_CENTRE: [f32; 2] = [CHIP_X + 0.1, LINE_GAP / 2.0];
/// The zone's half extents.
pub const ZONE_HALF: [f32; 3] = [0.22, 0.18, 0.3];
/// The feeders, in a row across the zone: their x positions (all at the zone's y).
pub const FEEDER_X: [f32; 4] = [CHIP_X - 0.05, CHIP_X + 0.05, CHIP_X + 0.15, CHIP_X + 0.25];
/// How close the tool must be to a feeder or a card to work on it.
pub const REACH_TOLERANCE: f32 = 0.02;

/// Grasping a chip from a feeder.
pub const GRASP_TIME: Duration = Duration::from_millis(500);
/// Inserting a chip into the card.
pub const INSERT_TIME: Duration = Duration::from_millis(800);
/// Picking a blank card from the magazine.
pub const PICK_CARD_TIME: Duration = Duration::from_millis(600);
/// Laying a card on the pallet.
pub const PLACE_CARD_TIME: Duration = Duration::from_millis(700);
/// Screwing a card to the pallet.
pub const SCREW_TIME: Duration = Duration::from_millis(2500);
/// How long the operator takes to refill a feeder found empty.
pub const REFILL_DELAY: Duration = Duration::from_secs(120);
/// How many chips a refill puts in a feeder, at least and at most.
pub const REFILL_CHIPS: (u32, u32) = (150, 250);

/// The gate's relay letting one pallet go.
pub const RELEASE_TIME: Duration = Duration::from_millis(300);

/// The y of line `line` (0 or 1).
pub const fn line_y(line: usize) -> f32 {
    line as f32 * LINE_GAP
}
