//! The operator's alarms (the Appendix's `{signal for help}`), each of a kind, so that the
//! report can break them down: the kind leads the message, as `[robot fault] ...`.

use std::fmt;

use imrs_core::Ctx;
use imrs_sim::DeviceError;

/// What an alarm is about.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum AlarmKind {
    /// A robot faulted and was reset by the operator.
    RobotFault,
    /// A feeder was found empty.
    EmptyFeeder,
    /// A pallet jammed at a station.
    Jam,
    /// A task or module did not answer in time.
    NoAnswer,
    /// A task died and was restarted.
    TaskFailed,
    /// A station waited too long for work.
    Starved,
    /// The line backed up to the gate.
    BackedUp,
    /// A step could not be done (a device refused it).
    StepFailed,
}

impl AlarmKind {
    /// Every kind, in the report's order.
    pub const ALL: [AlarmKind; 8] = [
        AlarmKind::RobotFault,
        AlarmKind::EmptyFeeder,
        AlarmKind::Jam,
        AlarmKind::NoAnswer,
        AlarmKind::TaskFailed,
        AlarmKind::Starved,
        AlarmKind::BackedUp,
        AlarmKind::StepFailed,
    ];

    /// Its name in messages and in the report.
    pub fn label(self) -> &'static str {
        match self {
            AlarmKind::RobotFault => "robot fault",
            AlarmKind::EmptyFeeder => "empty feeder",
            AlarmKind::Jam => "jam",
            AlarmKind::NoAnswer => "no answer",
            AlarmKind::TaskFailed => "task failed",
            AlarmKind::Starved => "starved",
            AlarmKind::BackedUp => "backed up",
            AlarmKind::StepFailed => "step failed",
        }
    }

    /// The kind of alarm a device error raises.
    pub fn of_error(error: &DeviceError) -> Self {
        match error {
            DeviceError::RobotFault { .. } => AlarmKind::RobotFault,
            DeviceError::EmptyFeeder { .. } => AlarmKind::EmptyFeeder,
            DeviceError::Jam { .. } => AlarmKind::Jam,
            _ => AlarmKind::StepFailed,
        }
    }

    /// The kind an alarm message was raised with, if it was raised by [`alarm`].
    pub fn of(message: &str) -> Option<Self> {
        let label = message.strip_prefix('[')?.split_once(']')?.0;
        Self::ALL.into_iter().find(|kind| kind.label() == label)
    }
}

impl fmt::Display for AlarmKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.label())
    }
}

/// Raises an alarm of `kind` for the operator.
pub fn alarm<S: Send + Sync + 'static>(ctx: &Ctx<S>, kind: AlarmKind, message: impl fmt::Display) {
    ctx.alarm(format!("[{kind}] {message}"));
}
