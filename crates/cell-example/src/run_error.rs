//! Why a run could not be made. Apart from the running, since the runs across processes and
//! the ROS 2 bridge fail a run with one too.

use std::path::{Path, PathBuf};

use imrs_core::{CellError, CellErrors};
use imrs_record::RecordError;

use crate::config::MAX_HOURS;

/// Why a run could not be made.
#[derive(Debug, Clone, PartialEq)]
pub enum RunError {
    /// The cell is wired wrong: every problem, each naming its module and port.
    Wiring(CellErrors),
    /// The simulated hours are not a number above 0 and at most [`MAX_HOURS`].
    Hours(f64),
    /// The recording or the timeline could not be written.
    Output {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        error: String,
    },
    /// A run across processes could not be made: which process, and why.
    Processes {
        /// The process: the world, line A or line B.
        process: String,
        /// What went wrong.
        why: String,
    },
    /// The cell could not be made visible to ROS 2 (`--ros2`): why.
    Ros2(String),
    /// A fault is set for after the run's end, so it would never fire.
    FaultAfterEnd {
        /// The fault, as `--fault` writes it.
        fault: String,
        /// The run's length in hours.
        hours: f64,
    },
}

impl std::fmt::Display for RunError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Wiring(problems) => write!(f, "the cell is wired wrong:\n{problems}"),
            Self::Hours(hours) => {
                write!(
                    f,
                    "{hours} hours: expected a number of hours above 0, at most {MAX_HOURS}"
                )
            }
            Self::Output { path, error } => {
                write!(f, "{}: cannot be written: {error}", path.display())
            }
            Self::Processes { process, why } => write!(f, "across processes, {process}: {why}"),
            Self::Ros2(why) => write!(f, "--ros2: {why}"),
            Self::FaultAfterEnd { fault, hours } => write!(
                f,
                "--fault {fault}: set for after the run's end ({hours} h), so it would never fire; \
                 run longer with --hours or set it earlier"
            ),
        }
    }
}

impl std::error::Error for RunError {}

impl From<CellErrors> for RunError {
    fn from(problems: CellErrors) -> Self {
        Self::Wiring(problems)
    }
}

impl From<CellError> for RunError {
    fn from(problem: CellError) -> Self {
        Self::Wiring(problem.into())
    }
}

pub(crate) fn output(path: &Path, error: RecordError) -> RunError {
    RunError::Output {
        path: path.to_path_buf(),
        error: error.to_string(),
    }
}
