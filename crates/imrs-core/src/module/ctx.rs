//! What a task of a module sees: its module's state, the clock, named sections, and the
//! port primitives, wrapped so that timeouts raise the module's exceptions and every
//! operation lands in the event log.

use std::fmt;
use std::future::Future;
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};
use std::time::Duration;

use imrs_ports::post::{Posting, QueryOutcome, SendOutcome};
use imrs_ports::usage::{Plain, Queries, Receives, Sends, Usage};
use imrs_ports::{
    End, Instant, ModuleState, Name, Port, QueryError, ReceiveError, Receiving, SendError,
    SharedClock, Shown, UserList, WireError,
};
use tracing::Instrument;

use super::module_shared::ModuleShared;
use crate::event::{EventKind, Observed, Primitive};
use crate::exception::Exception;
use crate::order::{Rank, Section};
use crate::thread::Thread;
use crate::wait_record::{WaitId, WaitRecord};
use crate::waitfor::{Pool, WaitFor, WaitForError};
use crate::work::{Performed, WorkSchedule};

/// A task's (or handler's) view of its module. Cheap to clone.
pub struct Ctx<S> {
    module: Arc<ModuleShared<S>>,
    /// The thread: its name, section and waits.
    thread: Arc<Thread>,
}

impl<S> Clone for Ctx<S> {
    fn clone(&self) -> Self {
        Self {
            module: Arc::clone(&self.module),
            thread: Arc::clone(&self.thread),
        }
    }
}

impl<S: Send + Sync + 'static> Ctx<S> {
    pub(crate) fn new(module: Arc<ModuleShared<S>>, thread: Arc<Thread>) -> Self {
        Self { module, thread }
    }

    /// The module's name.
    pub fn module(&self) -> &Name {
        &self.module.name
    }

    /// The module that costarted this one, if any.
    pub fn parent(&self) -> Option<&Name> {
        self.module.parent.as_ref()
    }

    /// The task's (or handler's) name.
    pub fn task(&self) -> &Name {
        &self.thread.task
    }

    /// The module's state: change it with `update`, read it with `read`.
    pub fn state(&self) -> &ModuleState<S> {
        &self.module.state
    }

    /// Attaches the owner end of `port` for this module. Call it where a task copy is made
    /// (in the task's closure, before its `async` block), so that the closure keeps the one
    /// clone of the port it was given and each copy of the task attaches anew:
    ///
    /// ```text
    /// .task("LOAD_IT", move |ctx| {
    ///     let ask_child1 = ctx.owner(&ask_child1);
    ///     async move { let mut ask_child1 = ask_child1?; /* ... */ Ok(()) }
    /// })
    /// ```
    pub fn owner<Req, Rep, U, L, const N: usize>(
        &self,
        port: &Port<Req, Rep, U, L, N>,
    ) -> Result<End<Req, Rep, U>, WireError>
    where
        Req: Send + 'static,
        Rep: Send + 'static,
        U: Usage + Plain,
        L: UserList,
    {
        if port.owner_module() != &self.module.name {
            return Err(WireError::NotOwner {
                port: port.name().clone(),
                module: self.module.name.clone(),
                owner: port.owner_module().clone(),
            });
        }
        port.owner()
    }

    /// Attaches a user end of `port` for this module, checked against the port's user list
    /// and number of users; see [`Ctx::owner`] for where to call it.
    pub fn user<Req, Rep, U, L, const N: usize>(
        &self,
        port: &Port<Req, Rep, U, L, N>,
    ) -> Result<End<Req, Rep, U::Complement>, WireError>
    where
        Req: Send + 'static,
        Rep: Send + 'static,
        U: Usage,
        U::Complement: Plain,
        L: UserList,
    {
        port.user_named(self.module.name.clone())
    }

    /// Attaches a user end of `port` for this task, under the task's own name: for the
    /// seed's intertask ports, whose user is a task of the owning module (GATE's task RELEASE
    /// on GATE's LET_1_GO), checked as [`Ctx::user`] checks a module.
    pub fn task_user<Req, Rep, U, L, const N: usize>(
        &self,
        port: &Port<Req, Rep, U, L, N>,
    ) -> Result<End<Req, Rep, U::Complement>, WireError>
    where
        Req: Send + 'static,
        Rep: Send + 'static,
        U: Usage,
        U::Complement: Plain,
        L: UserList,
    {
        port.user_named(self.thread.task.clone())
    }

    /// The cell's clock.
    pub fn clock(&self) -> &SharedClock {
        &self.module.cell.clock
    }

    /// The time now, on the cell's clock.
    pub fn now(&self) -> Instant {
        self.module.cell.clock.now()
    }

    /// `DELAY d`, on the cell's clock.
    pub async fn delay(&self, duration: Duration) {
        self.module.cell.clock.sleep(duration).await;
    }

    /// Runs `body` inside the named section: while it runs, the module's scheduler sees this
    /// thread at the section's rank in the module's order.
    ///
    /// # Panics
    ///
    /// If the module's order does not rank `section`: the task fails at once, its failure
    /// naming the module and the section, rather than run a section that protects nothing.
    pub async fn section<F: Future>(&self, section: &Section, body: F) -> F::Output {
        let Some(rank) = self.module.order.rank_of(section.as_str()) else {
            panic!(
                "module {} entered section {}, which its order does not rank",
                self.module.name,
                section.as_str()
            );
        };
        let rank = Some(rank);
        let name: Name = section.name();
        let _inside = SectionGuard::enter(self, name.clone(), rank);
        let span = tracing::debug_span!("section", module = %self.module.name, section = %name);
        body.instrument(span).await
    }

    /// `SEND`: as [`End::send`], and a timeout raises `PORT.TIMEOUT` in this module.
    #[inline]
    pub fn send<'a, Req, Rep, U>(
        &'a self,
        end: &'a mut End<Req, Rep, U>,
        message: Req,
    ) -> PortOp<'a, S, Posting<'a, Req, Rep, SendOutcome>, ShowReply<Rep>>
    where
        Req: Send + 'static,
        Rep: Send + 'static,
        U: Sends,
    {
        let watch = self.watch(end, |shown| {
            let text = (shown.request)(&message);
            (Some(text), ShowReply(Some(shown.reply)))
        });
        PortOp::new(self, end.send(message), watch)
    }

    /// `RECEIVE`: as [`End::receive`], and a timeout raises `PORT.TIMEOUT` in this module.
    #[inline]
    pub fn receive<'a, Req, Rep, U>(
        &'a self,
        end: &'a mut End<Req, Rep, U>,
    ) -> PortOp<'a, S, Receiving<'a, Req, Rep>, ShowRequest<Req>>
    where
        Req: Send + 'static,
        Rep: Send + 'static,
        U: Receives,
    {
        let watch = self.watch(end, |shown| (None, ShowRequest(Some(shown.request))));
        PortOp::new(self, end.receive(), watch)
    }

    /// `QUERY`: as [`End::query`], and a timeout raises `PORT.TIMEOUT` in this module.
    #[inline]
    pub fn query<'a, Req, Rep, U>(
        &'a self,
        end: &'a mut End<Req, Rep, U>,
        query: Req,
    ) -> PortOp<'a, S, Posting<'a, Req, Rep, QueryOutcome>, ShowReply<Rep>>
    where
        Req: Send + 'static,
        Rep: Send + 'static,
        U: Queries,
    {
        let watch = self.watch(end, |shown| {
            let text = (shown.request)(&query);
            (Some(text), ShowReply(Some(shown.reply)))
        });
        PortOp::new(self, end.query(query), watch)
    }

    /// Whether the cell observes its primitives closely ([`Cell::observe`]).
    fn observing(&self) -> bool {
        self.module.cell.observing()
    }

    /// What an operation on `end` watches, if the cell observes (else nothing, at the cost
    /// of one load): its start, and the text `message` gives of what it sends, where the
    /// port shows its values; with how the port shows them.
    #[allow(clippy::type_complexity)]
    #[inline]
    fn watch<Req, Rep, U, D: Default>(
        &self,
        end: &End<Req, Rep, U>,
        shown: impl FnOnce(Shown<Req, Rep>) -> (Option<String>, D),
    ) -> Option<Box<Watch<D>>>
    where
        Req: Send + 'static,
        Rep: Send + 'static,
        U: Usage,
    {
        if !self.observing() {
            return None;
        }
        let (text, show) = end.shown().map_or((None, D::default()), shown);
        Some(Box::new(Watch {
            since: None,
            text,
            show,
        }))
    }

    /// `waitfor`: as [`WaitFor::waitfor`], under this task's name; a timeout raises
    /// `BARRIER.TIMEOUT` in this module.
    pub async fn waitfor<M, R>(
        &self,
        barrier: &WaitFor<M>,
        message: M,
        combine: impl FnOnce(&Pool<M>) -> R,
        timeout: Option<Duration>,
    ) -> Result<R, WaitForError<M>>
    where
        M: Send + Sync + 'static,
    {
        let since = self.observing().then(|| self.now());
        let result = barrier
            .waitfor(self.thread.task.as_str(), message, combine, timeout)
            .await;
        match &result {
            // Logged, as every primitive that succeeds, only while the cell observes.
            Ok(_) if since.is_none() => {}
            Ok(_) => self.event(EventKind::WaitForReleased {
                barrier: barrier.name().clone(),
            }),
            Err(error) => {
                let timed_out = matches!(error, WaitForError::Timeout { .. });
                let observed = since.map(|since| {
                    Box::new(Observed {
                        waited: self.now().saturating_duration_since(since),
                        ..Observed::default()
                    })
                });
                self.port_failed(
                    barrier.name().clone(),
                    Primitive::WaitFor,
                    error.to_string(),
                    observed,
                    timed_out,
                );
            }
        }
        result
    }

    /// `PERFORM`: runs the next step of `schedule`, recording it; a failed step is skipped,
    /// recorded, and raised as an alarm for the operator.
    pub async fn perform<St, F, Fut, E>(
        &self,
        schedule: &mut WorkSchedule<St>,
        run: F,
    ) -> Option<Performed<E>>
    where
        St: fmt::Debug,
        F: FnOnce(&St) -> Fut,
        Fut: Future<Output = Result<(), E>>,
        E: fmt::Display,
    {
        let performed = schedule.perform(run).await?;
        match &performed {
            Performed::Done { index } => {
                let step = format!(
                    "{:?}",
                    schedule.get(*index).expect("a performed step exists")
                );
                self.event(EventKind::StepPerformed { step });
            }
            Performed::Failed { index, error } => {
                let step = format!(
                    "{:?}",
                    schedule.get(*index).expect("a performed step exists")
                );
                self.event(EventKind::StepFailed {
                    step,
                    error: error.to_string(),
                });
            }
        }
        Some(performed)
    }

    /// Raises exception `name` in this module; its handler runs at its rank.
    pub fn raise(&self, name: impl Into<Name>, detail: impl Into<String>) {
        self.module.raise(Exception {
            name: name.into(),
            task: Some(self.thread.task.clone()),
            detail: detail.into(),
        });
    }

    /// `{signal for help}`: records an alarm for the operator.
    pub fn alarm(&self, message: impl Into<String>) {
        self.event(EventKind::Alarm {
            message: message.into(),
        });
    }

    /// Asks the module to kill task `task` (if it runs) and start a new copy of it.
    pub fn restart_task(&self, task: impl Into<Name>) {
        self.module.request_restart(task.into());
    }

    /// Kills the running copy of module `module` (a supervised one gets a new copy). Returns
    /// whether such a module runs.
    pub fn kill(&self, module: &str) -> bool {
        self.module.cell.kill(module)
    }

    /// What the module's tasks and handlers share.
    pub(crate) fn module_shared(&self) -> &Arc<ModuleShared<S>> {
        &self.module
    }

    pub(crate) fn event(&self, kind: EventKind) {
        self.module.event(Some(&self.thread.task), kind);
    }

    fn port_failed(
        &self,
        port: Name,
        primitive: Primitive,
        error: String,
        observed: Option<Box<Observed>>,
        timed_out: bool,
    ) {
        self.event(EventKind::PortError {
            port: port.clone(),
            error: error.clone(),
            primitive,
            observed,
        });
        if timed_out {
            self.module.raise(Exception {
                name: Exception::timeout_of(port.as_str()),
                task: Some(self.thread.task.clone()),
                detail: error,
            });
        }
    }

    /// Notes, in this thread's record, a wait on `port` served by `peer` (or by any of the
    /// port's users): the deadlock diagnosis reads it only if the wait lasts. Inlined into
    /// [`begin_wait`], the one caller, which is itself out of the message's way.
    #[inline(always)]
    fn wait_on(&self, port: &Name, peer: Option<&Name>) -> WaitGuard<'_> {
        let guard = WaitGuard {
            record: &self.thread.waits,
            id: self.thread.waits.begin(port, peer),
        };
        self.module.cell.wait_began(&self.module.name, port, peer);
        guard
    }
}

impl<S> fmt::Debug for Ctx<S> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Ctx")
            .field("module", &self.module.name)
            .field("task", &self.thread.task)
            .field("rank", &self.thread.section.get())
            .finish()
    }
}

/// Marks a thread as inside a section until dropped, also when the section is cancelled.
struct SectionGuard<'a, S: Send + Sync + 'static> {
    ctx: &'a Ctx<S>,
    name: Name,
    outer: u32,
}

impl<'a, S: Send + Sync + 'static> SectionGuard<'a, S> {
    fn enter(ctx: &'a Ctx<S>, name: Name, rank: Option<Rank>) -> Self {
        let outer = ctx.thread.section.enter(rank);
        ctx.event(EventKind::SectionEntered {
            section: name.clone(),
        });
        Self { ctx, name, outer }
    }
}

impl<S: Send + Sync + 'static> Drop for SectionGuard<'_, S> {
    fn drop(&mut self) {
        self.ctx.thread.section.restore(self.outer);
        self.ctx.event(EventKind::SectionLeft {
            section: self.name.clone(),
        });
    }
}

/// A thread's wait on a peer, cleared from its record when the wait ends.
struct WaitGuard<'a> {
    record: &'a WaitRecord,
    id: WaitId,
}

impl Drop for WaitGuard<'_> {
    fn drop(&mut self) {
        self.record.end(self.id);
    }
}

/// Errors of port operations that can time out.
pub trait PortFailure: fmt::Display {
    /// Whether the port's timeout ran out (the seed's `PORT.TIMEOUT`).
    fn is_timeout(&self) -> bool;
}

impl<T> PortFailure for SendError<T> {
    fn is_timeout(&self) -> bool {
        SendError::is_timeout(self)
    }
}

impl<T> PortFailure for QueryError<T> {
    fn is_timeout(&self) -> bool {
        QueryError::is_timeout(self)
    }
}

impl PortFailure for ReceiveError {
    fn is_timeout(&self) -> bool {
        ReceiveError::is_timeout(self)
    }
}

/// The end's own future under a [`PortOp`]: the port it works on, whom it waits on, and
/// which primitive it is. What depends only on the kind of operation is here, in the type,
/// so that a port operation carries none of it.
pub trait PortOperation {
    /// The port.
    fn port(&self) -> &Name;
    /// The module a wait of this operation waits on: a user's post waits on the port's
    /// owner; `None` for a receive and for an owner's post, which any user may serve.
    fn waits_on(&self) -> Option<&Name>;
    /// Whether the deadlock diagnosis notes this operation's wait: a receive waits for
    /// whoever comes, which is no peer in a cycle.
    const NOTED: bool;
    /// The primitive, as the event log names it.
    const PRIMITIVE: Primitive;
}

impl<Req, Rep> PortOperation for Posting<'_, Req, Rep, SendOutcome> {
    fn port(&self) -> &Name {
        Posting::port(self)
    }
    fn waits_on(&self) -> Option<&Name> {
        Posting::waits_on(self)
    }
    const NOTED: bool = true;
    const PRIMITIVE: Primitive = Primitive::Send;
}

impl<Req, Rep> PortOperation for Posting<'_, Req, Rep, QueryOutcome> {
    fn port(&self) -> &Name {
        Posting::port(self)
    }
    fn waits_on(&self) -> Option<&Name> {
        Posting::waits_on(self)
    }
    const NOTED: bool = true;
    const PRIMITIVE: Primitive = Primitive::Query;
}

impl<Req, Rep> PortOperation for Receiving<'_, Req, Rep> {
    fn port(&self) -> &Name {
        Receiving::port(self)
    }
    fn waits_on(&self) -> Option<&Name> {
        None
    }
    const NOTED: bool = false;
    const PRIMITIVE: Primitive = Primitive::Receive;
}

/// The event a port operation of `primitive` logs when it succeeds. A waitfor is no port
/// operation (it logs its own events), so no `PortOp` asks for its arm.
fn done(primitive: Primitive, port: Name, observed: Option<Box<Observed>>) -> EventKind {
    match primitive {
        Primitive::Send => EventKind::Sent { port, observed },
        Primitive::Query => EventKind::Queried { port, observed },
        Primitive::Receive | Primitive::WaitFor => EventKind::Received { port, observed },
    }
}

pin_project_lite::pin_project! {
    /// A port operation of a task, [`Ctx::send`], [`Ctx::receive`] or [`Ctx::query`]: the
    /// end's own future, and what the module logs when it ends (the event, the timeout
    /// exception, the end of the wait in the thread's record of its waits). A send or a
    /// query notes its wait only once it has to wait: one answered at its first poll never
    /// does, and the deadlock diagnosis reads the note only if the wait lasts.
    ///
    /// A named type rather than an `async fn`, so that its type does not carry the end's
    /// usage: a misused end is reported once, where the operation is called.
    #[must_use = "a port operation does nothing unless awaited"]
    pub struct PortOp<'a, S, F, D> {
        ctx: &'a Ctx<S>,
        waiting: Option<WaitGuard<'a>>,
        // What an observing cell watches; `None` (and no clock read, no text) otherwise.
        watch: Option<Box<Watch<D>>>,
        #[pin]
        operation: F,
    }
}

/// What an observing cell's port operation keeps until it ends: when it first had to wait
/// (`None` while it has not, so that one that completes at once reads the clock only for its
/// event), the text of the message it sent, and how to show what comes back.
struct Watch<D> {
    since: Option<Instant>,
    text: Option<String>,
    show: D,
}

impl<'a, S, F, D> PortOp<'a, S, F, D> {
    // Built in one go, and inlined into the task's future, so that the operation's future
    // is built where it stays rather than copied there.
    #[inline]
    fn new(ctx: &'a Ctx<S>, operation: F, watch: Option<Box<Watch<D>>>) -> Self {
        Self {
            ctx,
            waiting: None,
            watch,
            operation,
        }
    }
}

/// How a port operation shows what it got, for the event log.
pub trait ShowResult<T> {
    /// The text of `value`, if the port's values are shown.
    fn show(&self, value: &T) -> Option<String>;
}

/// Shows the reply a send or a query got, if the port's values are shown.
#[derive(Debug)]
pub struct ShowReply<Rep>(Option<fn(&Rep) -> String>);

/// Shows the message a receive got, if the port's values are shown.
#[derive(Debug)]
pub struct ShowRequest<Req>(Option<fn(&Req) -> String>);

// By hand: a derive would ask the shown type to be `Default` too.
impl<Rep> Default for ShowReply<Rep> {
    fn default() -> Self {
        Self(None)
    }
}

impl<Req> Default for ShowRequest<Req> {
    fn default() -> Self {
        Self(None)
    }
}

impl<Rep> ShowResult<Rep> for ShowReply<Rep> {
    fn show(&self, reply: &Rep) -> Option<String> {
        self.0.map(|show| show(reply))
    }
}

impl<Req, Handle> ShowResult<(Req, Handle)> for ShowRequest<Req> {
    fn show(&self, (message, _): &(Req, Handle)) -> Option<String> {
        self.0.map(|show| show(message))
    }
}

impl<S, F, T, E, D> Future for PortOp<'_, S, F, D>
where
    S: Send + Sync + 'static,
    F: Future<Output = Result<T, E>> + PortOperation,
    E: PortFailure,
    D: ShowResult<T>,
{
    type Output = F::Output;

    // Inlined into the task's future, always: what it adds to the end's own poll is a few
    // loads and branches, less than a call of its own would cost.
    #[inline(always)]
    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<F::Output> {
        let mut this = self.project();
        let Poll::Ready(result) = this.operation.as_mut().poll(cx) else {
            if this.watch.is_some() || (F::NOTED && this.waiting.is_none()) {
                let operation = this.operation.as_ref().get_ref();
                begin_wait(this.ctx, this.watch, this.waiting, operation);
            }
            return Poll::Pending;
        };
        drop(this.waiting.take());
        // Cloned only for an event: a clone is two atomic operations.
        let port = || this.operation.as_ref().get_ref().port().clone();
        let Some(watch) = this.watch.take() else {
            // Not observed: a primitive that succeeds logs nothing, at the cost of no clock
            // read; one that fails is logged, and a timeout raises its exception.
            if let Err(error) = &result {
                let timed_out = error.is_timeout();
                let port = port();
                this.ctx
                    .port_failed(port, F::PRIMITIVE, error.to_string(), None, timed_out);
            }
            return Poll::Ready(result);
        };
        let Watch { since, text, show } = *watch;
        let port = port();
        let now = this.ctx.module.cell.clock.now();
        let mut observed = Box::new(Observed {
            waited: since.map_or(Duration::ZERO, |since| now.saturating_duration_since(since)),
            message: text,
            reply: None,
        });
        match &result {
            Ok(value) => {
                // What came back: a send's or a query's reply, a receive's message.
                let shown = show.show(value);
                match F::PRIMITIVE {
                    Primitive::Receive => observed.message = shown,
                    _ => observed.reply = shown,
                }
                let kind = done(F::PRIMITIVE, port, Some(observed));
                this.ctx
                    .module
                    .event_at(now, Some(&this.ctx.thread.task), kind);
            }
            Err(error) => this.ctx.port_failed(
                port,
                F::PRIMITIVE,
                error.to_string(),
                Some(observed),
                error.is_timeout(),
            ),
        }
        Poll::Ready(result)
    }
}

/// A port operation has to wait: an observing cell notes since when, and a send or a query
/// notes whom it waits on, once. Out of line: an operation that completes at once, and an
/// operation polled again while it waits, pass by it.
#[inline(never)]
fn begin_wait<'a, S: Send + Sync + 'static, F: PortOperation, D>(
    ctx: &'a Ctx<S>,
    watch: &mut Option<Box<Watch<D>>>,
    waiting: &mut Option<WaitGuard<'a>>,
    operation: &F,
) {
    if let Some(watch) = watch {
        watch.since.get_or_insert_with(|| ctx.now());
    }
    if F::NOTED && waiting.is_none() {
        *waiting = Some(ctx.wait_on(operation.port(), operation.waits_on()));
    }
}

impl<S, F: PortOperation, D> fmt::Debug for PortOp<'_, S, F, D> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("PortOp")
            .field("port", self.operation.port())
            .finish_non_exhaustive()
    }
}
