//! A chip robot's reservation of the space its next move sweeps, as the coordinator's
//! ZONE_RESERVE carries it: a fixed-size record, so that it crosses processes as it is.

use std::fmt;

use imrs_ipc::{FromBytes, ZeroCopySend};
use imrs_sim::Line;
use serde::de::Error as _;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::devices::Pose;
use crate::module_name::ModuleName;
use crate::names::LineNames;
use crate::zone_asker::ZoneAsker;

/// The most poses a reservation holds.
pub const MAX_POSES: usize = 64;

/// The space a robot asks for: who asks (its name, line and run, as to the arbiter) and the
/// poses its arm passes through.
#[derive(Clone, Copy, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("cell_example::Reservation")]
pub struct Reservation {
    asker: ZoneAsker,
    poses: u32,
    sweep: [Pose; MAX_POSES],
}

impl Default for Reservation {
    fn default() -> Self {
        Self {
            asker: ZoneAsker::default(),
            poses: 0,
            sweep: [Pose::default(); MAX_POSES],
        }
    }
}

impl Reservation {
    /// `asker`'s reservation of the space `sweep` passes through; `None` if the sweep has
    /// more than [`MAX_POSES`] poses — a reservation of part of it would leave the rest
    /// unguarded.
    pub fn new(asker: ZoneAsker, sweep: &[Pose]) -> Option<Self> {
        let mut reservation = Self {
            asker,
            poses: u32::try_from(sweep.len()).ok()?,
            ..Self::default()
        };
        reservation
            .sweep
            .get_mut(..sweep.len())?
            .copy_from_slice(sweep);
        Some(reservation)
    }

    /// Who asks.
    pub fn asker(&self) -> &ZoneAsker {
        &self.asker
    }

    /// The robot asking.
    pub fn robot(&self) -> &ModuleName {
        self.asker.robot()
    }

    /// The line whose chip robot asks, if the record names one of the cell's two, on its
    /// own line: the coordinator weighs no other, so that names a peer makes up are never
    /// kept.
    pub fn chip_robot(&self) -> Option<Line> {
        chip_robot(&self.asker)
    }

    /// The poses; `None` if a peer wrote a count the record cannot hold.
    pub fn sweep(&self) -> Option<&[Pose]> {
        self.sweep.get(..usize::try_from(self.poses).ok()?)
    }
}

/// The line of `asker`, if it is the chip robot of that line.
pub fn chip_robot(asker: &ZoneAsker) -> Option<Line> {
    asker
        .line()
        .filter(|&line| LineNames::of(line).chip_it == asker.robot().as_str())
}

impl fmt::Debug for Reservation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Reservation")
            .field("asker", &self.asker)
            .field("poses", &self.poses)
            .finish()
    }
}

/// Across hosts a reservation is who asks and the poses it holds, no more: the record's
/// unused room does not cross.
impl Serialize for Reservation {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        (self.asker, self.sweep().unwrap_or_default()).serialize(serializer)
    }
}

/// A reservation read from a peer: refused if it holds more poses than a reservation can.
impl<'de> Deserialize<'de> for Reservation {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let (asker, sweep): (ZoneAsker, Vec<Pose>) = Deserialize::deserialize(deserializer)?;
        if asker.robot().as_str().is_empty() {
            return Err(D::Error::custom("a reservation that names no robot"));
        }
        Reservation::new(asker, &sweep).ok_or_else(|| {
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
        let asker = ZoneAsker::new("CHIP_IT2", Line::B, 1);
        let reservation = Reservation::new(asker, &sweep).unwrap();
        assert_eq!(reservation.robot().as_str(), "CHIP_IT2");
        assert_eq!(reservation.asker(), &asker);
        assert_eq!(reservation.sweep(), Some(&sweep[..]));
        let too_long = vec![Pose::default(); MAX_POSES + 1];
        assert!(Reservation::new(asker, &too_long).is_none());
        let garbled = Reservation {
            poses: MAX_POSES as u32 + 1,
            ..Reservation::default()
        };
        assert_eq!(garbled.sweep(), None);
    }

    #[test]
    fn only_the_cells_chip_robots_on_their_own_lines_are_weighed() {
        let sweep = [Pose::default(); 2];
        let of = |robot, line| {
            Reservation::new(ZoneAsker::new(robot, line, 0), &sweep)
                .unwrap()
                .chip_robot()
        };
        assert_eq!(of("CHIP_IT", Line::A), Some(Line::A));
        assert_eq!(of("CHIP_IT2", Line::B), Some(Line::B));
        assert_eq!(of("CHIP_IT2", Line::A), None);
        assert_eq!(of("CHIP_IT3", Line::B), None);
        assert_eq!(of("LOAD_IT", Line::A), None);
    }

    #[test]
    fn a_reservation_crosses_hosts_as_its_asker_and_poses() {
        let sweep: Vec<Pose> = (0..3)
            .map(|i| [[0.0, 0.0], [0.01 * i as f32, 0.2], [0.3, 0.4]])
            .collect();
        let asker = ZoneAsker::new("CHIP_IT", Line::A, 2);
        let reservation = Reservation::new(asker, &sweep).unwrap();
        let text = serde_json::to_string(&reservation).unwrap();
        let back: Reservation = serde_json::from_str(&text).unwrap();
        assert_eq!(back.asker(), &asker);
        assert_eq!(back.sweep(), Some(&sweep[..]));
        let too_long = (asker, vec![Pose::default(); MAX_POSES + 1]);
        let error = serde_json::from_str::<Reservation>(&serde_json::to_string(&too_long).unwrap())
            .unwrap_err();
        assert!(error.to_string().contains("65 poses"), "{error}");
    }
}
