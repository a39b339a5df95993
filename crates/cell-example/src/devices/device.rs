//! The cell's devices by name: which a line has, the world's port that serves each, and the
//! module that drives it. Apart from either side of those ports, since the world declares
//! them by these names and a line's process imports them by the same.

use imrs_sim::{Line, RobotId, Role, Station};

use crate::names::LineNames;

/// A device of the cell, as the world serves it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Device {
    /// A robot.
    Robot(RobotId),
    /// A line's gate.
    Gate(Line),
    /// A station's freeze relay.
    Relay(Line, Station),
}

impl Device {
    /// Every device of `line`.
    pub fn of_line(line: Line) -> [Device; 6] {
        [
            Device::Gate(line),
            Device::Robot(RobotId::new(line, Role::LoadCard)),
            Device::Robot(RobotId::new(line, Role::ScrewInCard)),
            Device::Robot(RobotId::new(line, Role::ChipIt)),
            Device::Relay(line, Station::Load),
            Device::Relay(line, Station::Chip),
        ]
    }

    /// Its line.
    pub fn line(self) -> Line {
        match self {
            Device::Robot(robot) => robot.line,
            Device::Gate(line) | Device::Relay(line, _) => line,
        }
    }

    /// The name of the world's port that serves it.
    pub fn port(self) -> String {
        let line = |line: Line| match line {
            Line::A => "A",
            Line::B => "B",
        };
        match self {
            Device::Robot(robot) => {
                let role = match robot.role {
                    Role::LoadCard => "LOAD",
                    Role::ScrewInCard => "SCREW",
                    Role::ChipIt => "CHIP",
                };
                format!("{role}_ROBOT_{}", line(robot.line))
            }
            Device::Gate(at) => format!("GATE_DEVICE_{}", line(at)),
            Device::Relay(at, Station::Load) => format!("LOAD_RELAY_{}", line(at)),
            Device::Relay(at, Station::Chip) => format!("CHIP_RELAY_{}", line(at)),
        }
    }

    /// The module that drives it, the user of its port beside the world's
    /// [`LINE_SUPERVISOR`](crate::names::LINE_SUPERVISOR).
    pub fn user(self) -> String {
        match self {
            Device::Gate(line) => LineNames::of(line).gate,
            Device::Robot(robot) => {
                let names = LineNames::of(robot.line);
                match robot.role {
                    Role::LoadCard => names.load_card,
                    Role::ScrewInCard => names.screw_in_card,
                    Role::ChipIt => names.chip_it,
                }
            }
            Device::Relay(line, Station::Load) => LineNames::of(line).load_card,
            Device::Relay(line, Station::Chip) => LineNames::of(line).chip_it,
        }
    }
}
