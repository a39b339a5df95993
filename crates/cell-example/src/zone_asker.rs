//! What a chip robot says to FEEDER_MONITOR when it asks for the feeder zone and when it
//! hands it back: who it is, on which line, and from which run of its line's process.
//!
//! In one process every line runs once (run 0). Across processes the world restarts a
//! line whose process died, and counts the runs: a word sent by a run that has died (a
//! request that waited while it died, a release it sent on its way out) is told from the
//! word of the run after it, so the monitor neither hands the zone to a dead run nor keeps
//! it for one.

use std::fmt;

use imrs_ipc::{FromBytes, ZeroCopySend};
use imrs_sim::Line;
use serde::{Deserialize, Serialize};

use crate::module_name::ModuleName;

/// A chip robot's word to the feeder zone's monitor: a fixed-size record that crosses
/// processes as it is.
#[derive(Clone, Copy, Default, PartialEq, Eq, ZeroCopySend, FromBytes, Serialize, Deserialize)]
#[repr(C)]
#[type_name("cell_example::ZoneAsker")]
pub struct ZoneAsker {
    robot: ModuleName,
    line: u32,
    run: u32,
}

impl ZoneAsker {
    /// `robot` of `line`, in `run` of its line's process.
    pub fn new(robot: &str, line: Line, run: u32) -> Self {
        Self {
            robot: ModuleName::new(robot),
            line: line.index() as u32,
            run,
        }
    }

    /// The robot's module.
    pub fn robot(&self) -> &ModuleName {
        &self.robot
    }

    /// Its line; `None` if a peer wrote a record that is not one.
    pub fn line(&self) -> Option<Line> {
        Line::ALL
            .into_iter()
            .find(|line| line.index() as u32 == self.line)
    }

    /// The run of its line's process it was sent from.
    pub fn run(&self) -> u32 {
        self.run
    }
}

impl fmt::Debug for ZoneAsker {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} (run {})", self.robot, self.run)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_word_names_its_robot_line_and_run() {
        let asker = ZoneAsker::new("CHIP_IT2", Line::B, 3);
        assert_eq!(asker.robot().as_str(), "CHIP_IT2");
        assert_eq!(asker.line(), Some(Line::B));
        assert_eq!(asker.run(), 3);
        assert_eq!(format!("{asker:?}"), "CHIP_IT2 (run 3)");
        let garbled = ZoneAsker {
            line: 7,
            ..ZoneAsker::default()
        };
        assert_eq!(garbled.line(), None);
    }
}
