//! A chip robot's reservation of the space its next move sweeps, as the coordinator's
//! ZONE_RESERVE carries it: a fixed-size record, so that it crosses processes as it is.

use std::fmt;

use imrs_ipc::{FromBytes, ZeroCopySend};
use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::devices::Pose;
use crate::ports::ModuleName;

/// The most poses a reservation holds.
pub const MAX_POSES: usize = 64;

/// The space a robot asks for: its name and the poses its arm passes through.
#[derive(Clone, Copy, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("cell_example::Reservation")]
pub struct Reservation {
    robot: ModuleName,
    poses: u32,
    sweep: [Pose; MAX_POSES],
}

impl Default for Reservation {
    fn default() -> Self {
        Self {
            robot: ModuleName::default(),
            poses: 0,
            sweep: [Pose::default(); MAX_POSES],
        }
    }
}

impl Reservation {
    /// `robot`'s reservation of the space `sweep` passes through; `None` if the sweep has
    /// more than [`MAX_POSES`] poses — a reservation of part of it would leave the rest
    /// unguarded.
    pub fn new(robot: &str, sweep: &[Pose]) -> Option<Self> {
        let mut reservation = Self {
            robot: ModuleName::new(robot),
            poses: u32::try_from(sweep.len()).ok()?,
            ..Self::default()
        };
        reservation
            .sweep
            .get_mut(..sweep.len())?
            .copy_from_slice(sweep);
        Some(reservation)
    }

    /// The robot asking.
    pub fn robot(&self) -> &ModuleName {
        &self.robot
    }

    /// The poses; `None` if a peer wrote a count the record cannot hold.
    pub fn sweep(&self) -> Option<&[Pose]> {
        self.sweep.get(..usize::try_from(self.poses).ok()?)
    }
}

impl fmt::Debug for Reservation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Reservation")
            .field("robot", &self.robot)
            .field("poses", &self.poses)
            .finish()
    }
}

/// Across hosts a reservation is its robot and the poses it holds, no more: the record's
/// unused room does not cross.
impl Serialize for Reservation {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        (self.robot, self.sweep().unwrap_or_default()).serialize(serializer)
    }
}

/// A reservation read from a peer: refused if it holds more poses than a reservation can.
impl<'de> Deserialize<'de> for Reservation {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let (robot, sweep): (ModuleName, Vec<Pose>) = Deserialize::deserialize(deserializer)?;
        if robot.as_str().is_empty() {
            return Err(D::Error::custom("a reservation that names no robot"));
        }
        Reservation::new(robot.as_str(), &sweep).ok_or_else(|| {
            D::Error::custom(format!(
                "a reservation of {} poses, past the {MAX_POSES} one can hold",
                sweep.len()
            ))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sweep_that_fits_comes_back_whole_and_one_that_does_not_is_refused() {
        let sweep: Vec<Pose> = (0..26)
            .map(|i| [[0.0, 0.0], [0.01 * i as f32, 0.2], [0.3, 0.4]])
            .collect();
        let reservation = Reservation::new("CHIP_IT2", &sweep).unwrap();
        assert_eq!(reservation.robot().as_str(), "CHIP_IT2");
        assert_eq!(reservation.sweep(), Some(&sweep[..]));
        let too_long = vec![Pose::default(); MAX_POSES + 1];
        assert!(Reservation::new("CHIP_IT", &too_long).is_none());
        let garbled = Reservation {
            poses: MAX_POSES as u32 + 1,
            ..Reservation::default()
        };
        assert_eq!(garbled.sweep(), None);
    }

    #[test]
    fn a_reservation_crosses_hosts_as_its_robot_and_poses() {
        let sweep: Vec<Pose> = (0..3)
            .map(|i| [[0.0, 0.0], [0.01 * i as f32, 0.2], [0.3, 0.4]])
            .collect();
        let reservation = Reservation::new("CHIP_IT", &sweep).unwrap();
        let text = serde_json::to_string(&reservation).unwrap();
        let back: Reservation = serde_json::from_str(&text).unwrap();
        assert_eq!(back.robot(), reservation.robot());
        assert_eq!(back.sweep(), Some(&sweep[..]));
        let too_long = (
            ModuleName::new("CHIP_IT"),
            vec![Pose::default(); MAX_POSES + 1],
        );
        let error = serde_json::from_str::<Reservation>(&serde_json::to_string(&too_long).unwrap())
            .unwrap_err();
        assert!(error.to_string().contains("65 poses"), "{error}");
    }
}
