//! A cell: the clock, the event log, the wiring, and the modules running in it.

use std::fmt;
use std::sync::Arc;
use std::sync::atomic::Ordering;

use imrs_ports::usage::{Plain, Usage};
use imrs_ports::{
    End, FilteredPort, Instant, Name, Port, PortSpec, SharedClock, UserList, VirtualClock,
    WireError,
};

use crate::check::{CellErrors, check};
use crate::decl::ModuleDecl;
use crate::event::EventLog;
use crate::launch::{Factory, spawn_module, supervisor};
use crate::module::spec::ModuleSpec;
use crate::processor::Processor;
use crate::shared::{CellShared, ModuleHandle, lock};
use crate::supervision::RestartPolicy;
use crate::tree::ModuleTree;

/// Whether two handles name the same clock: the same object, not only the same kind.
fn same_clock(a: &SharedClock, b: &SharedClock) -> bool {
    std::ptr::addr_eq(Arc::as_ptr(a), Arc::as_ptr(b))
}

/// A port (or pair of ports) that can be declared to a cell: see [`Cell::declare`].
pub trait Declare: sealed::Sealed {
    /// Declares `self` to `cell`.
    #[doc(hidden)]
    fn declare_to(&self, cell: &Cell) -> Result<(), WireError>;
}

mod sealed {
    pub trait Sealed {}
}

impl<Req, Rep, U, L, const N: usize> sealed::Sealed for Port<Req, Rep, U, L, N>
where
    U: Usage,
    L: UserList,
{
}

impl<Req, Rep, U, L, const N: usize> Declare for Port<Req, Rep, U, L, N>
where
    Req: Send + 'static,
    Rep: Send + 'static,
    U: Usage,
    L: UserList,
{
    fn declare_to(&self, cell: &Cell) -> Result<(), WireError> {
        cell.declare_port(self)
    }
}

impl<Req, Rep, F, FReq, FRep, O, L, const N: usize> sealed::Sealed
    for FilteredPort<Req, Rep, F, FReq, FRep, O, L, N>
where
    F: Usage,
    O: Usage,
    L: UserList,
{
}

/// A filtered port: the users' side under the port's name, and the owner's side as
/// `PORT.FILTER`.
impl<Req, Rep, F, FReq, FRep, O, L, const N: usize> Declare
    for FilteredPort<Req, Rep, F, FReq, FRep, O, L, N>
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
    fn declare_to(&self, cell: &Cell) -> Result<(), WireError> {
        cell.declare_port(self.users_side())?;
        cell.declare_port(self.filter_side())
    }
}

/// A work cell: its clock, its event log, its ports by name, and its modules.
///
/// Modules run as tokio tasks, in parallel on a multi-thread runtime, or one at a time on a
/// current-thread runtime — which, on a [`VirtualClock`](imrs_ports::VirtualClock), makes
/// a run reproducible event for event. Modules that talk at every turn may share one task
/// instead: [`Cell::start_on`] a [`Processor`].
#[derive(Clone)]
pub struct Cell {
    shared: Arc<CellShared>,
}

impl Cell {
    /// A cell on `clock`.
    pub fn new(clock: SharedClock) -> Self {
        let shared = Arc::new(CellShared::new(clock));
        // The deadlock watchdog, on a clock that needs one, once a runtime runs.
        crate::watchdog::watch(&shared);
        Self { shared }
    }

    /// How long a deadlock cycle may stand before it is named, on a clock other than a
    /// virtual one (on virtual time it is named as it closes): a
    /// [`EventKind::Deadlock`](crate::EventKind::Deadlock) event, from the wait that closed
    /// it. A send or a query answered without waiting is never looked at.
    pub const DEADLOCK_BOUND: std::time::Duration = crate::watchdog::BOUND;

    /// A cell on a new virtual clock, and that clock, to drive it.
    pub fn virtual_clock() -> (Self, VirtualClock) {
        let clock = VirtualClock::new();
        (Self::new(Arc::new(clock.clone())), clock)
    }

    /// The cell's clock.
    pub fn clock(&self) -> &SharedClock {
        &self.shared.clock
    }

    /// The time now, on the cell's clock.
    pub fn now(&self) -> Instant {
        self.shared.clock.now()
    }

    /// The cell's event log.
    pub fn events(&self) -> &EventLog {
        &self.shared.events
    }

    /// Observes the primitives from now on (or no more): each send, receive, query, waitfor
    /// and response handler's answer that succeeds is logged, saying how long it waited and
    /// carrying the text of its message and reply where the port shows them
    /// ([`Port::shown`](imrs_ports::Port::shown)). Off by default: a primitive that
    /// succeeds then logs nothing and reads no clock, so that the path modules use costs
    /// what the ports cost; failures, timeouts, sections, exceptions, deadlocks, alarms and
    /// module life are logged either way. A recorder and a timeline turn it on.
    pub fn observe(&self, on: bool) {
        self.shared.observe.store(on, Ordering::Relaxed);
    }

    /// `PORT ...`: makes a port on the cell's clock and declares it to the cell, owned by
    /// the module `spec` names. This is how a cell's ports are made: the port's timeouts run
    /// on the cell's clock (virtual or real), and the check each module passes when it starts
    /// sees the port. A `spec` that names another clock is refused
    /// ([`WireError::OtherClock`]), as is a second port of the same name.
    pub fn port<Req, Rep, U, L, const N: usize>(
        &self,
        spec: PortSpec,
    ) -> Result<Port<Req, Rep, U, L, N>, WireError>
    where
        Req: Send + 'static,
        Rep: Send + 'static,
        U: Usage,
        L: UserList,
    {
        let port = Port::new(self.on_its_clock(spec)?);
        self.declare(&port)?;
        Ok(port)
    }

    /// `PORT ...` with a filter task spliced in (Shin 1985, restriction 5): makes a
    /// [`FilteredPort`] on the cell's clock and declares both its sides, as [`Cell::port`]
    /// does for a plain port.
    // The type is the filtered port's own, with every parameter the caller chose.
    #[allow(clippy::type_complexity)]
    pub fn filtered_port<Req, Rep, F, FReq, FRep, O, L, const N: usize>(
        &self,
        spec: PortSpec,
        filter_task: impl Into<Name>,
    ) -> Result<FilteredPort<Req, Rep, F, FReq, FRep, O, L, N>, WireError>
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
        let port = FilteredPort::new(self.on_its_clock(spec)?, filter_task);
        self.declare(&port)?;
        Ok(port)
    }

    /// `spec` on the cell's clock; refused if it names another.
    fn on_its_clock(&self, spec: PortSpec) -> Result<PortSpec, WireError> {
        if let Some(clock) = spec.clock_of()
            && !same_clock(clock, &self.shared.clock)
        {
            return Err(WireError::OtherClock {
                port: spec.name().clone(),
            });
        }
        Ok(spec.clock(Arc::clone(&self.shared.clock)))
    }

    /// Declares to the cell a port made elsewhere — a [`FilteredPort`], or a port a
    /// transport made — as [`Cell::port`] declares the ports it makes. A port on another
    /// clock than the cell's is refused ([`WireError::OtherClock`]).
    pub fn declare(&self, port: &impl Declare) -> Result<(), WireError> {
        port.declare_to(self)
    }

    fn declare_port<Req, Rep, U, L, const N: usize>(
        &self,
        port: &Port<Req, Rep, U, L, N>,
    ) -> Result<(), WireError>
    where
        Req: Send + 'static,
        Rep: Send + 'static,
        U: Usage,
        L: UserList,
    {
        if !same_clock(port.clock(), &self.shared.clock) {
            return Err(WireError::OtherClock {
                port: port.name().clone(),
            });
        }
        lock(&self.shared.wiring).declare(port)
    }

    /// Makes known to the cell a port whose owner runs in another process (a port imported
    /// by a transport such as `imrs-ipc`): the modules of this process that use it are
    /// checked as for any port, and its owner is checked in the process it runs in.
    pub fn declare_imported<Req, Rep, U, L, const N: usize>(
        &self,
        port: &Port<Req, Rep, U, L, N>,
    ) -> Result<(), WireError>
    where
        Req: Send + 'static,
        Rep: Send + 'static,
        U: Usage,
        L: UserList,
    {
        lock(&self.shared.wiring).declare_elsewhere(port)
    }

    /// Attaches `module` to the port named `port`, checking what the types could not.
    pub fn use_port<Req, Rep, U>(
        &self,
        module: &str,
        port: &str,
    ) -> Result<End<Req, Rep, U>, WireError>
    where
        Req: Send + 'static,
        Rep: Send + 'static,
        U: Usage + Plain,
    {
        lock(&self.shared.wiring).use_port(module, port)
    }

    /// Every port declared to the cell, as the wiring describes it (name order): what a
    /// report on the cell's network needs — owner, users, message sizes, timeout, priority.
    pub fn ports(&self) -> Vec<imrs_ports::PortInfo> {
        lock(&self.shared.wiring).ports()
    }

    /// Shin's load-time check over a whole cell: every problem with these modules and the
    /// declared ports, all at once, each naming its module and port — including what only
    /// the whole cell shows (a port whose owner is not among them; too many users among
    /// modules not started yet). For tools; a cell needs no call to it, since each module
    /// is checked when it starts, against the ports and the modules running then.
    pub fn check(&self, modules: &[ModuleDecl]) -> Result<(), CellErrors> {
        check(&lock(&self.shared.wiring), modules)
    }

    /// Starts `spec` as a top-level module. If it fails, it stays failed.
    ///
    /// The module is checked first, against the ports declared to the cell: every problem
    /// the check finds in it (a port it uses that is not declared, a user list that does not
    /// name it, a handler or section left out of its order, ...) refuses it, all of them
    /// named in the error; so is a module of the same name already running.
    pub fn start<S: Send + Sync + 'static>(
        &self,
        spec: ModuleSpec<S>,
    ) -> Result<ModuleHandle, CellErrors> {
        self.launch(None, RestartPolicy::NEVER, spec, None)
    }

    /// Starts a top-level module made by `factory`, and makes a new copy of it with
    /// `factory` when it fails or is killed, as `policy` allows. Refused if a module of the
    /// same name runs in the cell.
    pub fn supervise<S, F>(
        &self,
        policy: RestartPolicy,
        mut factory: F,
    ) -> Result<ModuleHandle, CellErrors>
    where
        S: Send + Sync + 'static,
        F: FnMut() -> ModuleSpec<S> + Send + 'static,
    {
        let first = factory();
        self.launch(None, policy, first, Some(Box::new(factory)))
    }

    /// Starts `spec` as a top-level module on `processor`, co-scheduled with the other
    /// modules there: a rendezvous between them does not go through the runtime.
    pub fn start_on<S: Send + Sync + 'static>(
        &self,
        processor: &Processor,
        spec: ModuleSpec<S>,
    ) -> Result<ModuleHandle, CellErrors> {
        self.launch(Some(processor), RestartPolicy::NEVER, spec, None)
    }

    /// [`Cell::supervise`], on `processor`: every copy of the module runs there.
    pub fn supervise_on<S, F>(
        &self,
        processor: &Processor,
        policy: RestartPolicy,
        mut factory: F,
    ) -> Result<ModuleHandle, CellErrors>
    where
        S: Send + Sync + 'static,
        F: FnMut() -> ModuleSpec<S> + Send + 'static,
    {
        let first = factory();
        self.launch(Some(processor), policy, first, Some(Box::new(factory)))
    }

    /// Starts the supervisor of a top-level module on `processor`, or as a tokio task of
    /// its own.
    fn launch<S: Send + Sync + 'static>(
        &self,
        processor: Option<&Processor>,
        policy: RestartPolicy,
        first: ModuleSpec<S>,
        factory: Option<Factory<S>>,
    ) -> Result<ModuleHandle, CellErrors> {
        let Some(processor) = processor else {
            return spawn_module(Arc::clone(&self.shared), None, policy, first, factory);
        };
        // Every copy runs in this one supervisor job: the first copy's priority is the job's.
        let priority = first.priority;
        let (handle, supervisor) = supervisor(
            Arc::clone(&self.shared),
            (None, Some(processor.name().clone())),
            policy,
            first,
            factory,
        )?;
        // The module handle reports how the module ends: no job handle is needed.
        processor.place(priority, supervisor);
        Ok(handle)
    }

    /// Kills the running copy of `module`; a supervised module gets a new copy. Returns
    /// whether a module of that name runs.
    pub fn kill(&self, module: &str) -> bool {
        self.shared.kill(module)
    }

    /// Stops `module` for good. Returns whether a module of that name runs.
    pub fn stop(&self, module: &str) -> bool {
        let switch = self.shared.switch(module);
        switch.inspect(|switch| switch.stop()).is_some()
    }

    /// The module tree as it stands: every running module under the one that costarted it,
    /// and every port between two running modules as a vertical or horizontal link (seed
    /// 000 §2). `Display` draws it; `println!("{}", cell.tree())`.
    pub fn tree(&self) -> ModuleTree {
        let modules = lock(&self.shared.modules);
        ModuleTree::of(modules.placements())
    }
}

impl fmt::Debug for Cell {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Cell")
            .field("clock", &self.shared.clock)
            .field(
                "modules",
                &lock(&self.shared.modules).names().collect::<Vec<_>>(),
            )
            .finish_non_exhaustive()
    }
}
