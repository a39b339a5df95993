//! What every assemblage of a network shares: its clock, the processor its instances run
//! on, and the trace of their lives. Apart from the network's handle, since each
//! assemblage's inside holds it, and the handle holds the top one.

use imrs_core::{Log, Processor};
use imrs_ports::{Name, SharedClock};

use crate::trace::{Ending, TraceEntry};

pub(crate) struct Net {
    pub(crate) clock: SharedClock,
    pub(crate) processor: Processor,
    pub(crate) trace: Log<TraceEntry>,
}

impl Net {
    pub(crate) fn record(&self, instance: &Name, ended: Option<Ending>) {
        self.trace.record(TraceEntry {
            at: self.clock.now(),
            instance: instance.clone(),
            ended,
        });
    }
}
