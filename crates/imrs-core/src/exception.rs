//! Exceptions (Shin 1985, §5.1): `PORT.TIMEOUT` and friends, handled at their order rank.

use std::fmt;

use imrs_ports::Name;

/// An exception raised in a module: a port timeout (`LET_1_GO.TIMEOUT`), a failed task
/// (`RELEASE.FAILED`), or one a module raises itself.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Exception {
    /// Its name, as the order and the handlers name it.
    pub name: Name,
    /// The task it was raised in, if any.
    pub task: Option<Name>,
    /// What happened, for the operator.
    pub detail: String,
}

impl Exception {
    /// The name of the timeout exception of `port`: `PORT.TIMEOUT`.
    pub fn timeout_of(port: &str) -> Name {
        format!("{port}.TIMEOUT").into()
    }

    /// The name of the exception raised when `task` fails: `TASK.FAILED`.
    pub fn failure_of(task: &str) -> Name {
        format!("{task}.FAILED").into()
    }
}

impl fmt::Display for Exception {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.name, self.detail)
    }
}
