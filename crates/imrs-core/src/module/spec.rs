//! What a module is made of, declared in one place, the way the seed's module specification
//! and body declare it: state, order, tasks, response and exception handlers, named
//! sections, the ports it owns and uses, and its hardware division.

use std::fmt;
use std::future::Future;
use std::pin::Pin;
use std::sync::Arc;

use imrs_ports::usage::{Answers, Usage};
use imrs_ports::{
    Handler, ModuleState, Name, Port, Priority, Respond, UsageKind, UserList, WireError, Wiring,
};

use super::ctx::Ctx;
use crate::decl::{ModuleDecl, owned_by};
use crate::exception::Exception;
use crate::supervision::RestartPolicy;
use crate::tree::{Placement, TreeModule};

/// What a task may fail with: any error, so that `?` works on port errors.
pub type TaskError = Box<dyn std::error::Error + Send + Sync>;

/// What a task returns.
pub type TaskResult = Result<(), TaskError>;

pub(crate) type BoxFuture<T> = Pin<Box<dyn Future<Output = T> + Send>>;
pub(crate) type TaskFactory<S> = Box<dyn FnMut(Ctx<S>) -> BoxFuture<TaskResult> + Send>;
pub(crate) type ExceptionHandler<S> = Arc<dyn Fn(Ctx<S>, Exception) -> BoxFuture<()> + Send + Sync>;

pub(crate) struct TaskSpec<S> {
    pub(crate) name: Name,
    pub(crate) factory: TaskFactory<S>,
    pub(crate) policy: RestartPolicy,
}

/// A module, declared: build it with [`ModuleSpec::new`] and start it with
/// [`Cell::start`](crate::Cell::start) or [`Ctx::costart`](crate::Ctx::costart).
///
/// `S` is the module's state. Tasks change it with
/// [`ModuleState::update`](imrs_ports::ModuleState::update); response handlers read it.
pub struct ModuleSpec<S> {
    pub(crate) name: Name,
    pub(crate) state: Arc<ModuleState<S>>,
    pub(crate) order: Vec<Name>,
    pub(crate) hardware: Vec<Name>,
    pub(crate) uses: Vec<(Name, UsageKind)>,
    pub(crate) filters: Vec<(Name, UsageKind)>,
    pub(crate) tasks: Vec<TaskSpec<S>>,
    pub(crate) responses: Vec<(Name, Box<dyn Respond<S> + Send>)>,
    pub(crate) exceptions: Vec<(Name, ExceptionHandler<S>)>,
    pub(crate) raises: Vec<Name>,
    /// The module's priority on the processor it is placed on.
    pub(crate) priority: Priority,
    /// Ends that could not be attached while the module was declared: reported by the
    /// wiring check, and a module that has any is refused at start.
    pub(crate) problems: Vec<WireError>,
}

impl<S: Send + Sync + 'static> ModuleSpec<S> {
    /// Module `name` with initial state `state`.
    pub fn new(name: impl Into<Name>, state: S) -> Self {
        Self {
            name: name.into(),
            state: Arc::new(ModuleState::new(state)),
            order: Vec::new(),
            hardware: Vec::new(),
            uses: Vec::new(),
            filters: Vec::new(),
            tasks: Vec::new(),
            responses: Vec::new(),
            exceptions: Vec::new(),
            raises: Vec::new(),
            priority: Priority::DEFAULT,
            problems: Vec::new(),
        }
    }

    /// The module's name.
    pub fn name(&self) -> &Name {
        &self.name
    }

    /// `ORDER(...)`: the module's sections, most urgent first: its handlers
    /// ([`Port::handler`]), its named [`Section`](crate::Section)s, and its own name for its
    /// background code. Every handler and section of the module must be in it; see
    /// [`Order`](crate::Order).
    pub fn order<I, N>(mut self, names: I) -> Self
    where
        I: IntoIterator<Item = N>,
        N: Into<Name>,
    {
        self.order = names.into_iter().map(Into::into).collect();
        self
    }

    /// The module's priority on its [`Processor`](crate::Processor): among the woken
    /// modules there, the most urgent is polled first, as the processor's
    /// [message handler](crate::Processor#the-message-handler) rule says. 1 is the most
    /// urgent; a module that declares none ranks below every declared one. A module started
    /// as a task of its own ([`Cell::start`](crate::Cell::start)) is scheduled by tokio,
    /// which has no priorities: there the number only appears in the
    /// [module tree](crate::Cell::tree). Every copy of a supervised module runs in the one
    /// job its first copy was placed in, at the first copy's priority.
    pub fn priority(mut self, n: u32) -> Self {
        self.priority = Priority::declared(n);
        self
    }

    /// The hardware division: the devices the module drives, by name.
    pub fn hardware<I, N>(mut self, devices: I) -> Self
    where
        I: IntoIterator<Item = N>,
        N: Into<Name>,
    {
        self.hardware.extend(devices.into_iter().map(Into::into));
        self
    }

    /// `USE PORT ...`: declares that this module uses `port`, with the usage its type gives
    /// a user (the complement of the owner's).
    pub fn uses<Req, Rep, U, L, const N: usize>(mut self, port: &Port<Req, Rep, U, L, N>) -> Self
    where
        Req: Send + 'static,
        Rep: Send + 'static,
        U: Usage,
        L: UserList,
    {
        self.add_use(port.name().clone(), port.user_usage());
        self
    }

    /// `USE PORT ... USAGE=usage`, for a port known only by name (wired through
    /// [`Cell::use_port`](crate::Cell::use_port)).
    pub fn uses_named(mut self, port: impl Into<Name>, usage: UsageKind) -> Self {
        self.add_use(port.into(), usage);
        self
    }

    /// `WHEN PORT.what ==>`: the response handler `handler` (made by [`Port::handler`], and
    /// ranked by the module's order under the same value). Its answering end is attached
    /// here, for this module: the owner end of a `RESPONSE` port, or a user end of a `QUERY`
    /// or `CALLALL` port, which declares that the module uses the port. An end that cannot
    /// be attached refuses the module when it starts, by name.
    pub fn respond<Req, Rep, U, L, const N: usize>(
        mut self,
        handler: &Handler<Req, Rep, U, L, N>,
        answer: impl Fn(&S, Req) -> Rep + Send + Sync + 'static,
    ) -> Self
    where
        Req: Send + 'static,
        Rep: Send + 'static,
        U: Answers,
        L: UserList,
    {
        let port = handler.port();
        if !U::OWNER_ANSWERS {
            self.add_use(port.name().clone(), UsageKind::Response);
        }
        match port.answer(self.name.clone(), answer) {
            Ok(end) => self.responses.push((handler.name(), Box::new(end))),
            Err(problem) => self.problems.push(problem),
        }
        self
    }

    /// Records a use of `port`: once, however many times it is declared (`.uses(&port)`
    /// beside a response handler on the same port is one user, not two).
    fn add_use(&mut self, port: Name, usage: UsageKind) {
        if !self.uses.contains(&(port.clone(), usage)) {
            self.uses.push((port, usage));
        }
    }

    /// A view of this module's state from outside, for a test or a report to read during or
    /// after a run (`view.inspect(|s| ...)`). It sees this copy of the module; a supervised
    /// module's next copy has a state of its own.
    pub fn view(&self) -> StateView<S> {
        StateView(Arc::clone(&self.state))
    }

    /// Declares that a task of this module is the filter of `port`, serving the port's users
    /// with `usage`.
    pub fn filters(mut self, port: impl Into<Name>, usage: UsageKind) -> Self {
        self.filters.push((port.into(), usage));
        self
    }

    /// `TASK name`: a task of the module's background code; all tasks start together when
    /// the module starts. `body` makes a fresh copy of the task each time it (re)starts.
    pub fn task<F, Fut>(self, name: impl Into<Name>, body: F) -> Self
    where
        F: FnMut(Ctx<S>) -> Fut + Send + 'static,
        Fut: Future<Output = TaskResult> + Send + 'static,
    {
        self.task_with_policy(name, RestartPolicy::NEVER, body)
    }

    /// As [`ModuleSpec::task`], restarted by `policy` when it fails.
    pub fn task_with_policy<F, Fut>(
        mut self,
        name: impl Into<Name>,
        policy: RestartPolicy,
        mut body: F,
    ) -> Self
    where
        F: FnMut(Ctx<S>) -> Fut + Send + 'static,
        Fut: Future<Output = TaskResult> + Send + 'static,
    {
        self.tasks.push(TaskSpec {
            name: name.into(),
            factory: Box::new(move |ctx| Box::pin(body(ctx))),
            policy,
        });
        self
    }

    /// `WHEN exception ==>`: an exception handler, named as the order names it
    /// (`"LET_1_GO.TIMEOUT"`, `"RELEASE.FAILED"`).
    pub fn exception<F, Fut>(mut self, name: impl Into<Name>, handler: F) -> Self
    where
        F: Fn(Ctx<S>, Exception) -> Fut + Send + Sync + 'static,
        Fut: Future<Output = ()> + Send + 'static,
    {
        let handler: ExceptionHandler<S> =
            Arc::new(move |ctx, exception| Box::pin(handler(ctx, exception)));
        self.exceptions.push((name.into(), handler));
        self
    }

    /// Declares the exceptions this module raises itself, beyond its ports' `PORT.TIMEOUT`s
    /// and its tasks' `TASK.FAILED`s: those it raises with [`Ctx::raise`], and the
    /// `BARRIER.TIMEOUT`s of the `waitfor` barriers it meets. The wiring check refuses an
    /// exception handler for anything the module cannot raise.
    pub fn raises<I, N>(mut self, exceptions: I) -> Self
    where
        I: IntoIterator<Item = N>,
        N: Into<Name>,
    {
        self.raises.extend(exceptions.into_iter().map(Into::into));
        self
    }

    /// Where the module sits in the cell's tree, for [`Cell::tree`](crate::Cell::tree).
    pub(crate) fn placement(
        &self,
        parent: Option<Name>,
        processor: Option<Name>,
        wiring: &Wiring,
    ) -> Placement {
        // A response handler answers on an end the module owns or uses, so the port is
        // already among the ports it owns or `uses`.
        let owns = owned_by(wiring, &self.name);
        // A module that filters a port it owns (its filter task) is not its own user.
        let filtered = self
            .filters
            .iter()
            .map(|(port, _)| port.clone())
            .filter(|port| !owns.contains(port))
            .collect::<Vec<_>>();
        Placement {
            module: TreeModule {
                name: self.name.clone(),
                parent,
                priority: self.priority,
                processor,
            },
            owns,
            uses: self
                .uses
                .iter()
                .map(|(port, _)| port.clone())
                .chain(filtered)
                .collect(),
        }
    }

    /// What the wiring check needs to know of this module.
    pub fn declaration(&self) -> ModuleDecl {
        ModuleDecl {
            name: self.name.clone(),
            order: self.order.clone(),
            uses: self.uses.clone(),
            filters: self.filters.clone(),
            responses: self
                .responses
                .iter()
                .map(|(name, end)| (name.clone(), end.port().clone()))
                .collect(),
            exceptions: self
                .exceptions
                .iter()
                .map(|(name, _)| name.clone())
                .collect(),
            tasks: self.tasks.iter().map(|task| task.name.clone()).collect(),
            raises: self.raises.clone(),
            problems: self.problems.clone(),
        }
    }
}

impl<S> fmt::Debug for ModuleSpec<S> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ModuleSpec")
            .field("name", &self.name)
            .field("order", &self.order)
            .field(
                "tasks",
                &self.tasks.iter().map(|t| &t.name).collect::<Vec<_>>(),
            )
            .finish_non_exhaustive()
    }
}

/// A module's state seen from outside; see [`ModuleSpec::view`].
pub struct StateView<S>(Arc<ModuleState<S>>);

impl<S> StateView<S> {
    /// Reads the state, waiting for an update in progress to end.
    pub fn inspect<R>(&self, look: impl FnOnce(&S) -> R) -> R {
        self.0.inspect(look)
    }
}

impl<S> Clone for StateView<S> {
    fn clone(&self) -> Self {
        Self(Arc::clone(&self.0))
    }
}

impl<S> fmt::Debug for StateView<S> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("StateView").finish_non_exhaustive()
    }
}
