//! What a device operation can fail with.

use std::fmt;

use crate::ids::{FeederId, Line, RobotId, Station};

/// A device operation's failure, naming the device.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DeviceError {
    /// The robot faulted during the operation (an injected fault).
    RobotFault {
        /// The robot.
        robot: RobotId,
    },
    /// The target lies outside the arm's reach.
    OutOfReach {
        /// The robot.
        robot: RobotId,
        /// The target, in metres.
        target: [i32; 2],
    },
    /// A place on the card that lies off the card.
    OffCard {
        /// The robot.
        robot: RobotId,
        /// The place asked for, in millimetres from the card's corner.
        at: [i32; 2],
    },
    /// No feeder has that number.
    UnknownFeeder {
        /// The feeder asked for.
        feeder: FeederId,
    },
    /// The feeder has no chips left.
    EmptyFeeder {
        /// The feeder.
        feeder: FeederId,
        /// The chip number it holds.
        chip: u32,
    },
    /// The tool is not where the operation needs it.
    NotThere {
        /// The robot.
        robot: RobotId,
        /// What it should be at.
        at: &'static str,
    },
    /// The tool holds nothing to insert or place.
    NothingHeld {
        /// The robot.
        robot: RobotId,
    },
    /// No pallet is held at the station.
    NoPallet {
        /// The line.
        line: Line,
        /// The station.
        station: Station,
    },
    /// The pallet is not ready for this step (no card yet, card not screwed).
    NotReady {
        /// The line.
        line: Line,
        /// What is missing.
        missing: &'static str,
    },
    /// A pallet jammed at a station's freeze relay (an injected fault).
    Jam {
        /// The line.
        line: Line,
        /// The station.
        station: Station,
    },
}

impl fmt::Display for DeviceError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::RobotFault { robot } => write!(f, "{robot} faulted"),
            Self::OutOfReach { robot, target } => {
                write!(
                    f,
                    "{robot} cannot reach ({} mm, {} mm)",
                    target[0], target[1]
                )
            }
            Self::OffCard { robot, at } => write!(
                f,
                "{robot} was sent to ({} mm, {} mm) on the card, which lies off the card",
                at[0], at[1]
            ),
            Self::UnknownFeeder { feeder } => write!(f, "there is no {feeder}"),
            Self::EmptyFeeder { feeder, chip } => write!(f, "{feeder} (chip {chip}) is empty"),
            Self::NotThere { robot, at } => write!(f, "{robot} is not at the {at}"),
            Self::NothingHeld { robot } => write!(f, "{robot} holds nothing"),
            Self::NoPallet { line, station } => {
                write!(
                    f,
                    "no pallet held at the {station:?} station of line {line:?}"
                )
            }
            Self::NotReady { line, missing } => {
                write!(f, "the pallet on line {line:?} has no {missing}")
            }
            Self::Jam { line, station } => {
                write!(
                    f,
                    "a pallet jammed at the {station:?} station of line {line:?}"
                )
            }
        }
    }
}

impl std::error::Error for DeviceError {}
