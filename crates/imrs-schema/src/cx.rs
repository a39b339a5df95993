//! What an instance's set-up and behaviour can do besides reading and writing its ports.

use std::sync::Arc;
use std::time::Duration;

use imrs_ports::synchronous::{AnyPort, Input, Output, connect, connect_any};
use imrs_ports::{Instant, Name, SharedClock};

use crate::error::SchemaError;
use crate::instance::{Si, find, forall, instantiate};
use crate::schema::Schema;
use crate::scope::Scope;

/// One couplet of a connection map: a port of the new instance, by name, and a port of
/// another instance.
#[derive(Clone, Copy)]
pub enum Couplet<'a> {
    /// `Ipname ← SIPname`: the new instance's input `port` reads what `from` writes.
    Input {
        /// The new instance's input.
        port: &'static str,
        /// An output of another instance.
        from: &'a dyn AnyPort,
    },
    /// `SIPname ← Opname`: `to` reads what the new instance's output `port` writes.
    Output {
        /// An input of another instance.
        to: &'a dyn AnyPort,
        /// The new instance's output.
        port: &'static str,
    },
}

impl<'a> Couplet<'a> {
    /// `port ← from`.
    pub fn input(port: &'static str, from: &'a dyn AnyPort) -> Self {
        Self::Input { port, from }
    }

    /// `to ← port`.
    pub fn output(port: &'static str, to: &'a dyn AnyPort) -> Self {
        Self::Output { to, port }
    }
}

/// An instance's view of the network: the assemblage it instantiates into, its own name,
/// the clock.
#[derive(Clone)]
pub struct Cx {
    scope: Arc<Scope>,
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

    /// `N{V0}`: a new instance of `schema`, whose fields are its internal variables' initial
    /// values, numbered with the lowest number free in this assemblage.
    pub fn instantiate<S: Schema>(&self, schema: S) -> Result<Si<S>, SchemaError> {
        instantiate(&self.scope, None, schema)
    }

    /// `N_i{V0}`: a new instance numbered `number`; refused if `N_number` is live here.
    pub fn instantiate_as<S: Schema>(&self, number: u32, schema: S) -> Result<Si<S>, SchemaError> {
        instantiate(&self.scope, Some(number), schema)
    }

    /// `N_i{V0}{C0}`: a new instance (numbered `number`, or the lowest free number) with
    /// its connection map, each couplet checked now. If one is refused, the new instance is
    /// deinstantiated and the error names both ends.
    ///
    /// ```
    /// # use std::sync::Arc;
    /// # use imrs_ports::VirtualClock;
    /// # use imrs_schema::{Couplet, Network, seed::TClosejoint, special::Jmotor};
    /// # use imrs_sim::hand::{Hand, HandConfig};
    /// # fn main() -> Result<(), Box<dyn std::error::Error>> {
    /// # let runtime = tokio::runtime::Builder::new_current_thread().enable_all().start_paused(true).build()?;
    /// # runtime.block_on(async {
    /// # let clock = Arc::new(VirtualClock::new());
    /// # let hand = Hand::new(HandConfig::seeded(1), clock.clone());
    /// let net = Network::new("HAND", clock);
    /// let motor = net.instantiate_as(7, Jmotor::new(&hand))?;
    /// // TClosejoint{10}(Jmotor_7(desired) ← Pout)
    /// let closing = net.cx().instantiate_with(
    ///     None,
    ///     TClosejoint { del: 0.01 },
    ///     &[Couplet::output("Pout", motor.port("desired")?)],
    /// )?;
    /// // Tin reads a bool; Jmotor_7(actual) writes an f32: refused, naming both ends.
    /// let refused = net.cx().instantiate_with(
    ///     None,
    ///     TClosejoint { del: 0.01 },
    ///     &[Couplet::input("Tin", motor.port("actual")?)],
    /// );
    /// assert_eq!(
    ///     refused.unwrap_err().to_string(),
    ///     "cannot connect Jmotor_7(actual) to TClosejoint_2(Tin): Jmotor_7(actual) writes f32, \
    ///      TClosejoint_2(Tin) reads bool"
    /// );
    /// # drop(closing);
    /// # Ok::<_, Box<dyn std::error::Error>>(())
    /// # })?;
    /// # Ok(())
    /// # }
    /// ```
    pub fn instantiate_with<S: Schema>(
        &self,
        number: Option<u32>,
        schema: S,
        map: &[Couplet<'_>],
    ) -> Result<Si<S>, SchemaError> {
        let si = instantiate(&self.scope, number, schema)?;
        let connected = map.iter().try_for_each(|couplet| match *couplet {
            Couplet::Input { port, from } => Ok(connect_any(from, si.port(port)?)?),
            Couplet::Output { to, port } => Ok(connect_any(si.port(port)?, to)?),
        });
        match connected {
            Ok(()) => Ok(si),
            Err(error) => {
                si.stop();
                Err(error)
            }
        }
    }

    /// `FORALL N`: the live instances of `S` here, by number.
    pub fn forall<S: Schema>(&self) -> Vec<Si<S>> {
        forall(&self.scope)
    }

    /// The live instance `S_number` here, if there is one.
    pub fn get<S: Schema>(&self, number: u32) -> Option<Si<S>> {
        find(&self.scope, number)
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
