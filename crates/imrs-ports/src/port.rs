//! Port declarations: the owner's `PORT` statement with its restrictions.

use std::any::type_name;
use std::fmt;
use std::marker::PhantomData;
use std::sync::Arc;
use std::time::Duration;

use crate::attachment::Attachment;
use crate::clock::{RealClock, SharedClock};
use crate::core::{Core, SlotId, hold};
use crate::end::End;
use crate::error::{ClaimRefused, WireError};
use crate::meta::{Name, Named, PortMeta};
use crate::presence::Presence;
use crate::priority::Priority;
use crate::process_type::ProcessType;
use crate::response::ResponseEnd;
use crate::shown::Shown;
use crate::usage::{Answers, Plain, Usage, UsageKind};
use crate::user_list::{Admits, AnyUser, UserList};

/// The restrictions of a port that are values rather than types: its name and owner,
/// timeout, priority, process type, clock, and a user list of names when the users are not
/// known as types.
#[derive(Debug, Clone)]
pub struct PortSpec {
    name: Name,
    owner: Name,
    timeout: Option<Duration>,
    user_timeout: Option<Duration>,
    priority: Priority,
    process_type: ProcessType,
    user_list: Option<Vec<Name>>,
    clock: Option<SharedClock>,
}

impl PortSpec {
    /// Port `name`, owned by module `owner`.
    pub fn new(name: impl Into<Name>, owner: impl Into<Name>) -> Self {
        Self {
            name: name.into(),
            owner: owner.into(),
            timeout: None,
            user_timeout: None,
            priority: Priority::DEFAULT,
            process_type: ProcessType::default(),
            user_list: None,
            clock: None,
        }
    }

    /// `PORT ... TIMEOUT=`: bounds the **owner's** end only. Each wait of the owner's
    /// primitives (send, receive, query, sendall, callall, answering) fails with a timeout
    /// after `timeout`; the users' ends are not bounded by it (see
    /// [`PortSpec::user_timeout`]).
    pub fn owner_timeout(mut self, timeout: Duration) -> Self {
        self.timeout = Some(timeout);
        self
    }

    /// `USE PORT ... TIMEOUT=`: bounds **every user's** end. Each wait of a user's
    /// primitives fails with a timeout after `timeout`; the owner's end is not bounded by it
    /// (see [`PortSpec::owner_timeout`]). One end may still set its own with
    /// [`End::with_timeout`](crate::End::with_timeout).
    pub fn user_timeout(mut self, timeout: Duration) -> Self {
        self.user_timeout = Some(timeout);
        self
    }

    /// `PRIORITY=n`: 1 is the most urgent.
    pub fn priority(mut self, n: u32) -> Self {
        self.priority = Priority::declared(n);
        self
    }

    /// The process class of the subprocesses this port links.
    pub fn process_type(mut self, process_type: ProcessType) -> Self {
        self.process_type = process_type;
        self
    }

    /// `USERLIST=(...)` by name, checked when a user attaches. Ports whose users are types
    /// declare a [`user_list!`](crate::user_list) instead, checked at compile time.
    pub fn user_list<I, S>(mut self, modules: I) -> Self
    where
        I: IntoIterator<Item = S>,
        S: Into<Name>,
    {
        self.user_list = Some(modules.into_iter().map(Into::into).collect());
        self
    }

    /// The clock the port's timeouts run on (the wall clock by default).
    pub fn clock(mut self, clock: SharedClock) -> Self {
        self.clock = Some(clock);
        self
    }

    /// The port's name.
    pub fn name(&self) -> &Name {
        &self.name
    }

    pub(crate) fn owner_name(&self) -> &Name {
        &self.owner
    }

    pub(crate) fn with_timeout_of(mut self, other: &PortSpec) -> Self {
        self.timeout = other.timeout;
        self.user_timeout = other.user_timeout;
        self
    }

    pub(crate) fn with_clock_of(mut self, other: &PortSpec) -> Self {
        self.clock = other.clock.clone();
        self
    }

    pub(crate) fn without_timeout(mut self) -> Self {
        self.timeout = None;
        self.user_timeout = None;
        self
    }

    /// The clock the spec names, if it names one.
    pub fn clock_of(&self) -> Option<&SharedClock> {
        self.clock.as_ref()
    }
}

/// A declared port carrying `Req` messages answered by `Rep`, whose owner's usage is `U`,
/// whose users are restricted by the user list `L`, and which admits at most `N` active
/// users (`#USERS=N`; the buffers are sized once from it).
///
/// The declaration is a handle: clones share the port, and while one lives, ends may attach
/// and re-attach (a restarted module re-attaches to the same port).
pub struct Port<Req, Rep, U: Usage, L: UserList = AnyUser, const N: usize = 1> {
    core: Arc<Core<Req, Rep>>,
    _restrictions: PhantomData<fn() -> (U, L)>,
}

impl<Req, Rep, U, L, const N: usize> Port<Req, Rep, U, L, N>
where
    Req: Send + 'static,
    Rep: Send + 'static,
    U: Usage,
    L: UserList,
{
    /// `PORT ...`: makes the port, outside any cell (on the wall clock unless `spec` names
    /// another). In a cell, `Cell::port` makes it on the cell's clock and declares it to
    /// the cell.
    ///
    /// A port whose user list is both a type (`L`) and names ([`PortSpec::user_list`]) is
    /// refused at every attach and by the [`Wiring`](crate::Wiring) with
    /// [`WireError::TwoUserLists`]: neither list silently wins.
    ///
    /// `N = 0` is refused when the port is built (`cargo build`, `cargo test`): the check is a
    /// constant evaluated for each `N`, which `cargo check` does not evaluate, since stable
    /// Rust cannot bound a const generic in a `where` clause.
    pub fn new(spec: PortSpec) -> Self {
        const {
            assert!(
                N > 0,
                "a port needs room for at least one user (#USERS >= 1)"
            )
        };
        let two_user_lists = L::NAMES.is_some() && spec.user_list.is_some();
        let user_list = match L::NAMES {
            Some(names) => Some(names.iter().map(|&name| Name::from(name)).collect()),
            None => spec.user_list.map(Vec::into_boxed_slice),
        };
        let meta = PortMeta {
            name: spec.name,
            owner: spec.owner,
            usage: U::KIND,
            user_list,
            two_user_lists,
            timeout: spec.timeout,
            user_timeout: spec.user_timeout,
            priority: spec.priority,
            process_type: spec.process_type,
        };
        let clock = spec.clock.unwrap_or_else(|| Arc::new(RealClock::new()));
        Self {
            core: Arc::new(Core::new(meta, clock, N)),
            _restrictions: PhantomData,
        }
    }

    /// Shows the port's messages and replies as `Debug` writes them, in the event log of a
    /// cell that asks for them (a recorder does; see [`shown`](crate::shown)). The first way
    /// of showing set holds, for every handle of the port.
    pub fn shown(self) -> Self
    where
        Req: std::fmt::Debug,
        Rep: std::fmt::Debug,
    {
        self.shown_with(Shown::debug())
    }

    /// Shows the port's messages and replies as `shown` writes them (see [`Port::shown`]).
    pub fn shown_with(self, shown: Shown<Req, Rep>) -> Self {
        let _first_holds = self.core.shown.set(shown);
        self
    }

    /// The port's name.
    pub fn name(&self) -> &Name {
        &self.core.meta.name
    }

    /// The clock the port's timeouts run on.
    pub fn clock(&self) -> &SharedClock {
        &self.core.clock
    }

    /// The owning module's name.
    pub fn owner_module(&self) -> &Name {
        &self.core.meta.owner
    }

    /// The process type the port was declared with: how its waits are made.
    pub fn process_type(&self) -> ProcessType {
        self.core.meta.process_type
    }

    /// This port's handler or exception `what`: `PORT.what`, as an order names it
    /// (`ask_child1.handler("STATUS")` is `ASK_CHILD1.STATUS`, `.handler("TIMEOUT")` its
    /// timeout). Make it once, and use the value wherever the handler is meant — the
    /// module's order, the handler itself — so that it cannot name another port, or another
    /// handler, by a typo.
    pub fn handler(&self, what: &str) -> Handler<Req, Rep, U, L, N> {
        Handler {
            name: Name::from(format!("{}.{what}", self.core.meta.name)),
            port: self.clone(),
        }
    }

    /// The usage of this port's owner end.
    pub fn owner_usage(&self) -> UsageKind {
        U::KIND
    }

    /// The usage of this port's user ends: the complement of the owner's.
    pub fn user_usage(&self) -> UsageKind {
        <U::Complement as Usage>::KIND
    }

    /// How many users are attached now.
    pub fn users_attached(&self) -> usize {
        self.core.users_attached()
    }

    /// Checks a remote module's claim to attach as a user, by its name's text alone, and
    /// gives the module's name: refused if it is not on the port's user list, every user
    /// place is taken, or the name is new and the process keeps
    /// [`Name::MOST_FROM_PEERS`] made from peers already. A transport checks this before
    /// it attaches a module a peer names, so that a refused claim leaves no name behind
    /// (names are kept for the life of the process, see [`Name`]).
    pub fn claim(&self, module: &str) -> Result<Name, ClaimRefused> {
        let port = self.core.meta.name.clone();
        if !self.core.meta.admits(module) {
            Err(ClaimRefused::NotOnUserList {
                port,
                module: module.to_owned(),
            })
        } else if self.core.users_attached() >= self.core.capacity() {
            Err(ClaimRefused::Full {
                port,
                module: module.to_owned(),
                capacity: self.core.capacity(),
            })
        } else {
            Name::from_peer(module).ok_or_else(|| ClaimRefused::TooManyNames {
                port,
                module: module.to_owned(),
            })
        }
    }

    /// Whether module `module` may use this port by its user list (any module, on a port
    /// without one). Makes no name.
    pub fn admits(&self, module: &str) -> bool {
        self.core.meta.admits(module)
    }

    /// Attaches the owner end. One owner end at a time; after it is dropped (its module
    /// died), a new copy of the module may attach again.
    pub fn owner(&self) -> Result<End<Req, Rep, U>, WireError>
    where
        U: Plain,
    {
        Ok(End::new(self.attach_owner()?))
    }

    /// Attaches a user end for module `M`, whose presence on the user list is checked at
    /// compile time. The end's usage is the complement of the owner's.
    pub fn user<M: Named>(&self) -> Result<End<Req, Rep, U::Complement>, WireError>
    where
        L: Admits<M>,
        U::Complement: Plain,
    {
        self.user_named(M::NAME)
    }

    /// Attaches a user end for the module named `module`, checking the user list now.
    pub fn user_named(
        &self,
        module: impl Into<Name>,
    ) -> Result<End<Req, Rep, U::Complement>, WireError>
    where
        U::Complement: Plain,
    {
        Ok(End::new(attach_user(&self.core, module.into())?))
    }

    pub(crate) fn attach_owner(&self) -> Result<Attachment<Req, Rep>, WireError> {
        let meta = &self.core.meta;
        meta.check_user_lists()?;
        if !self.core.attach_owner() {
            return Err(WireError::OwnerTaken {
                port: meta.name.clone(),
                module: meta.owner.clone(),
            });
        }
        hold(&self.core, SlotId::Owner, &meta.owner, Presence::current());
        Ok(Attachment {
            core: Arc::clone(&self.core),
            at: SlotId::Owner,
            module: meta.owner.clone(),
            timeout: meta.timeout,
            parked: false,
        })
    }

    pub(crate) fn core(&self) -> &Arc<Core<Req, Rep>> {
        &self.core
    }
}

impl<Req, Rep, U, L, const N: usize> Port<Req, Rep, U, L, N>
where
    Req: Send + 'static,
    Rep: Send + 'static,
    U: Answers,
    L: UserList,
{
    /// Attaches the side of this port that answers queries, for module `module`, with its
    /// response handler, which reads the module's state `S`: the owner end of a `RESPONSE`
    /// port (refused unless `module` is its owner), or a user end of a `QUERY` or `CALLALL`
    /// port (checked against the user list and the number of users). In a module, give the
    /// handler to [`ModuleSpec::respond`] instead, which attaches it for the module.
    ///
    /// [`ModuleSpec::respond`]: https://docs.rs/imrs-core/latest/imrs_core/struct.ModuleSpec.html#method.respond
    pub fn answer<S>(
        &self,
        module: impl Into<Name>,
        handler: impl Fn(&S, Req) -> Rep + Send + Sync + 'static,
    ) -> Result<ResponseEnd<Req, Rep, S>, WireError> {
        let module = module.into();
        let attachment = if U::OWNER_ANSWERS {
            if module != self.core.meta.owner {
                return Err(WireError::NotOwner {
                    port: self.core.meta.name.clone(),
                    module,
                    owner: self.core.meta.owner.clone(),
                });
            }
            self.attach_owner()?
        } else {
            attach_user(&self.core, module)?
        };
        Ok(ResponseEnd::new(attachment, Box::new(handler)))
    }
}

impl<Req, Rep, U: Usage, L: UserList, const N: usize> From<&Port<Req, Rep, U, L, N>> for Name {
    /// The port's name: a port is named through its declaration.
    fn from(port: &Port<Req, Rep, U, L, N>) -> Self {
        port.core.meta.name.clone()
    }
}

/// A handler of a port, `PORT.what`: a response handler, or an exception such as the
/// port's `TIMEOUT`. Made by [`Port::handler`]; the order ranks it by its name.
pub struct Handler<Req, Rep, U: Usage, L: UserList = AnyUser, const N: usize = 1> {
    name: Name,
    port: Port<Req, Rep, U, L, N>,
}

impl<Req, Rep, U: Usage, L: UserList, const N: usize> Handler<Req, Rep, U, L, N> {
    /// `PORT.what`, as an order names it.
    pub fn name(&self) -> Name {
        self.name.clone()
    }

    /// The port it handles.
    pub fn port(&self) -> &Port<Req, Rep, U, L, N> {
        &self.port
    }
}

impl<Req, Rep, U: Usage, L: UserList, const N: usize> From<&Handler<Req, Rep, U, L, N>> for Name {
    fn from(handler: &Handler<Req, Rep, U, L, N>) -> Self {
        handler.name.clone()
    }
}

impl<Req, Rep, U: Usage, L: UserList, const N: usize> From<Handler<Req, Rep, U, L, N>> for Name {
    fn from(handler: Handler<Req, Rep, U, L, N>) -> Self {
        handler.name
    }
}

impl<Req, Rep, U: Usage, L: UserList, const N: usize> Clone for Handler<Req, Rep, U, L, N> {
    fn clone(&self) -> Self {
        Self {
            name: self.name.clone(),
            port: self.port.clone(),
        }
    }
}

impl<Req, Rep, U: Usage, L: UserList, const N: usize> fmt::Debug for Handler<Req, Rep, U, L, N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Handler({})", self.name)
    }
}

/// Attaches a user of `core`: checks the user list and the number of active users.
pub(crate) fn attach_user<Req: Send + 'static, Rep: Send + 'static>(
    core: &Arc<Core<Req, Rep>>,
    module: Name,
) -> Result<Attachment<Req, Rep>, WireError> {
    let meta = &core.meta;
    meta.check_user_lists()?;
    if !meta.admits(module.as_str()) {
        return Err(WireError::NotOnUserList {
            port: meta.name.clone(),
            module,
        });
    }
    let Some(index) = core.attach_user() else {
        return Err(WireError::TooManyUsers {
            port: meta.name.clone(),
            module,
            capacity: core.capacity(),
        });
    };
    hold(core, SlotId::User(index), &module, Presence::current());
    // Whoever waits for a user (`End::peer_attached`) looks again.
    core.user_attached.wake();
    Ok(Attachment {
        core: Arc::clone(core),
        at: SlotId::User(index),
        module,
        timeout: meta.user_timeout,
        parked: false,
    })
}

impl<Req, Rep, U: Usage, L: UserList, const N: usize> Clone for Port<Req, Rep, U, L, N> {
    fn clone(&self) -> Self {
        self.core.add_declaration();
        Self {
            core: Arc::clone(&self.core),
            _restrictions: PhantomData,
        }
    }
}

impl<Req, Rep, U: Usage, L: UserList, const N: usize> Drop for Port<Req, Rep, U, L, N> {
    fn drop(&mut self) {
        self.core.drop_declaration();
    }
}

impl<Req, Rep, U: Usage, L: UserList, const N: usize> fmt::Debug for Port<Req, Rep, U, L, N> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let meta = &self.core.meta;
        f.debug_struct("Port")
            .field("name", &meta.name)
            .field("owner", &meta.owner)
            .field("usage", &meta.usage)
            .field("request", &type_name::<Req>())
            .field("reply", &type_name::<Rep>())
            .field("users", &N)
            .field("owner_timeout", &meta.timeout)
            .field("user_timeout", &meta.user_timeout)
            .field("priority", &meta.priority)
            .finish()
    }
}
