//! An instance's view of the network: its name and number, the clock, and the connecting
//! of ports. Its instantiating is with the instantiation, in `instance.rs`: every schema is
//! given a context, so the context names no schema.

use std::sync::Arc;
use std::time::Duration;

use imrs_ports::synchronous::{AnyPort, Input, Output, connect, connect_any};
use imrs_ports::{Instant, Name, SharedClock};

use crate::error::SchemaError;
use crate::scope::Scope;

/// An instance's view of the network: the assemblage it instantiates into, its own name,
/// the clock.
#[derive(Clone)]
pub struct Cx {
    pub(crate) scope: Arc<Scope>,
    me: Name,
    number: u32,
}

impl Cx {
    pub(crate) fn new(scope: Arc<Scope>, me: Name, number: u32) -> Self {
        Self { scope, me, number }
    }

    /// The instance this context belongs to (the network's top: `/`).
    pub fn me(&self) -> &Name {
        &self.me
    }

    /// The instance's number `i` (0 for the network's top). A special schema reads which
    /// joint or sensor it stands for here: the `i`th instance of `Jmotor` drives joint `i`.
    pub fn number(&self) -> u32 {
        self.number
    }

    /// A couplet of a connection map, `Ipname ← SIPname`, checked by the compiler.
    pub fn connect<T: Clone + Send + 'static>(&self, output: &Output<T>, input: &Input<T>) {
        connect(output, input);
    }

    /// A couplet given by name, checked now: the directions, and that both ends carry one
    /// type. The error names both ends.
    pub fn connect_any(
        &self,
        output: &dyn AnyPort,
        input: &dyn AnyPort,
    ) -> Result<(), SchemaError> {
        Ok(connect_any(output, input)?)
    }

    /// The network's clock.
    pub fn clock(&self) -> &SharedClock {
        &self.scope.net.clock
    }

    /// The time now.
    pub fn now(&self) -> Instant {
        self.scope.net.clock.now()
    }

    /// Waits `duration` on the network's clock.
    pub async fn delay(&self, duration: Duration) {
        let clock = &self.scope.net.clock;
        clock.sleep_until(clock.now() + duration).await;
    }
}
