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
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::task::{Context, Poll, Wake, Waker};

use imrs_ports::transport::waking;
use imrs_ports::{Name, Priority};
use tokio::sync::{Notify, oneshot};

type Job = Pin<Box<dyn Future<Output = ()> + Send>>;

/// How many polls of its jobs one turn of the processor's task may make before it yields to
/// the runtime, so that a job that keeps waking itself cannot starve timers and other tasks.
const TURN_BUDGET: usize = 256;

/// A handle to a processor: modules and futures placed on it share one tokio task.
///
/// # The message handler
///
/// Seed 000 §5.1 gives each processor a message handler that resumes "the most urgent thread
/// of control", judged by task, message and channel priorities. A processor's rule is:
///
/// > Of its woken jobs, a processor polls next the most urgent. A job's urgency is its own
/// > priority, lifted, for its next poll only, to the priority of the port whose message
/// > (request or reply) woke it, if that is higher. Equals go in the order they were placed.
/// > A job that has waited [`AGING`](Processor::AGING) polls of others goes first, oldest first.
///
/// Priorities are [`Priority`] values, as ports have: 1 is the most urgent, and a job or
/// port that declares none ranks below every declared one. A module's priority is
/// [`ModuleSpec::priority`](crate::ModuleSpec::priority); a plain future's, the one given
/// to [`Processor::spawn_with_priority`]. So a routine module can get an emergency stop
/// through to a safety module of low priority ahead of a busy module of higher priority, if
/// the stop travels on a port of higher priority than that module (the seed's "crucial
/// emergency message through a high priority port").
///
/// The processor is cooperative: the choice is made at each suspension point of the job
/// that runs, never in the middle of a poll. No woken job starves: it is polled after at
/// most `AGING + n - 1` polls of the others, `n` the number of jobs on the processor.
/// The choice depends only on wakes and priorities, so a run on virtual time is
/// reproducible.
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
    arrivals: Mutex<Vec<(Priority, Job)>>,
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
    /// The most urgent port priority among the wakes from other threads since the job was
    /// last polled, encoded by [`encode`]; 0 when none.
    lift: AtomicU64,
    /// The same, for the wakes made on the thread that runs the processor's turn (one job of
    /// the processor waking another): only that thread writes it, and only while it runs
    /// the turn, so it is raised by a load and a store, with no read-modify-write.
    local_lift: AtomicU64,
    shared: Arc<Shared>,
}

/// A priority as a number that grows with urgency, 0 for [`Priority::DEFAULT`].
fn encode(priority: Priority) -> u64 {
    priority
        .number()
        .map_or(0, |n| u64::from(u32::MAX) + 1 - u64::from(n))
}

impl Wake for JobWake {
    fn wake(self: Arc<Self>) {
        self.wake_by_ref();
    }

    fn wake_by_ref(self: &Arc<Self>) {
        let lift = waking();
        if RUNNING.get() == Arc::as_ptr(&self.shared) {
            // A job of the processor whose turn this thread is running woke another (the
            // common case: one end of a rendezvous wakes the other). The turn reads the flag
            // and the lift on this same thread before it ends, so plain stores are enough.
            if lift != Priority::DEFAULT {
                let lift = encode(lift);
                if lift > self.local_lift.load(Ordering::Relaxed) {
                    self.local_lift.store(lift, Ordering::Relaxed);
                }
            }
            self.ready.store(true, Ordering::Relaxed);
            return;
        }
        if lift != Priority::DEFAULT {
            // Published by the store of `ready` below, which the turn takes before it
            // reads the lift.
            self.lift.fetch_max(encode(lift), Ordering::Relaxed);
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
    /// The job's own priority, encoded by [`encode`] (so that the turn compares integers).
    priority: u64,
    /// Woken and not yet polled since. Kept here, not in the wake's flag, so that the turn
    /// notes when it became ready.
    ready: bool,
    /// The poll count of the processor when the job was noted ready.
    ready_since: u64,
    /// Its own priority, lifted by the ports whose messages woke it; encoded.
    urgency: u64,
}

/// The jobs of a processor, as its task keeps them.
#[derive(Default)]
struct Jobs {
    slots: Vec<Slot>,
    /// Polls made so far: the processor's measure of waiting.
    polls: u64,
}

impl Processor {
    /// How many polls of other jobs a woken job may wait before it goes first, whatever its
    /// priority: the bound on starvation.
    pub const AGING: u64 = 64;

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
        self.spawn_with_priority(Priority::DEFAULT, future)
    }

    /// [`Processor::spawn`], with a priority: among woken jobs, the processor polls the
    /// most urgent first (see [the message handler](Processor#the-message-handler)).
    pub fn spawn_with_priority<F>(&self, priority: Priority, future: F) -> JobHandle<F::Output>
    where
        F: Future + Send + 'static,
        F::Output: Send + 'static,
    {
        let (output, handle) = oneshot::channel();
        self.place(priority, async move {
            // The handle may be gone: then nobody wants the output.
            let _ = output.send(future.await);
        });
        JobHandle {
            processor: self.name().clone(),
            output: handle,
        }
    }

    /// Puts `job` on the processor's list and wakes its task.
    pub(crate) fn place(&self, priority: Priority, job: impl Future<Output = ()> + Send + 'static) {
        let shared = &self.owner.shared;
        shared
            .arrivals
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .push((priority, Box::pin(job)));
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

/// The processor's task: polls the most urgent woken job until none is woken, then parks.
async fn run(shared: Arc<Shared>) {
    let mut jobs = Jobs::default();
    loop {
        let notified = shared.task.notified();
        tokio::pin!(notified);
        // Registered before the flags are read, so that a wake after the last look at them
        // is not lost.
        notified.as_mut().enable();
        shared.polling.store(true, Ordering::SeqCst);
        match turn(&shared, &mut jobs) {
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

impl Jobs {
    /// Takes in the jobs placed since the last look.
    fn admit(&mut self, shared: &Arc<Shared>) {
        let arrivals = std::mem::take(
            &mut *shared
                .arrivals
                .lock()
                .unwrap_or_else(PoisonError::into_inner),
        );
        let polls = self.polls;
        self.slots
            .extend(arrivals.into_iter().map(|(priority, job)| {
                let wake = Arc::new(JobWake {
                    ready: AtomicBool::new(false),
                    lift: AtomicU64::new(0),
                    local_lift: AtomicU64::new(0),
                    shared: Arc::clone(shared),
                });
                let waker = Waker::from(Arc::clone(&wake));
                Slot {
                    job,
                    wake,
                    waker,
                    priority: encode(priority),
                    ready: true,
                    ready_since: polls,
                    urgency: encode(priority),
                }
            }));
    }

    /// Notes the jobs woken since the last look, with the lifts their wakes carried.
    fn note_wakes(&mut self) {
        for slot in &mut self.slots {
            if !take(&slot.wake.ready) {
                continue;
            }
            if !slot.ready {
                slot.ready = true;
                slot.ready_since = self.polls;
            }
            let local = slot.wake.local_lift.load(Ordering::Relaxed);
            if local != 0 {
                // This thread runs the turn, the only writer while it does.
                slot.wake.local_lift.store(0, Ordering::Relaxed);
                slot.urgency = slot.urgency.max(local);
            }
            if slot.wake.lift.load(Ordering::Relaxed) != 0 {
                let lift = slot.wake.lift.swap(0, Ordering::Relaxed);
                slot.urgency = slot.urgency.max(lift);
            }
        }
    }

    /// The job to poll next, by [the rule](Processor#the-message-handler).
    fn next(&self) -> Option<usize> {
        self.slots
            .iter()
            .enumerate()
            .filter(|(_, slot)| slot.ready)
            .reduce(|chosen, slot| {
                if self.goes_before(slot.1, chosen.1) {
                    slot
                } else {
                    chosen
                }
            })
            .map(|(index, _)| index)
    }

    /// Whether `slot` goes before `chosen`, which comes earlier in placing order.
    fn goes_before(&self, slot: &Slot, chosen: &Slot) -> bool {
        let aged = |slot: &Slot| self.polls - slot.ready_since >= Processor::AGING;
        match (aged(slot), aged(chosen)) {
            (true, true) => slot.ready_since < chosen.ready_since,
            (true, false) => true,
            (false, true) => false,
            (false, false) => slot.urgency > chosen.urgency,
        }
    }

    /// Polls the job at `index`; drops it if it finished or panicked.
    fn poll(&mut self, index: usize) {
        self.polls += 1;
        let slot = &mut self.slots[index];
        slot.ready = false;
        slot.urgency = slot.priority;
        let mut cx = Context::from_waker(&slot.waker);
        match catch_unwind(AssertUnwindSafe(|| slot.job.as_mut().poll(&mut cx))) {
            Ok(Poll::Pending) => {}
            // Finished or panicked: either way it is done. `remove` keeps the others in the
            // order they came, so that a run on virtual time is reproducible.
            Ok(Poll::Ready(())) | Err(_) => {
                self.slots.remove(index);
            }
        }
    }
}

/// Polls woken jobs, most urgent first, until none is woken, the budget is spent, or the
/// processor is done.
fn turn(shared: &Arc<Shared>, jobs: &mut Jobs) -> Turn {
    let _running = Running::enter(shared);
    let mut budget = TURN_BUDGET;
    loop {
        if take(&shared.arrived) {
            jobs.admit(shared);
        }
        jobs.note_wakes();
        if let Some(index) = jobs.next() {
            if budget == 0 {
                // The job stays noted ready for the next turn.
                shared.polling.store(false, Ordering::SeqCst);
                return Turn::Busy;
            }
            budget -= 1;
            jobs.poll(index);
            continue;
        }
        shared.polling.store(false, Ordering::SeqCst);
        let woken = shared.arrived.load(Ordering::SeqCst)
            || jobs
                .slots
                .iter()
                .any(|slot| slot.wake.ready.load(Ordering::SeqCst));
        if woken {
            shared.polling.store(true, Ordering::SeqCst);
            continue;
        }
        if jobs.slots.is_empty() && shared.closed.load(Ordering::SeqCst) {
            return Turn::Done;
        }
        return Turn::Idle;
    }
}
