//! The hand's numbering and dimensions, in metres, radians and seconds. The table top is
//! the plane z = 0.
//!
//! Joints are numbered from 1, as the seed numbers them: 1 to 6 are the wrist's degrees of
//! freedom (x, y, z, roll, pitch, yaw), and finger `f` (1 to 4) has joints `5 + 2f`
//! (proximal) and `6 + 2f` (distal). Tactile sensor `f` is finger `f`'s tip.

use std::time::Duration;

/// How often the hand's world steps.
pub const HAND_STEP: Duration = Duration::from_millis(10);

/// The wrist's joints: x, y, z, roll, pitch, yaw.
pub const WRIST: [usize; 6] = [1, 2, 3, 4, 5, 6];
/// The fingers, numbered as the tactile sensors at their tips.
pub const FINGERS: [usize; 4] = [1, 2, 3, 4];
/// Every joint.
pub const JOINTS: usize = 14;

/// Where the palm starts: above the table's middle, 25 cm up, fingers down.
pub const PALM_HOME: [f32; 3] = [0.0, -0.2, 0.25];
/// The palm, a square plate.
pub const PALM_HALF: [f32; 3] = [0.05, 0.05, 0.01];
/// Where each finger's base sits under the palm, in the palm's frame.
pub const FINGER_BASES: [[f32; 2]; 4] =
    [[0.04, 0.04], [-0.04, 0.04], [-0.04, -0.04], [0.04, -0.04]];
/// The phalanges' lengths, proximal then distal, and their radius.
pub const PHALANX_LENGTHS: [f32; 2] = [0.05, 0.04];
/// A phalanx's radius.
pub const PHALANX_RADIUS: f32 = 0.008;
/// How far a finger joint may bend, either way.
pub const FINGER_LIMIT: f32 = 1.4;

/// The wrist's fastest motion: metres per second along an axis, radians per second about one.
pub const WRIST_SPEED: [f32; 2] = [0.2, 1.0];

/// The finger joints of finger `f` (1 to 4): proximal and distal.
pub fn finger_joints(finger: usize) -> [usize; 2] {
    [5 + 2 * finger, 6 + 2 * finger]
}

/// The finger a finger joint belongs to, or `None` for a wrist joint or no joint.
pub fn finger_of(joint: usize) -> Option<usize> {
    (7..=JOINTS).contains(&joint).then(|| (joint - 5) / 2)
}
