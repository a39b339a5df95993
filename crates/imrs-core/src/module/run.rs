//! The order scheduler: one module's executor.
//!
//! A module is one future, polled by one tokio task. Inside it, this scheduler polls the
//! module's threads — its tasks, and the exception handlers that are running — and decides
//! when pending handlers may start. The rule (Shin 1985, §4.2 and §5.1):
//!
//! - A pending handler (a query for a response handler, a raised exception) starts when its
//!   rank outranks the section of the thread it interrupts (the least urgent live thread)
//!   and every named section that any live thread of the module is in, at the end of a
//!   poll. Ranks are re-checked after every poll of every thread. Wakers only wake the
//!   module's task; nothing is polled inside a waker.
//! - A response handler is synchronous: it runs to completion right there, reading `&S`.
//!   An exception handler is asynchronous and becomes a thread of its own, at its rank.
//! - The order decides only when handlers *start*; it never stops a running thread from
//!   making progress, so a high-rank thread waiting on a port served by a lower-ranked thread
//!   of the same module cannot deadlock. The crate docs ("The order rule") give the whole
//!   argument.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll, Waker};

use imrs_ports::clock::Sleep;
use imrs_ports::transport::Presence;
use imrs_ports::{Name, Respond, Served};

use super::ctx::Ctx;
use super::module_shared::ModuleShared;
use super::spec::{BoxFuture, ExceptionHandler, ModuleSpec, TaskFactory, TaskResult};
use crate::deadlock::ModuleThreads;
use crate::event::EventKind;
use crate::exception::Exception;
use crate::kill::KillSwitch;
use crate::order::{Order, Rank};
use crate::shared::{CellShared, Children};
use crate::supervision::RestartPolicy;
use crate::thread::Thread;

/// How a module's copy ended.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum ModuleExit {
    /// Every task finished.
    Finished,
    /// A task failed beyond its restart policy.
    Failed(String),
    /// Killed from outside.
    Killed,
}

// A one-byte tag: the scheduler looks at the stage at every poll, and a niche in the
// reason's `String` would cost a decoding each time.
#[repr(u8)]
enum Stage {
    Running(BoxFuture<TaskResult>),
    Restarting(Pin<Box<Sleep>>),
    Finished,
    GaveUp(String),
}

struct TaskRun<S> {
    name: Name,
    factory: TaskFactory<S>,
    policy: RestartPolicy,
    thread: Arc<Thread>,
    stage: Stage,
    restarts: u32,
}

struct HandlerRun {
    name: Name,
    rank: Rank,
    /// The handler's thread: the section it is in (its rank, or a section it entered).
    thread: Arc<Thread>,
    future: BoxFuture<()>,
}

struct ResponseRun<S> {
    name: Name,
    rank: Rank,
    end: Box<dyn Respond<S> + Send>,
}

pub(crate) struct ModuleRun<S> {
    shared: Arc<ModuleShared<S>>,
    tasks: Vec<TaskRun<S>>,
    handlers: Vec<HandlerRun>,
    responses: Vec<ResponseRun<S>>,
    exception_handlers: Vec<(Name, Rank, ExceptionHandler<S>)>,
    kill: Arc<KillSwitch>,
    /// The waker last registered with `kill`.
    kill_waker: Option<Waker>,
    /// One task and no response handler: while no exception handler runs and nothing is
    /// pending, a poll of the module is a poll of its task.
    single: bool,
    /// The module's span, where a subscriber wanted it when the copy started: boxed, since
    /// most cells have none and every idle module would carry its room.
    span: Option<Box<tracing::Span>>,
}

impl<S: Send + Sync + 'static> ModuleRun<S> {
    pub(crate) fn new(
        spec: ModuleSpec<S>,
        cell: Arc<CellShared>,
        parent: Option<Name>,
        kill: Arc<KillSwitch>,
        children: Children,
        presence: &Arc<Presence>,
    ) -> Self {
        let order = Order::new(spec.name.clone(), spec.order);
        let background = order.background();
        let mut responses: Vec<_> = spec
            .responses
            .into_iter()
            .map(|(name, mut end)| {
                // Attached before the module ran: held by it all the same.
                end.bind(presence);
                ResponseRun {
                    rank: order.handler_rank(name.as_str()),
                    name,
                    end,
                }
            })
            .collect();
        responses.sort_by_key(|response| response.rank);
        let exception_handlers = spec
            .exceptions
            .into_iter()
            .map(|(name, handler)| {
                let rank = order.handler_rank(name.as_str());
                (name, rank, handler)
            })
            .collect();
        let span = tracing::info_span!("module", name = %spec.name);
        // A span made without a subscriber stays disabled for good.
        let span = (!span.is_disabled()).then(|| Box::new(span));
        let shared = Arc::new(ModuleShared::new(
            spec.name, parent, spec.state, order, cell, children,
        ));
        let tasks: Vec<TaskRun<S>> = spec
            .tasks
            .into_iter()
            .map(|task| {
                let thread = Arc::new(Thread::new(task.name.clone(), background));
                let mut run = TaskRun {
                    name: task.name,
                    factory: task.factory,
                    policy: task.policy,
                    thread,
                    stage: Stage::Finished,
                    restarts: 0,
                };
                let ctx = Ctx::new(Arc::clone(&shared), Arc::clone(&run.thread));
                // Within the presence: the ends the task's closure attaches are the module's.
                let future = Presence::within(Some(presence), || (run.factory)(ctx));
                run.stage = Stage::Running(future);
                shared.event(Some(&run.name), EventKind::TaskStarted);
                run
            })
            .collect();
        shared.cell.threads_of(&shared.name, |threads| {
            tasks.iter().for_each(|task| threads.add(&task.thread));
        });
        Self {
            shared,
            single: tasks.len() == 1 && responses.is_empty(),
            tasks,
            handlers: Vec::new(),
            responses,
            exception_handlers,
            kill,
            kill_waker: None,
            span,
        }
    }

    /// The rank a pending handler must outrank to start: the most urgent *named* section a
    /// live thread is in, or, when no thread is in one, the least urgent section of any live
    /// thread (the one a handler interrupts). `None` when no thread lives, and any handler
    /// may start.
    ///
    /// A named section always ranks at least as urgent as the least urgent live thread, so
    /// this is the rule "outrank the thread you interrupt and every named section occupied".
    fn host_rank(&self) -> Option<Rank> {
        let tasks = self.tasks.iter().filter_map(|task| match task.stage {
            Stage::Running(_) => Some(&task.thread.section),
            _ => None,
        });
        let handlers = self.handlers.iter().map(|handler| &handler.thread.section);
        let mut least_urgent = None;
        let mut named: Option<Rank> = None;
        for section in tasks.chain(handlers) {
            least_urgent = least_urgent.max(Some(section.get()));
            if let Some(rank) = section.named() {
                named = Some(named.map_or(rank, |most_urgent| most_urgent.min(rank)));
            }
        }
        named.or(least_urgent)
    }

    /// Starts every pending handler whose rank allows it now. Returns whether a thread
    /// started (an exception handler, or a restarted task) that must be polled. A response
    /// handler runs to completion right here, so answering queries starts none.
    ///
    /// It registers for no wake (it runs after every poll of every thread, and a waker
    /// registration costs atomic read-modify-writes): [`ModuleRun::park`] does, once, before
    /// the module's future returns `Pending`.
    #[inline(always)]
    fn admit(&mut self) -> bool {
        // The usual case, after nearly every poll: nothing raised, no restart asked, no
        // query waiting. Two loads, no call, and no rank is computed.
        let pending = self.shared.has_pending();
        if !pending
            && !self
                .responses
                .iter()
                .any(|response| response.end.is_pending())
        {
            return false;
        }
        self.admit_pending(pending)
    }

    /// [`ModuleRun::admit`] when something may be pending.
    fn admit_pending(&mut self, pending: bool) -> bool {
        let mut started = pending && self.restart_requested();
        while self.shared.has_pending() {
            let host = self.host_rank();
            let admissible = |rank: Rank| host.is_none_or(|host| rank.outranks(host));
            let Some(exception) = self.shared.take_raised(|exception| {
                let rank = self.handler_for(&exception.name).map(|(rank, _)| rank);
                rank.is_none_or(admissible)
            }) else {
                break;
            };
            self.start_handler(exception);
            started = true;
        }
        let host = self.host_rank();
        for response in &mut self.responses {
            if !host.is_none_or(|host| response.rank.outranks(host)) {
                // Sorted by rank: no later handler outranks the host either.
                break;
            }
            while response.end.is_pending() {
                let end = &mut response.end;
                // A panicking handler fails its one query (the querier gets `NoResponse`)
                // and is logged; the module lives on, as after a panicking exception
                // handler. The state is only read, so the panic cannot leave it half-done.
                let answered = catch_unwind(AssertUnwindSafe(|| {
                    self.shared.state.read(|state| end.respond(state))
                }));
                let kind = match answered {
                    // Logged, as every primitive that succeeds, only while the cell observes.
                    Ok(Served::Answered) if !self.shared.cell.observing() => continue,
                    Ok(Served::Answered) => EventKind::Responded {
                        handler: response.name.clone(),
                    },
                    Ok(Served::Late) => EventKind::RespondedLate {
                        handler: response.name.clone(),
                    },
                    Ok(Served::Idle) => continue,
                    Err(panic) => EventKind::TaskFailed {
                        reason: format!(
                            "response handler panicked: {}",
                            panic_message(panic.as_ref())
                        ),
                    },
                };
                self.shared.event(Some(&response.name), kind);
            }
        }
        started
    }

    /// Before the module's future returns `Pending`: registers every response handler for a
    /// wake when a query comes. Returns whether one that may start now came meanwhile.
    fn park(&mut self, cx: &mut Context<'_>) -> bool {
        if self.responses.is_empty() {
            return false;
        }
        let host = self.host_rank();
        let mut ready = false;
        for response in &mut self.responses {
            let admissible = host.is_none_or(|host| response.rank.outranks(host));
            let waiting = matches!(response.end.poll_pending(cx), Poll::Ready(Ok(())));
            ready |= waiting && admissible;
        }
        ready
    }

    fn handler_for(&self, exception: &Name) -> Option<(Rank, &ExceptionHandler<S>)> {
        self.exception_handlers
            .iter()
            .find(|(name, _, _)| name == exception)
            .map(|(_, rank, handler)| (*rank, handler))
    }

    fn start_handler(&mut self, exception: Exception) {
        let Some((rank, handler)) = self.handler_for(&exception.name) else {
            self.shared.event(
                exception.task.as_ref(),
                EventKind::ExceptionUnhandled {
                    exception: exception.name,
                },
            );
            return;
        };
        let handler = Arc::clone(handler);
        let name = exception.name.clone();
        let thread = Arc::new(Thread::new(name.clone(), rank));
        self.shared
            .cell
            .threads_of(&self.shared.name, |threads| threads.add(&thread));
        let ctx = Ctx::new(Arc::clone(&self.shared), Arc::clone(&thread));
        self.shared.event(
            Some(&name),
            EventKind::ExceptionHandled {
                exception: name.clone(),
            },
        );
        let future = handler(ctx, exception);
        let position = self
            .handlers
            .partition_point(|running| running.rank <= rank);
        self.handlers.insert(
            position,
            HandlerRun {
                name,
                rank,
                thread,
                future,
            },
        );
    }

    /// Starts a new copy of each task whose restart was asked for. Returns whether any
    /// started.
    fn restart_requested(&mut self) -> bool {
        let mut started = false;
        for name in self.shared.take_restart_requests() {
            let Some(index) = self.tasks.iter().position(|task| task.name == name) else {
                self.shared.event(
                    None,
                    EventKind::Alarm {
                        message: format!(
                            "restart asked for task {name}, which module {} does not have",
                            self.shared.name
                        ),
                    },
                );
                continue;
            };
            self.start_copy(index);
            started = true;
        }
        started
    }

    /// Drops whatever copy of task `index` there is and starts a new one.
    fn start_copy(&mut self, index: usize) {
        let background = self.shared.order.background();
        let task = &mut self.tasks[index];
        task.stage = Stage::Finished;
        task.restarts += 1;
        task.thread.section.set(background);
        let ctx = Ctx::new(Arc::clone(&self.shared), Arc::clone(&task.thread));
        task.stage = Stage::Running((task.factory)(ctx));
        self.shared.event(
            Some(&task.name),
            EventKind::TaskRestarted {
                attempt: task.restarts,
            },
        );
    }

    /// Polls task `index` once. Returns whether its stage changed.
    #[inline(always)]
    fn poll_task(&mut self, index: usize, cx: &mut Context<'_>) -> bool {
        let task = &mut self.tasks[index];
        match &mut task.stage {
            Stage::Running(future) => {
                let outcome = catch_unwind(AssertUnwindSafe(|| future.as_mut().poll(cx)));
                let failure = match outcome {
                    Ok(Poll::Pending) => return false,
                    Ok(Poll::Ready(outcome)) => outcome,
                    Err(panic) => Err(panic_message(panic.as_ref()).into()),
                };
                self.task_ended(index, failure);
                true
            }
            Stage::Restarting(sleep) => {
                if sleep.as_mut().poll(cx).is_pending() {
                    return false;
                }
                self.start_copy(index);
                true
            }
            Stage::Finished | Stage::GaveUp(_) => false,
        }
    }

    /// Task `index`'s copy has returned `outcome`, or panicked.
    #[inline(never)]
    fn task_ended(&mut self, index: usize, outcome: TaskResult) {
        match outcome {
            Ok(()) => {
                let task = &mut self.tasks[index];
                task.stage = Stage::Finished;
                self.shared.event(Some(&task.name), EventKind::TaskFinished);
            }
            Err(error) => self.fail_task(index, error.to_string()),
        }
    }

    fn fail_task(&mut self, index: usize, reason: String) {
        let task = &mut self.tasks[index];
        self.shared.event(
            Some(&task.name),
            EventKind::TaskFailed {
                reason: reason.clone(),
            },
        );
        task.stage = match task.policy.delay_before(task.restarts + 1) {
            Some(delay) => Stage::Restarting(Box::pin(self.shared.cell.clock.sleep(delay))),
            None => Stage::GaveUp(reason.clone()),
        };
        let restarting = matches!(task.stage, Stage::Restarting(_));
        let exception = Exception {
            name: Exception::failure_of(task.name.as_str()),
            task: Some(task.name.clone()),
            detail: reason,
        };
        // A failure that the task's restart policy handles needs no handler: raise it only
        // for a handler that asked for it, so the log does not call it unhandled.
        if restarting && self.handler_for(&exception.name).is_none() {
            return;
        }
        self.shared.raise(exception);
    }

    /// A handler's thread has ended: the diagnosis reads its waits no more.
    fn forget_thread(&self, thread: &Arc<Thread>) {
        self.shared
            .cell
            .threads_of(&self.shared.name, |threads| threads.remove(thread));
    }

    /// Polls running handler `index` once. Returns whether it finished.
    fn poll_handler(&mut self, index: usize, cx: &mut Context<'_>) -> bool {
        let handler = &mut self.handlers[index];
        match catch_unwind(AssertUnwindSafe(|| handler.future.as_mut().poll(cx))) {
            Ok(Poll::Pending) => false,
            Ok(Poll::Ready(())) => {
                let handler = self.handlers.remove(index);
                self.forget_thread(&handler.thread);
                true
            }
            Err(panic) => {
                let handler = self.handlers.remove(index);
                self.forget_thread(&handler.thread);
                self.shared.event(
                    Some(&handler.name),
                    EventKind::TaskFailed {
                        reason: format!(
                            "exception handler panicked: {}",
                            panic_message(panic.as_ref())
                        ),
                    },
                );
                true
            }
        }
    }

    /// How the module ends, once no thread can go on: every task finished, or some gave up
    /// (while another task lives, a handler may still start a new copy of a failed one).
    fn exit(&self) -> Option<ModuleExit> {
        if !self.handlers.is_empty() || self.shared.has_raised() {
            return None;
        }
        let live = self
            .tasks
            .iter()
            .any(|task| matches!(task.stage, Stage::Running(_) | Stage::Restarting(_)));
        if live || self.tasks.is_empty() {
            return None;
        }
        let failure = self.tasks.iter().find_map(|task| match &task.stage {
            Stage::GaveUp(reason) => Some(format!("task {} failed: {reason}", task.name)),
            _ => None,
        });
        Some(failure.map_or(ModuleExit::Finished, ModuleExit::Failed))
    }
}

impl<S> Drop for ModuleRun<S> {
    fn drop(&mut self) {
        // The copy's threads are gone with it, whatever they were waiting on.
        self.shared
            .cell
            .threads_of(&self.shared.name, ModuleThreads::clear);
    }
}

impl<S: Send + Sync + 'static> std::future::Future for ModuleRun<S> {
    type Output = ModuleExit;

    // Inlined into the supervisor's future: a module's poll is its task's poll, with no
    // call of its own between them.
    #[inline(always)]
    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<ModuleExit> {
        let this = self.get_mut();
        // Without a subscriber there is no span, and nothing to enter at every poll.
        if this.span.is_some() {
            return this.poll_in_span(cx);
        }
        this.poll_copy(cx)
    }
}

impl<S: Send + Sync + 'static> ModuleRun<S> {
    #[cold]
    #[inline(never)]
    fn poll_in_span(&mut self, cx: &mut Context<'_>) -> Poll<ModuleExit> {
        let _entered = self.span.as_deref().cloned().map(tracing::Span::entered);
        self.poll_copy(cx)
    }

    #[inline(always)]
    fn poll_copy(&mut self, cx: &mut Context<'_>) -> Poll<ModuleExit> {
        if self.kill.poll_killed(cx, &mut self.kill_waker) {
            return Poll::Ready(ModuleExit::Killed);
        }
        self.poll_threads(cx)
    }
}

impl<S: Send + Sync + 'static> ModuleRun<S> {
    /// One poll of the module: its threads, and the handlers their ranks admit.
    #[inline(always)]
    fn poll_threads(&mut self, cx: &mut Context<'_>) -> Poll<ModuleExit> {
        // The usual module, between two messages: one task, no handler to start or run,
        // nothing raised. Its poll is its task's poll, and one load after it tells whether
        // the task raised something that the order must look at.
        if self.single && self.handlers.is_empty() && !self.shared.has_pending() {
            if !self.poll_task(0, cx) {
                if !self.shared.has_pending() {
                    return Poll::Pending;
                }
            } else if let Some(exit) = self.exit() {
                return Poll::Ready(exit);
            }
        }
        self.poll_all(cx)
    }

    /// [`ModuleRun::poll_threads`] for whatever the usual case does not cover.
    #[inline(never)]
    fn poll_all(&mut self, cx: &mut Context<'_>) -> Poll<ModuleExit> {
        let mut budget = TURN_BUDGET;
        loop {
            let mut progress = self.admit();
            // Running handlers are kept in rank order, most urgent first.
            let mut index = 0;
            while index < self.handlers.len() && budget > 0 {
                budget -= 1;
                if self.poll_handler(index, cx) {
                    progress = true;
                } else {
                    index += 1;
                }
                progress |= self.admit();
            }
            for index in 0..self.tasks.len() {
                budget = budget.saturating_sub(1);
                progress |= self.poll_task(index, cx);
                progress |= self.admit();
            }
            // Only a thread that finished or started can end the module: a poll that moved
            // nothing leaves the answer as it was the last time, `None`.
            if progress && let Some(exit) = self.exit() {
                return Poll::Ready(exit);
            }
            if !progress && !self.park(cx) {
                return Poll::Pending;
            }
            if budget == 0 {
                // Still busy after a whole budget (say, a handler that raises its own
                // exception again and again): let the other tasks of the thread run first.
                cx.waker().wake_by_ref();
                return Poll::Pending;
            }
        }
    }
}

/// How many polls of its threads one poll of a module may run before it yields to the
/// runtime, as a processor's turn does: a module that always has more to do cannot starve
/// the other modules of its thread.
const TURN_BUDGET: usize = 64;

fn panic_message(panic: &(dyn std::any::Any + Send)) -> String {
    panic
        .downcast_ref::<&str>()
        .map(|text| (*text).to_owned())
        .or_else(|| panic.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "panicked".to_owned())
}
