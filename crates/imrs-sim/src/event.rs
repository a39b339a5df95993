//! What the simulation measures, with virtual timestamps: the physical truth of a run.

use std::fmt;

use imrs_core::{Log, Record};
use imrs_ports::Instant;

use crate::fault::FaultKind;
use crate::ids::{Line, PalletId, RobotId, Station};

/// One measured fact.
#[derive(Debug, Clone, PartialEq)]
pub struct SimEvent {
    /// When, on the framework clock.
    pub at: Instant,
    /// What.
    pub kind: SimEventKind,
}

/// What was measured.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum SimEventKind {
    /// A robot's links began to overlap the shared feeder zone.
    ZoneEntered {
        /// The robot.
        robot: RobotId,
    },
    /// A robot's links no longer overlap the zone.
    ZoneLeft {
        /// The robot.
        robot: RobotId,
    },
    /// Two robots began to touch, at `point` (metres).
    Collision {
        /// One robot.
        a: RobotId,
        /// The other.
        b: RobotId,
        /// Where, in the world.
        point: [f32; 3],
    },
    /// The gate let a pallet onto the conveyor.
    PalletReleased {
        /// The line.
        line: Line,
        /// The pallet.
        pallet: PalletId,
    },
    /// A station's freeze relay holds a pallet in place.
    PalletInPlace {
        /// The line.
        line: Line,
        /// The station.
        station: Station,
        /// The pallet.
        pallet: PalletId,
    },
    /// A pallet jammed at a station's relay.
    PalletJammed {
        /// The line.
        line: Line,
        /// The station.
        station: Station,
        /// The pallet.
        pallet: PalletId,
    },
    /// A pallet was taken off the line: jammed, or held by a station of a line whose
    /// controller died.
    PalletScrapped {
        /// The line.
        line: Line,
        /// The pallet.
        pallet: PalletId,
    },
    /// A pallet left the end of the line.
    PalletDone {
        /// The line.
        line: Line,
        /// The pallet.
        pallet: PalletId,
        /// How many chips its card carries.
        chips: u32,
    },
    /// A card was laid on a pallet.
    CardPlaced {
        /// The line.
        line: Line,
        /// The pallet.
        pallet: PalletId,
    },
    /// A card was screwed to its pallet.
    CardScrewed {
        /// The line.
        line: Line,
        /// The pallet.
        pallet: PalletId,
    },
    /// A chip was inserted into a pallet's card.
    ChipInserted {
        /// The line.
        line: Line,
        /// The pallet.
        pallet: PalletId,
        /// The chip number.
        chip: u32,
        /// Where on the card it went: metres from the card's corner, along the conveyor and
        /// across it, measured from the tool against the pallet's pose in rapier.
        on_card: [f32; 2],
    },
    /// A robot found a feeder empty, and the operator was called to refill it.
    FeederEmptied {
        /// The feeder.
        feeder: crate::ids::FeederId,
    },
    /// The operator refilled an empty feeder.
    FeederRefilled {
        /// The feeder.
        feeder: crate::ids::FeederId,
        /// The chips put in.
        chips: u32,
    },
    /// An injected fault struck.
    FaultStruck {
        /// The fault.
        fault: FaultKind,
    },
}

impl fmt::Display for SimEvent {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{}] ", self.at)?;
        match &self.kind {
            SimEventKind::ZoneEntered { robot } => write!(f, "{robot} entered the feeder zone"),
            SimEventKind::ZoneLeft { robot } => write!(f, "{robot} left the feeder zone"),
            SimEventKind::Collision { a, b, point } => write!(
                f,
                "COLLISION {a} with {b} at ({:.3}, {:.3}, {:.3})",
                point[0], point[1], point[2]
            ),
            SimEventKind::PalletReleased { line, pallet } => {
                write!(f, "line {line:?}: {pallet} released")
            }
            SimEventKind::PalletInPlace {
                line,
                station,
                pallet,
            } => write!(f, "line {line:?}: {pallet} in place at {station:?}"),
            SimEventKind::PalletJammed {
                line,
                station,
                pallet,
            } => write!(f, "line {line:?}: {pallet} jammed at {station:?}"),
            SimEventKind::PalletScrapped { line, pallet } => {
                write!(f, "line {line:?}: {pallet} scrapped")
            }
            SimEventKind::PalletDone {
                line,
                pallet,
                chips,
            } => write!(f, "line {line:?}: {pallet} done with {chips} chips"),
            SimEventKind::CardPlaced { line, pallet } => {
                write!(f, "line {line:?}: card placed on {pallet}")
            }
            SimEventKind::CardScrewed { line, pallet } => {
                write!(f, "line {line:?}: card screwed on {pallet}")
            }
            SimEventKind::ChipInserted {
                line,
                pallet,
                chip,
                on_card,
            } => write!(
                f,
                "line {line:?}: chip {chip} inserted on {pallet} at ({:.0} mm, {:.0} mm)",
                on_card[0] * 1000.0,
                on_card[1] * 1000.0
            ),
            SimEventKind::FeederEmptied { feeder } => {
                write!(f, "{feeder} found empty: the operator is called")
            }
            SimEventKind::FeederRefilled { feeder, chips } => {
                write!(f, "{feeder} refilled with {chips} chips")
            }
            SimEventKind::FaultStruck { fault } => write!(f, "fault: {fault:?}"),
        }
    }
}

impl Record for SimEvent {}

/// The stream of measured facts: kept, and passed to subscribers as they happen.
pub type SimLog = Log<SimEvent>;
