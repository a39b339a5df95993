//! Faults a test or an operator's flag injects into the hardware.

use imrs_ports::Instant;

use crate::ids::{FeederId, Line, RobotId, Station};

/// A fault, and when it strikes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fault {
    /// When.
    pub at: Instant,
    /// What.
    pub kind: FaultKind,
}

/// What goes wrong.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FaultKind {
    /// The robot faults: the operation it runs then (or its next one) fails.
    Robot(RobotId),
    /// The feeder runs empty.
    FeederEmpty(FeederId),
    /// The next pallet to reach the station jams at its freeze relay.
    Jam(Line, Station),
}
