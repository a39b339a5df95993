//! A processor: several modules co-scheduled on one tokio task.
//!
//! Modules that talk at every turn — a robot and its gripper, a parent and its TIGHT child —
//! pay for each rendezvous with two trips through the runtime's scheduler when each is a
//! task of its own. Placed on one processor, a wake from one to the other sets a flag, and
//! the processor polls the woken module next, in the same turn of its task.
//!
//! Modules on one processor run one at a time, as on one CPU of the seed's multiprocessor;
//! modules on different processors (or started with [`Cell::start`](crate::Cell::start))
//! run in parallel on a multi-thread runtime.

use std::cell::Cell;
use std::fmt;
use std::future::Future;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::pin::Pin;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::task::{Context, Poll, Wake, Waker};

use imrs_ports::Name;
use tokio::sync::{Notify, oneshot};

type Job = Pin<Box<dyn Future<Output = ()> + Send>>;

/// How many polls of its jobs one turn of the processor's task may make before it yields to
/// the runtime, so that a job that keeps waking itself cannot starve timers and other tasks.
const TURN_BUDGET: usize = 256;

/// A handle to a processor: modules and futures placed on it share one tokio task.
///
/// The processor's task ends once every handle is dropped and every job on it has finished.
#[derive(Clone)]
pub struct Processor {
    owner: Arc<Owner>,
}

/// Closes the processor when the last handle goes.
struct Owner {
    shared: Arc<Shared>,
}

struct Shared {
    name: Name,
    /// Set while the processor's task is inside its poll loop: a wake then only sets the
    /// woken job's flag, because the loop looks at every flag again before it parks.
    polling: AtomicBool,
    /// Jobs placed on the processor and not yet picked up by its task.
    arrivals: Mutex<Vec<Job>>,
    arrived: AtomicBool,
    closed: AtomicBool,
    /// Wakes the processor's task.
    task: Notify,
}

impl Shared {
    fn wake_task(&self) {
        if !self.polling.load(Ordering::SeqCst) {
            self.task.notify_one();
        }
    }
}

/// The waker of one job: a flag, and the processor's task if it is parked.
struct JobWake {
    ready: AtomicBool,
    shared: Arc<Shared>,
}

impl Wake for JobWake {
    fn wake(self: Arc<Self>) {
        self.wake_by_ref();
    }

    fn wake_by_ref(self: &Arc<Self>) {
        if RUNNING.get() == Arc::as_ptr(&self.shared) {
            // A job of the processor whose turn this thread is running woke another (the
            // common case: one end of a rendezvous wakes the other). The turn reads the flag
            // on this same thread before it ends, so a plain store is enough.
            self.ready.store(true, Ordering::Relaxed);
            return;
        }
        // SeqCst pairs with the loop's clearing of `polling` and its last look at the
        // flags: either the loop sees this flag, or this wake sees the loop gone and
        // wakes the task.
        self.ready.store(true, Ordering::SeqCst);
        self.shared.wake_task();
    }
}

thread_local! {
    /// The processor whose turn this thread is running, if any.
    static RUNNING: Cell<*const Shared> = const { Cell::new(std::ptr::null()) };
}

/// Marks this thread as running `shared`'s turn, until dropped.
struct Running {
    before: *const Shared,
}

impl Running {
    fn enter(shared: &Arc<Shared>) -> Self {
        Self {
            before: RUNNING.replace(Arc::as_ptr(shared)),
        }
    }
}

impl Drop for Running {
    fn drop(&mut self) {
        RUNNING.set(self.before);
    }
}

struct Slot {
    job: Job,
    wake: Arc<JobWake>,
    waker: Waker,
}

impl Processor {
    /// A new processor named `name`, its task spawned on the current tokio runtime.
    ///
    /// # Panics
    ///
    /// Outside a tokio runtime, as [`tokio::spawn`] does.
    pub fn new(name: impl Into<Name>) -> Self {
        let shared = Arc::new(Shared {
            name: name.into(),
            polling: AtomicBool::new(false),
            arrivals: Mutex::default(),
            arrived: AtomicBool::new(false),
            closed: AtomicBool::new(false),
            task: Notify::new(),
        });
        tokio::spawn(run(Arc::clone(&shared)));
        Self {
            owner: Arc::new(Owner { shared }),
        }
    }

    /// The processor's name.
    pub fn name(&self) -> &Name {
        &self.owner.shared.name
    }

    /// Runs `future` on the processor, beside whatever else runs there; the handle yields
    /// its output. Dropping the handle leaves the job running.
    ///
    /// A job that panics is dropped, and its handle yields [`JobLost`]; the others go on.
    pub fn spawn<F>(&self, future: F) -> JobHandle<F::Output>
    where
        F: Future + Send + 'static,
        F::Output: Send + 'static,
    {
        let (output, handle) = oneshot::channel();
        self.place(async move {
            // The handle may be gone: then nobody wants the output.
            let _ = output.send(future.await);
        });
        JobHandle {
            processor: self.name().clone(),
            output: handle,
        }
    }

    /// Puts `job` on the processor's list and wakes its task.
    pub(crate) fn place(&self, job: impl Future<Output = ()> + Send + 'static) {
        let shared = &self.owner.shared;
        shared
            .arrivals
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .push(Box::pin(job));
        shared.arrived.store(true, Ordering::SeqCst);
        shared.wake_task();
    }
}

/// The output of a job placed with [`Processor::spawn`], once it has finished.
#[derive(Debug)]
#[must_use = "a job handle does nothing unless awaited; drop it to leave the job running"]
pub struct JobHandle<T> {
    processor: Name,
    output: oneshot::Receiver<T>,
}

impl<T> Future for JobHandle<T> {
    type Output = Result<T, JobLost>;

    fn poll(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Self::Output> {
        Pin::new(&mut self.output).poll(cx).map_err(|_| JobLost {
            processor: self.processor.clone(),
        })
    }
}

/// A job ended without an output: it panicked, or its processor's task was dropped (its
/// runtime shut down) before the job finished.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct JobLost {
    /// The processor the job ran on.
    pub processor: Name,
}

impl fmt::Display for JobLost {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "a job on processor {} ended without an output: it panicked, or the processor's \
             runtime shut down",
            self.processor
        )
    }
}

impl std::error::Error for JobLost {}

/// Whether `flag` was set, clearing it. A plain load first: the scheduler looks at flags far
/// more often than it finds them set, and a load costs no read-modify-write.
fn take(flag: &AtomicBool) -> bool {
    flag.load(Ordering::Relaxed) && flag.swap(false, Ordering::SeqCst)
}

impl Drop for Owner {
    fn drop(&mut self) {
        self.shared.closed.store(true, Ordering::SeqCst);
        self.shared.wake_task();
    }
}

impl fmt::Debug for Processor {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Processor")
            .field("name", self.name())
            .finish_non_exhaustive()
    }
}

/// The processor's task: polls each woken job in turn until none is woken, then parks.
async fn run(shared: Arc<Shared>) {
    let mut slots: Vec<Slot> = Vec::new();
    loop {
        let notified = shared.task.notified();
        tokio::pin!(notified);
        // Registered before the flags are read, so that a wake after the last look at them
        // is not lost.
        notified.as_mut().enable();
        shared.polling.store(true, Ordering::SeqCst);
        match turn(&shared, &mut slots) {
            Turn::Busy => tokio::task::yield_now().await,
            Turn::Idle => notified.await,
            Turn::Done => return,
        }
    }
}

enum Turn {
    /// The budget ran out with jobs still woken.
    Busy,
    /// No job is woken.
    Idle,
    /// Closed, and every job has finished.
    Done,
}

/// Polls woken jobs until none is woken, the budget is spent, or the processor is done.
fn turn(shared: &Arc<Shared>, slots: &mut Vec<Slot>) -> Turn {
    let _running = Running::enter(shared);
    let mut budget = TURN_BUDGET;
    loop {
        if take(&shared.arrived) {
            let arrivals = std::mem::take(
                &mut *shared
                    .arrivals
                    .lock()
                    .unwrap_or_else(PoisonError::into_inner),
            );
            slots.extend(arrivals.into_iter().map(|job| {
                let wake = Arc::new(JobWake {
                    ready: AtomicBool::new(true),
                    shared: Arc::clone(shared),
                });
                let waker = Waker::from(Arc::clone(&wake));
                Slot { job, wake, waker }
            }));
        }
        let mut polled = false;
        let mut index = 0;
        while index < slots.len() {
            let slot = &mut slots[index];
            if !take(&slot.wake.ready) {
                index += 1;
                continue;
            }
            if budget == 0 {
                // Leave the flag set for the next turn.
                slot.wake.ready.store(true, Ordering::SeqCst);
                shared.polling.store(false, Ordering::SeqCst);
                return Turn::Busy;
            }
            budget -= 1;
            polled = true;
            let mut cx = Context::from_waker(&slot.waker);
            match catch_unwind(AssertUnwindSafe(|| slot.job.as_mut().poll(&mut cx))) {
                Ok(Poll::Pending) => index += 1,
                // Finished or panicked: either way it is done. `remove` keeps the others in
                // the order they came, so that a run on virtual time is reproducible.
                Ok(Poll::Ready(())) | Err(_) => {
                    slots.remove(index);
                }
            }
        }
        if polled {
            continue;
        }
        shared.polling.store(false, Ordering::SeqCst);
        let woken = shared.arrived.load(Ordering::SeqCst)
            || slots
                .iter()
                .any(|slot| slot.wake.ready.load(Ordering::SeqCst));
        if woken {
            shared.polling.store(true, Ordering::SeqCst);
            continue;
        }
        if slots.is_empty() && shared.closed.load(Ordering::SeqCst) {
            return Turn::Done;
        }
        return Turn::Idle;
    }
}
