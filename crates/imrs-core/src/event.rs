//! The event log: what every module did, when, on the framework clock.
//!
//! A cell records module and task life, sections entered and left, port operations,
//! exceptions, deadlocks and alarms, each with its virtual timestamp. On a virtual clock in
//! single-thread mode, the same cell with the same seed yields the same log, event for
//! event. Later layers (a recorder, a report) read it as a stream through
//! [`EventLog::subscribe`].

use std::fmt;
use std::time::Duration;

use imrs_ports::{Instant, Name};

use crate::log::{Log, Record};

/// One thing that happened in a cell.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    /// When, on the cell's clock.
    pub at: Instant,
    /// In which module.
    pub module: Name,
    /// In which task or handler of it, if any.
    pub task: Option<Name>,
    /// What.
    pub kind: EventKind,
}

/// A primitive of a module's tasks on a port or a rendezvous.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Primitive {
    /// `SEND`: waits for the reply.
    Send,
    /// `RECEIVE`: waits for a message.
    Receive,
    /// `QUERY`: waits for the answer.
    Query,
    /// `waitfor`: waits for every member.
    WaitFor,
}

impl Primitive {
    /// Whether the module waits on a peer's answer (a send or a query), rather than for
    /// work to come (a receive) or for a rendezvous.
    pub fn awaits_a_peer(self) -> bool {
        matches!(self, Primitive::Send | Primitive::Query)
    }
}

impl fmt::Display for Primitive {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Primitive::Send => "send",
            Primitive::Receive => "receive",
            Primitive::Query => "query",
            Primitive::WaitFor => "waitfor",
        })
    }
}

/// What a cell that observes its primitives ([`Cell::observe`](crate::Cell::observe)) adds
/// to the event of each send, receive, query and failure. Boxed in the event, so that a
/// cell that does not observe logs events no larger for it.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Observed {
    /// How long the primitive waited.
    pub waited: Duration,
    /// The message, where the port shows its values ([`Port::shown`](imrs_ports::Port::shown)).
    pub message: Option<String>,
    /// The reply (of a send or a query), likewise.
    pub reply: Option<String>,
}

/// What happened.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum EventKind {
    /// The module was created, by `parent` if it was costarted.
    ModuleStarted {
        /// The module that costarted it.
        parent: Option<Name>,
    },
    /// Every task of the module finished.
    ModuleFinished,
    /// The module was killed.
    ModuleKilled,
    /// The module failed: a task failed beyond its restart policy.
    ModuleFailed {
        /// Why.
        reason: String,
    },
    /// A new copy of the module was started after a failure.
    ModuleRestarted {
        /// Which restart this is, from 1.
        attempt: u32,
    },
    /// A task started.
    TaskStarted,
    /// A task finished.
    TaskFinished,
    /// A task failed: it panicked or returned an error.
    TaskFailed {
        /// The panic message or the error.
        reason: String,
    },
    /// A new copy of the task was started.
    TaskRestarted {
        /// Which restart this is, from 1.
        attempt: u32,
    },
    /// The thread entered a named section.
    SectionEntered {
        /// The section.
        section: Name,
    },
    /// The thread left a named section.
    SectionLeft {
        /// The section.
        section: Name,
    },
    /// A send completed with a reply: logged while the cell observes its primitives
    /// ([`Cell::observe`](crate::Cell::observe)), as every primitive that succeeds.
    Sent {
        /// The port.
        port: Name,
        /// What a cell that observes its primitives adds.
        observed: Option<Box<Observed>>,
    },
    /// A message was received (logged while the cell observes).
    Received {
        /// The port.
        port: Name,
        /// What a cell that observes its primitives adds.
        observed: Option<Box<Observed>>,
    },
    /// A query was answered (logged while the cell observes).
    Queried {
        /// The port.
        port: Name,
        /// What a cell that observes its primitives adds.
        observed: Option<Box<Observed>>,
    },
    /// A primitive failed.
    PortError {
        /// The port.
        port: Name,
        /// The error.
        error: String,
        /// Which primitive failed.
        primitive: Primitive,
        /// What a cell that observes its primitives adds.
        observed: Option<Box<Observed>>,
    },
    /// A response handler answered a query (logged while the cell observes).
    Responded {
        /// The handler (`PORT.resp`).
        handler: Name,
    },
    /// A response handler answered a query whose querier had given up (timed out, or its
    /// module died): nobody read the answer.
    RespondedLate {
        /// The handler (`PORT.resp`).
        handler: Name,
    },
    /// An exception was raised in the module.
    ExceptionRaised {
        /// The exception (`PORT.TIMEOUT`).
        exception: Name,
    },
    /// The module's handler for an exception started.
    ExceptionHandled {
        /// The exception.
        exception: Name,
    },
    /// An exception was raised that the module has no handler for.
    ExceptionUnhandled {
        /// The exception.
        exception: Name,
    },
    /// Every member of a `waitfor` arrived, and this task went on (logged while the cell
    /// observes).
    WaitForReleased {
        /// The rendezvous.
        barrier: Name,
    },
    /// A step of a work schedule was performed.
    StepPerformed {
        /// The step.
        step: String,
    },
    /// A step of a work schedule failed and was skipped.
    StepFailed {
        /// The step.
        step: String,
        /// Why.
        error: String,
    },
    /// Every member of a cycle of modules is blocked on the next: `(module, port)` pairs,
    /// each module waiting on the port that leads to the next.
    Deadlock {
        /// The cycle.
        cycle: Vec<(Name, Name)>,
    },
    /// Something an operator should look at.
    Alarm {
        /// What.
        message: String,
    },
}

impl fmt::Display for Event {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "[{}] {}", self.at, self.module)?;
        if let Some(task) = &self.task {
            write!(f, "/{task}")?;
        }
        write!(f, ": ")?;
        match &self.kind {
            EventKind::ModuleStarted {
                parent: Some(parent),
            } => {
                write!(f, "started by {parent}")
            }
            EventKind::ModuleStarted { parent: None } => write!(f, "started"),
            EventKind::ModuleFinished => write!(f, "finished"),
            EventKind::ModuleKilled => write!(f, "killed"),
            EventKind::ModuleFailed { reason } => write!(f, "failed: {reason}"),
            EventKind::ModuleRestarted { attempt } => write!(f, "restarted (#{attempt})"),
            EventKind::TaskStarted => write!(f, "task started"),
            EventKind::TaskFinished => write!(f, "task finished"),
            EventKind::TaskFailed { reason } => write!(f, "task failed: {reason}"),
            EventKind::TaskRestarted { attempt } => write!(f, "task restarted (#{attempt})"),
            EventKind::SectionEntered { section } => write!(f, "entered {section}"),
            EventKind::SectionLeft { section } => write!(f, "left {section}"),
            EventKind::Sent { port, .. } => write!(f, "sent on {port}"),
            EventKind::Received { port, .. } => write!(f, "received on {port}"),
            EventKind::Queried { port, .. } => write!(f, "queried {port}"),
            EventKind::PortError { port, error, .. } => write!(f, "{port}: {error}"),
            EventKind::Responded { handler } => write!(f, "responded {handler}"),
            EventKind::RespondedLate { handler } => {
                write!(f, "responded {handler} after its querier gave up")
            }
            EventKind::ExceptionRaised { exception } => write!(f, "raised {exception}"),
            EventKind::ExceptionHandled { exception } => write!(f, "handling {exception}"),
            EventKind::ExceptionUnhandled { exception } => {
                write!(f, "no handler for {exception}")
            }
            EventKind::WaitForReleased { barrier } => write!(f, "waitfor {barrier} released"),
            EventKind::StepPerformed { step } => write!(f, "performed {step}"),
            EventKind::StepFailed { step, error } => write!(f, "skipped {step}: {error}"),
            EventKind::Deadlock { cycle } => {
                write!(f, "deadlock:")?;
                for (module, port) in cycle {
                    write!(f, " {module} -[{port}]->")?;
                }
                match cycle.first() {
                    Some((first, _)) => write!(f, " {first}"),
                    None => Ok(()),
                }
            }
            EventKind::Alarm { message } => write!(f, "ALARM {message}"),
        }
    }
}

impl Record for Event {
    /// Trouble at `warn`, everything else at `debug`, under the `imrs` target.
    fn trace(&self) {
        match &self.kind {
            EventKind::Deadlock { .. }
            | EventKind::Alarm { .. }
            | EventKind::ModuleFailed { .. }
            | EventKind::TaskFailed { .. }
            | EventKind::ExceptionUnhandled { .. } => tracing::warn!(target: "imrs", "{self}"),
            _ => tracing::debug!(target: "imrs", "{self}"),
        }
    }
}

/// Whether `tracing` takes the core's events (a subscriber wants `imrs` at warn or
/// finer): then an event is made even where the log would not see it.
pub(crate) fn traced() -> bool {
    tracing::enabled!(target: "imrs", tracing::Level::WARN)
}

/// The event log of a cell.
pub type EventLog = Log<Event>;
