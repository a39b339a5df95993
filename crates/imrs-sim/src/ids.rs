//! Names of the cell's lines, stations, robots and feeders.

use std::fmt;

/// One of the two assembly lines.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Line {
    /// The Appendix's line.
    A,
    /// "A similar assembly line next to this line."
    B,
}

impl Line {
    /// Both lines.
    pub const ALL: [Line; 2] = [Line::A, Line::B];

    /// The line's place in per-line arrays: 0 for A, 1 for B.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The line beside this one.
    pub fn other(self) -> Line {
        match self {
            Line::A => Line::B,
            Line::B => Line::A,
        }
    }
}

/// A station of a line, where a freeze relay holds the pallet.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Station {
    /// LOAD_CARD and SCREW_IN_CARD's station.
    Load,
    /// CHIP_IT's station.
    Chip,
}

impl Station {
    /// Both stations, in the order a pallet meets them.
    pub const ALL: [Station; 2] = [Station::Load, Station::Chip];

    pub(crate) fn index(self) -> usize {
        self as usize
    }
}

/// What a robot does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Role {
    /// Moves a blank card onto the pallet.
    LoadCard,
    /// Screws the card to the pallet.
    ScrewInCard,
    /// Inserts chips, taken from the shared feeders.
    ChipIt,
}

/// A robot: its line and its role.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct RobotId {
    /// Its line.
    pub line: Line,
    /// Its role.
    pub role: Role,
}

impl RobotId {
    /// Every robot of the cell.
    pub const ALL: [RobotId; 6] = [
        RobotId::new(Line::A, Role::LoadCard),
        RobotId::new(Line::A, Role::ScrewInCard),
        RobotId::new(Line::A, Role::ChipIt),
        RobotId::new(Line::B, Role::LoadCard),
        RobotId::new(Line::B, Role::ScrewInCard),
        RobotId::new(Line::B, Role::ChipIt),
    ];

    /// The robot of `role` on `line`.
    pub const fn new(line: Line, role: Role) -> Self {
        Self { line, role }
    }

    pub(crate) fn index(self) -> usize {
        self.line.index() * 3 + self.role as usize
    }
}

impl fmt::Display for RobotId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let role = match self.role {
            Role::LoadCard => "load",
            Role::ScrewInCard => "screw",
            Role::ChipIt => "chip",
        };
        write!(f, "{role}-robot-{:?}", self.line)
    }
}

/// One feeder of the shared zone.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct FeederId(pub u8);

impl fmt::Display for FeederId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "feeder-{}", self.0)
    }
}

/// A pallet, numbered in the order it was released.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct PalletId(pub u32);

impl fmt::Display for PalletId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "pallet-{}", self.0)
    }
}
