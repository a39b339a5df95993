//! Instantiation, the life of an instance, and the handle to one.

use std::any::Any;
use std::fmt;
use std::sync::Arc;

use imrs_ports::Name;
use imrs_ports::synchronous::AnyPort;

use crate::cx::Cx;
use crate::error::SchemaError;
use crate::network::Ending;
use crate::ports::Ports;
use crate::race::{Either, race};
use crate::schema::{Flow, Kind, Schema};
use crate::scope::{Control, Member, Scope};

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

/// The live instances of `S` in `scope` (and, for a schema found everywhere, in the
/// assemblages around it), by number.
pub(crate) fn forall<S: Schema>(scope: &Arc<Scope>) -> Vec<Si<S>> {
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
pub(crate) fn find<S: Schema>(scope: &Arc<Scope>, number: u32) -> Option<Si<S>> {
    forall::<S>(scope)
        .into_iter()
        .find(|si| si.number == number)
}

/// The instantiation operation: a new instance of `schema` (its internal variables set)
/// in `scope`, numbered `number` or the lowest free number.
pub(crate) fn instantiate<S: Schema>(
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
