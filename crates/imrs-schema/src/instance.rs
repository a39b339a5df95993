//! Instantiation, the life of an instance, and the handle to one; the couplets of a
//! connection map, and a context's instantiating.

use std::any::Any;
use std::fmt;
use std::sync::Arc;

use imrs_ports::Name;
use imrs_ports::synchronous::{AnyPort, connect_any};

use crate::cx::Cx;
use crate::error::SchemaError;
use crate::ports::Ports;
use crate::race::{Either, race};
use crate::schema::{Flow, Kind, Schema};
use crate::scope::{Control, Member, Scope};
use crate::trace::Ending;

/// A schema instance (an SI): its name `N_i`, its number, its ports.
///
/// Cheap to clone. Dropping it leaves the instance running.
pub struct Si<S: Schema> {
    number: u32,
    ports: Arc<S::Ports>,
    control: Arc<Control>,
}

impl<S: Schema> Clone for Si<S> {
    fn clone(&self) -> Self {
        Self {
            number: self.number,
            ports: Arc::clone(&self.ports),
            control: Arc::clone(&self.control),
        }
    }
}

impl<S: Schema> fmt::Debug for Si<S> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Si({})", self.name())
    }
}

impl<S: Schema> Si<S> {
    /// Its full name: the assemblages it is in, then `N_i`.
    pub fn name(&self) -> &Name {
        &self.control.name
    }

    /// `i`: its number in its assemblage.
    pub fn number(&self) -> u32 {
        self.number
    }

    /// Its ports, to connect statically (types checked by the compiler).
    pub fn ports(&self) -> &S::Ports {
        &self.ports
    }

    /// Its port named `name`, to connect by name (types checked at run time).
    pub fn port(&self, name: &str) -> Result<&dyn AnyPort, SchemaError> {
        self.ports
            .list()
            .into_iter()
            .find(|(known, _)| *known == name)
            .map(|(_, port)| port)
            .ok_or_else(|| SchemaError::NoPort {
                instance: self.name().clone(),
                port: name.into(),
            })
    }

    /// `STOP{N_i}`: deinstantiates it (and its components) at its next suspension point.
    pub fn stop(&self) {
        self.control.stop();
    }

    /// Whether it is still live.
    pub fn is_live(&self) -> bool {
        !self.control.has_ended()
    }

    /// Completes once it has ended and its ports are closed.
    pub async fn ended(&self) {
        self.control.ended().await;
    }

    fn from_member(number: u32, member: Member) -> Option<Self> {
        let ports = member.ports.downcast::<S::Ports>().ok()?;
        Some(Self {
            number,
            ports,
            control: member.control,
        })
    }
}

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

// Here, beside the instantiation they ask for, rather than with the context: every schema
// is given a context, so the context's own file names no schema.
impl Cx {
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
}

/// The live instances of `S` in `scope` (and, for a schema found everywhere, in the
/// assemblages around it), by number.
fn forall<S: Schema>(scope: &Arc<Scope>) -> Vec<Si<S>> {
    let mut found = Vec::new();
    let mut at = Some(scope);
    while let Some(scope) = at {
        found.extend(
            scope
                .of(S::NAME)
                .into_iter()
                .filter_map(|(n, member)| Si::from_member(n, member)),
        );
        at = S::EVERYWHERE.then_some(scope.parent.as_ref()).flatten();
    }
    found
}

/// The instance `S_number` in `scope`, if it is live.
fn find<S: Schema>(scope: &Arc<Scope>, number: u32) -> Option<Si<S>> {
    forall::<S>(scope)
        .into_iter()
        .find(|si| si.number == number)
}

/// The instantiation operation: a new instance of `schema` (its internal variables set)
/// in `scope`, numbered `number` or the lowest free number.
fn instantiate<S: Schema>(
    scope: &Arc<Scope>,
    number: Option<u32>,
    mut schema: S,
) -> Result<Si<S>, SchemaError> {
    let number = scope.reserve(S::NAME, number)?;
    let label = schema.label().unwrap_or(S::NAME);
    let name: Name = format!("{}{}_{}", scope.path, label, number).into();
    let inside = scope.inside(&name);
    let control = Arc::new(Control::new(name.clone(), Arc::clone(&inside)));
    // An assemblage or a task-unit sets up its components inside itself; a task-unit's
    // r-schema is one of them, so it instantiates inside too. A plain schema's instances
    // are components of the assemblage it is in.
    let set_up_in = if S::KIND == Kind::Schema {
        scope
    } else {
        &inside
    };
    let behave_in = if S::KIND == Kind::TaskUnit {
        &inside
    } else {
        scope
    };
    let set_up = Cx::new(Arc::clone(set_up_in), name.clone(), number);
    let ports = match schema.set_up(&set_up) {
        Ok(ports) => Arc::new(ports),
        Err(error) => {
            inside.stop_all();
            scope.remove(S::NAME, number);
            return Err(error);
        }
    };
    scope.fill(
        S::NAME,
        number,
        Member {
            ports: Arc::clone(&ports) as Arc<dyn Any + Send + Sync>,
            control: Arc::clone(&control),
        },
    );
    scope.net.record(&name, None);
    let behave = Cx::new(Arc::clone(behave_in), name, number);
    let si = Si {
        number,
        ports: Arc::clone(&ports),
        control: Arc::clone(&control),
    };
    let scope = Arc::clone(scope);
    let processor = scope.net.processor.clone();
    // The job runs on the network's processor; its handle is not needed.
    drop(processor.spawn(live(schema, ports, behave, control, scope, number)));
    Ok(si)
}

/// The life of an instance: its behaviour cycles (or, for an assemblage, its components
/// run) until it ends; then its components stop, its ports close and it leaves its
/// assemblage.
async fn live<S: Schema>(
    mut schema: S,
    ports: Arc<S::Ports>,
    cx: Cx,
    control: Arc<Control>,
    scope: Arc<Scope>,
    number: u32,
) {
    let ending = if S::KIND == Kind::Assemblage {
        match race(control.stopped(), control.inside.emptied()).await {
            Either::Left(()) => Ending::Deinstantiated,
            Either::Right(()) => Ending::ComponentsEnded,
        }
    } else {
        loop {
            match race(control.stopped(), schema.behavior(&ports, &cx)).await {
                Either::Left(()) => break Ending::Deinstantiated,
                Either::Right(Ok(Flow::Continue)) => {}
                Either::Right(Ok(Flow::Stop)) => break Ending::Stopped,
                Either::Right(Err(error)) => break Ending::Failed(error),
            }
        }
    };
    // Its components end first (each at its next suspension point), so that an instance
    // ends only once everything inside it has.
    control.inside.stop_all();
    control.inside.emptied().await;
    ports.list().iter().for_each(|(_, port)| port.close());
    drop(schema);
    scope.remove(S::NAME, number);
    scope.net.record(&control.name, Some(ending));
    control.end();
}
