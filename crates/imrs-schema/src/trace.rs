//! The trace of a network's instances: when each was instantiated, and how it ended. Apart
//! from the network's handle, since what records it, each instance as it starts and ends,
//! lies below the handle.

use std::fmt;

use imrs_core::Record;
use imrs_ports::{Instant, Name};

use crate::error::SchemaError;

/// How an instance ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Ending {
    /// Its behaviour said `STOP` (for a task-unit: its r-schema did).
    Stopped,
    /// Another instance (or the network) deinstantiated it, or the assemblage it is in
    /// ended.
    Deinstantiated,
    /// An assemblage whose components had all ended.
    ComponentsEnded,
    /// Its behaviour failed.
    Failed(SchemaError),
}

/// One line of a network's trace.
#[derive(Debug, Clone, PartialEq)]
pub struct TraceEntry {
    /// When, on the network's clock.
    pub at: Instant,
    /// The instance.
    pub instance: Name,
    /// `None` when it was instantiated; how it ended, when it ended.
    pub ended: Option<Ending>,
}

impl Record for TraceEntry {}

impl fmt::Display for TraceEntry {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let at = self.at.since_start().as_secs_f64();
        match &self.ended {
            None => write!(f, "{at:9.3} s  {} instantiated", self.instance),
            Some(Ending::Failed(error)) => {
                write!(f, "{at:9.3} s  {} failed: {error}", self.instance)
            }
            Some(ending) => write!(f, "{at:9.3} s  {} ended: {ending:?}", self.instance),
        }
    }
}
