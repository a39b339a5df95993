//! Wiring a cell: ports found by name, checked once when ends attach (the seed's "load
//! time"), for modules compiled apart from the ports they use.

use std::any::{Any, TypeId, type_name};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::sync::Arc;

use crate::core::Core;
use crate::end::End;
use crate::error::WireError;
use crate::meta::{Name, PortMeta};
use crate::port::{Port, attach_user};
use crate::response::ResponseEnd;
use crate::usage::{self, Plain, Usage};
use crate::user_list::UserList;

/// A port as the wiring knows it: its declaration, with the message types erased.
trait Declared: Send + Sync {
    fn meta(&self) -> &PortMeta;
    fn types(&self) -> (TypeId, TypeId, &'static str, &'static str);
    /// The sizes of the request and reply types, in bytes.
    fn sizes(&self) -> (usize, usize);
    fn core(&self) -> Arc<dyn Any + Send + Sync>;
    fn capacity(&self) -> usize;
}

impl<Req, Rep, U, L, const N: usize> Declared for Port<Req, Rep, U, L, N>
where
    Req: Send + 'static,
    Rep: Send + 'static,
    U: Usage,
    L: UserList,
{
    fn meta(&self) -> &PortMeta {
        &self.core().meta
    }

    fn types(&self) -> (TypeId, TypeId, &'static str, &'static str) {
        (
            TypeId::of::<Req>(),
            TypeId::of::<Rep>(),
            type_name::<Req>(),
            type_name::<Rep>(),
        )
    }

    fn sizes(&self) -> (usize, usize) {
        (size_of::<Req>(), size_of::<Rep>())
    }

    fn core(&self) -> Arc<dyn Any + Send + Sync> {
        Port::core(self).clone()
    }

    fn capacity(&self) -> usize {
        N
    }
}

/// The ports of a cell by name, and every wiring problem met so far.
///
/// Each call that attaches an end returns its own result; [`Wiring::check`] lists every
/// problem at once, each naming its port and module.
#[derive(Default)]
pub struct Wiring {
    ports: BTreeMap<Name, Box<dyn Declared>>,
    /// The ports each module owns, in name order: read at every module start, which would
    /// otherwise look through every port of the cell.
    owners: BTreeMap<Name, Vec<Name>>,
    /// Ports whose owner runs in another process: their owner is checked there.
    elsewhere: BTreeSet<Name>,
    problems: Vec<WireError>,
}

impl Wiring {
    /// No ports yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Makes `port` known by its name. The wiring keeps a handle to it.
    pub fn declare<Req, Rep, U, L, const N: usize>(
        &mut self,
        port: &Port<Req, Rep, U, L, N>,
    ) -> Result<(), WireError>
    where
        Req: Send + 'static,
        Rep: Send + 'static,
        U: Usage,
        L: UserList,
    {
        let name = port.name().clone();
        self.note(Port::core(port).meta.check_user_lists())?;
        if self.ports.contains_key(&name) {
            return self.note(Err(WireError::DuplicatePort {
                port: name,
                module: port.owner_module().clone(),
            }));
        }
        let owned = self.owners.entry(port.owner_module().clone()).or_default();
        let at = owned.partition_point(|known| *known < name);
        owned.insert(at, name.clone());
        self.ports.insert(name, Box::new(port.clone()));
        Ok(())
    }

    /// Makes `port` known by its name, as [`Wiring::declare`] does, for a port whose owner
    /// runs in another process (a transport's imported port): its users are checked here,
    /// its owner in its own process.
    pub fn declare_elsewhere<Req, Rep, U, L, const N: usize>(
        &mut self,
        port: &Port<Req, Rep, U, L, N>,
    ) -> Result<(), WireError>
    where
        Req: Send + 'static,
        Rep: Send + 'static,
        U: Usage,
        L: UserList,
    {
        self.declare(port)?;
        self.elsewhere.insert(port.name().clone());
        Ok(())
    }

    /// Whether `port` was declared as owned in another process.
    pub fn owned_elsewhere(&self, port: &str) -> bool {
        self.elsewhere.iter().any(|name| name.as_str() == port)
    }

    /// Attaches module `module` to port `port` with usage `U` and message types `Req`/`Rep`,
    /// checking everything the types could not: that the port exists, carries these types,
    /// has a usage `U` complements, admits the module, and has room for another user.
    pub fn use_port<Req, Rep, U>(
        &mut self,
        module: &str,
        port: &str,
    ) -> Result<End<Req, Rep, U>, WireError>
    where
        Req: Send + 'static,
        Rep: Send + 'static,
        U: Usage + Plain,
    {
        let attached = self
            .core::<Req, Rep>(module, port, U::KIND)
            .and_then(|core| attach_user(&core, module.into()));
        self.note(attached.map(End::new))
    }

    /// As [`Wiring::use_port`], for a `RESPONSE` user with its handler.
    pub fn use_responder<Req, Rep, S>(
        &mut self,
        module: &str,
        port: &str,
        handler: impl Fn(&S, Req) -> Rep + Send + Sync + 'static,
    ) -> Result<ResponseEnd<Req, Rep, S>, WireError>
    where
        Req: Send + 'static,
        Rep: Send + 'static,
    {
        let attached = self
            .core::<Req, Rep>(module, port, usage::Response::KIND)
            .and_then(|core| attach_user(&core, module.into()));
        self.note(attached.map(|attachment| ResponseEnd::new(attachment, Box::new(handler))))
    }

    /// What the wiring knows of port `port`, if it was declared.
    pub fn port_info(&self, port: &str) -> Option<PortInfo> {
        let declared = self.ports.get(&Name::from(port))?;
        let meta = declared.meta();
        let (_, _, request, reply) = declared.types();
        let (request_size, reply_size) = declared.sizes();
        Some(PortInfo {
            name: meta.name.clone(),
            owner: meta.owner.clone(),
            usage: meta.usage,
            user_list: meta.user_list.as_ref().map(|list| list.to_vec()),
            capacity: declared.capacity(),
            request,
            reply,
            request_size,
            reply_size,
            owner_timeout: meta.timeout,
            user_timeout: meta.user_timeout,
            priority: meta.priority,
        })
    }

    /// The names of every declared port, in order.
    pub fn port_names(&self) -> impl Iterator<Item = &Name> {
        self.ports.keys()
    }

    /// The names of the declared ports whose owner is `module`, in order.
    pub fn owned_by<'a>(&'a self, module: &'a Name) -> impl Iterator<Item = &'a Name> {
        self.owners.get(module).into_iter().flatten()
    }

    /// What the wiring knows of every declared port, in name order.
    pub fn ports(&self) -> Vec<PortInfo> {
        self.ports
            .keys()
            .filter_map(|name| self.port_info(name.as_str()))
            .collect()
    }

    /// Every problem met so far, or `Ok` if there was none.
    pub fn check(&self) -> Result<(), WireErrors> {
        if self.problems.is_empty() {
            Ok(())
        } else {
            Err(WireErrors(self.problems.clone()))
        }
    }

    fn core<Req, Rep>(
        &self,
        module: &str,
        port: &str,
        user_usage: usage::UsageKind,
    ) -> Result<Arc<Core<Req, Rep>>, WireError>
    where
        Req: Send + 'static,
        Rep: Send + 'static,
    {
        let (port, module) = (Name::from(port), Name::from(module));
        let Some(declared) = self.ports.get(&port) else {
            return Err(WireError::UnknownPort { port, module });
        };
        let meta = declared.meta();
        let (request, reply, request_name, reply_name) = declared.types();
        if (request, reply) != (TypeId::of::<Req>(), TypeId::of::<Rep>()) {
            return Err(WireError::TypeMismatch {
                port,
                module,
                declared: format!("{request_name} -> {reply_name}"),
                used: format!("{} -> {}", type_name::<Req>(), type_name::<Rep>()),
            });
        }
        if !meta.usage.complements(user_usage) {
            return Err(WireError::UsageMismatch {
                port,
                module,
                owner: meta.usage,
                user: user_usage,
            });
        }
        Ok(declared
            .core()
            .downcast::<Core<Req, Rep>>()
            .expect("the type ids were compared above"))
    }

    fn note<T>(&mut self, result: Result<T, WireError>) -> Result<T, WireError> {
        if let Err(problem) = &result {
            self.problems.push(problem.clone());
        }
        result
    }
}

impl fmt::Debug for Wiring {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Wiring")
            .field("ports", &self.ports.keys().collect::<Vec<_>>())
            .field("problems", &self.problems)
            .finish()
    }
}

/// A declared port, as the wiring describes it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PortInfo {
    /// The port's name.
    pub name: Name,
    /// The module declared as its owner.
    pub owner: Name,
    /// The owner's usage.
    pub usage: crate::usage::UsageKind,
    /// The user list, if the port has one.
    pub user_list: Option<Vec<Name>>,
    /// The number of active users it allows.
    pub capacity: usize,
    /// The request type's name.
    pub request: &'static str,
    /// The reply type's name.
    pub reply: &'static str,
    /// The request type's size in memory, in bytes: what a fixed-size message of it takes.
    pub request_size: usize,
    /// The reply type's size in memory, in bytes.
    pub reply_size: usize,
    /// The timeout that bounds the owner's end ([`PortSpec::owner_timeout`]), if any.
    ///
    /// [`PortSpec::owner_timeout`]: crate::PortSpec::owner_timeout
    pub owner_timeout: Option<std::time::Duration>,
    /// The timeout that bounds each user's end ([`PortSpec::user_timeout`]), if any.
    ///
    /// [`PortSpec::user_timeout`]: crate::PortSpec::user_timeout
    pub user_timeout: Option<std::time::Duration>,
    /// The port's priority.
    pub priority: crate::Priority,
}

/// Every wiring problem of a cell, each naming its port and module.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WireErrors(pub Vec<WireError>);

impl fmt::Display for WireErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "{} wiring problem(s):", self.0.len())?;
        for problem in &self.0 {
            writeln!(f, "  - {problem}")?;
        }
        Ok(())
    }
}

impl std::error::Error for WireErrors {}
