//! Port filters (Shin 1985, restriction 5): a task spliced into a port.
//!
//! A filtered port is cut in two. On one side the users talk to the filter as if it were
//! the owner; on the other the filter talks to the owner through the predefined port
//! `FILTER`. The owner's usage is complemented by the filter's `FILTER` end, and each user's
//! usage by the filter's end of the port, so both halves are checked by the types.

mod bounded_buffer;

use crate::end::End;
use crate::error::WireError;
use crate::meta::{Name, Named};
use crate::port::{Port, PortSpec};
use crate::usage::{Plain, Usage};
use crate::user_list::{Admits, AnyUser, UserList};

pub use bounded_buffer::{BoundedBuffer, BoundedBufferPort};

/// A port with a filter task spliced in.
///
/// Users send `Req`/`Rep` messages to the filter with their usage (the complement of `F`,
/// the filter's usage on the port); the owner talks to the filter with `FReq`/`FRep`
/// messages and usage `O` on `FILTER`.
#[derive(Debug, Clone)]
pub struct FilteredPort<Req, Rep, F, FReq, FRep, O, L = AnyUser, const N: usize = 1>
where
    F: Usage,
    O: Usage,
    L: UserList,
{
    port: Port<Req, Rep, F, L, N>,
    filter: Port<FReq, FRep, O, AnyUser, 1>,
    filter_task: Name,
}

/// The filter task's two ends: toward the users, and toward the owner (`FILTER`).
#[derive(Debug)]
pub struct FilterEnds<Req, Rep, F: Usage, FReq, FRep, O: Usage> {
    /// The port as the users see it, held by the filter.
    pub port: End<Req, Rep, F>,
    /// The predefined port `FILTER`, leading to the owner.
    pub filter: End<FReq, FRep, O::Complement>,
}

impl<Req, Rep, F, FReq, FRep, O, L, const N: usize> FilteredPort<Req, Rep, F, FReq, FRep, O, L, N>
where
    Req: Send + 'static,
    Rep: Send + 'static,
    FReq: Send + 'static,
    FRep: Send + 'static,
    F: Usage + Plain,
    O: Usage + Plain,
    O::Complement: Plain,
    F::Complement: Plain,
    L: UserList,
{
    /// Declares port `spec` with the filter task `filter_task` (a task of the owning module)
    /// spliced in. The spec's timeout applies to the owner's end of `FILTER`; its priority and
    /// user list to the users' side.
    pub fn new(spec: PortSpec, filter_task: impl Into<Name>) -> Self {
        let filter_task = filter_task.into();
        let owner_side =
            PortSpec::new(format!("{}.FILTER", spec.name()), spec.owner_name().clone())
                .with_timeout_of(&spec)
                .with_clock_of(&spec)
                .user_list([filter_task.clone()]);
        Self {
            port: Port::new(spec.without_timeout()),
            filter: Port::new(owner_side),
            filter_task,
        }
    }

    /// Shows the values on both sides of the filter as `Debug` writes them, as
    /// [`Port::shown`] does for a plain port.
    pub fn shown(self) -> Self
    where
        Req: std::fmt::Debug,
        Rep: std::fmt::Debug,
        FReq: std::fmt::Debug,
        FRep: std::fmt::Debug,
    {
        Self {
            port: self.port.shown(),
            filter: self.filter.shown(),
            filter_task: self.filter_task,
        }
    }

    /// The port's name.
    pub fn name(&self) -> &Name {
        self.port.name()
    }

    /// The port as its users see it, whose owner end the filter holds.
    pub fn users_side(&self) -> &Port<Req, Rep, F, L, N> {
        &self.port
    }

    /// The predefined port `FILTER`, between the owner and the filter.
    pub fn filter_side(&self) -> &Port<FReq, FRep, O, AnyUser, 1> {
        &self.filter
    }

    /// The owner's end: it reaches the filter, never the users directly.
    pub fn owner(&self) -> Result<End<FReq, FRep, O>, WireError> {
        self.filter.owner()
    }

    /// A user's end, for module `M` on the user list.
    pub fn user<M: Named>(&self) -> Result<End<Req, Rep, F::Complement>, WireError>
    where
        L: Admits<M>,
    {
        self.port.user::<M>()
    }

    /// A user's end, for a module known by name.
    pub fn user_named(
        &self,
        module: impl Into<Name>,
    ) -> Result<End<Req, Rep, F::Complement>, WireError> {
        self.port.user_named(module)
    }

    /// The filter task's ends. One filter at a time; a restarted filter attaches again.
    pub fn filter(&self) -> Result<FilterEnds<Req, Rep, F, FReq, FRep, O>, WireError> {
        Ok(FilterEnds {
            port: self.port.owner()?,
            filter: self.filter.user_named(self.filter_task.clone())?,
        })
    }
}
