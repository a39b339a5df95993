//! A schema network: the handle to its top-level assemblage, through which the cell
//! instantiates at the top, reads the trace, and stops every instance.

use std::sync::Arc;

use imrs_core::{Log, Processor};
use imrs_ports::{Name, SharedClock};

use crate::cx::Cx;
use crate::error::SchemaError;
use crate::instance::Si;
use crate::net::Net;
use crate::schema::Schema;
use crate::scope::Scope;
use crate::trace::TraceEntry;

/// A network of schema instances: the top-level assemblage.
///
/// Its instances run on one [`Processor`] — the seed's processes "close together in
/// communication space" — which polls woken instances in the order they woke, so that
/// all are "treated equally with respect to resource access", and a run on virtual time
/// is reproducible.
#[derive(Clone)]
pub struct Network {
    top: Arc<Scope>,
}

impl Network {
    /// An empty network on `clock`, its processor named `name`.
    ///
    /// # Panics
    ///
    /// Outside a tokio runtime, as the processor's task is spawned on it.
    pub fn new(name: impl Into<Name>, clock: SharedClock) -> Self {
        let net = Arc::new(Net {
            clock,
            processor: Processor::new(name),
            trace: Log::new(),
        });
        Self {
            top: Scope::top(net),
        }
    }

    /// The network's top, as a context to instantiate and connect in.
    pub fn cx(&self) -> Cx {
        Cx::new(Arc::clone(&self.top), "/".into(), 0)
    }

    /// Instantiates `schema` at the top, with the lowest free number.
    pub fn instantiate<S: Schema>(&self, schema: S) -> Result<Si<S>, SchemaError> {
        self.cx().instantiate(schema)
    }

    /// Instantiates `schema` at the top as number `number`.
    pub fn instantiate_as<S: Schema>(&self, number: u32, schema: S) -> Result<Si<S>, SchemaError> {
        self.cx().instantiate_as(number, schema)
    }

    /// The live instances of `S` at the top.
    pub fn forall<S: Schema>(&self) -> Vec<Si<S>> {
        self.cx().forall()
    }

    /// The instantiations and endings kept so far, in order: every one, or past the log's
    /// capacity the most recent.
    pub fn trace(&self) -> Vec<TraceEntry> {
        self.top.net.trace.snapshot()
    }

    /// The trace as a log: bounded like the cell's event log (by default the most recent
    /// [`Log::DEFAULT_CAPACITY`] entries), and streamed to subscribers, so that a network
    /// that instantiates without end — `Object?` does — runs in fixed memory.
    pub fn log(&self) -> &Log<TraceEntry> {
        &self.top.net.trace
    }

    /// Deinstantiates every instance.
    pub fn stop(&self) {
        self.top.stop_all();
    }

    /// Completes once no instance is left at the top.
    pub async fn ended(&self) {
        self.top.emptied().await;
    }

    /// The processor the instances run on: a module placed on it shares their turns.
    pub fn processor(&self) -> &Processor {
        &self.top.net.processor
    }
}
