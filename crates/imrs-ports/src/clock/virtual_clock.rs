use std::collections::BTreeMap;
use std::fmt;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::task::{Context, Poll, Waker};
use std::time::Duration;

use super::{Clock, Instant, Sleep};

/// A clock that moves only when told to: by a test, or by the simulation's stepper.
///
/// Timers that come due are woken in deadline order (ties in the order they were first
/// polled), which keeps single-thread runs reproducible.
#[derive(Clone, Default)]
pub struct VirtualClock {
    shared: Arc<Shared>,
}

#[derive(Default)]
struct Shared {
    state: Mutex<State>,
    /// `state.now` in nanoseconds since the start, written under the lock whenever it
    /// moves: every event a module logs reads the clock, and a load costs no lock.
    now: AtomicU64,
}

#[derive(Default)]
struct State {
    now: Instant,
    next_id: u64,
    timers: BTreeMap<(Instant, u64), Waker>,
}

impl VirtualClock {
    /// A virtual clock standing at [`Instant::ZERO`].
    pub fn new() -> Self {
        Self::default()
    }

    /// Moves the clock forward by `by`, waking every timer that comes due.
    pub fn advance(&self, by: Duration) {
        let to = self.now() + by;
        self.advance_to(to);
    }

    /// Moves the clock to `to` (never backwards), waking every timer due by then.
    pub fn advance_to(&self, to: Instant) {
        let due = {
            let mut state = self.shared.lock();
            state.now = state.now.max(to);
            let now = state.now;
            self.shared.now.store(nanos(now), Ordering::Release);
            let later = state.timers.split_off(&(now, u64::MAX));
            std::mem::replace(&mut state.timers, later)
        };
        due.into_values().for_each(Waker::wake);
    }

    /// Moves the clock to the earliest pending deadline and wakes its timers; returns that
    /// deadline, or `None` (and leaves the clock alone) when no timer is pending.
    pub fn advance_to_next(&self) -> Option<Instant> {
        let next = self.next_deadline()?;
        self.advance_to(next);
        Some(next)
    }

    /// The earliest deadline of a pending timer.
    pub fn next_deadline(&self) -> Option<Instant> {
        let state = self.shared.lock();
        state.timers.keys().next().map(|&(at, _)| at)
    }

    /// How many timers are pending: tasks blocked in a delay or a timed primitive.
    pub fn sleepers(&self) -> usize {
        self.shared.lock().timers.len()
    }
}

/// `at` in nanoseconds since the start; past 584 years, the most a `u64` holds.
fn nanos(at: Instant) -> u64 {
    u64::try_from(at.since_start().as_nanos()).unwrap_or(u64::MAX)
}

impl Shared {
    fn lock(&self) -> MutexGuard<'_, State> {
        // A panic while holding this lock cannot leave the map half-updated: every critical
        // section is a single map operation. So a poisoned lock is still consistent.
        self.state
            .lock()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }
}

impl Clock for VirtualClock {
    fn now(&self) -> Instant {
        Instant::from_start(Duration::from_nanos(
            self.shared.now.load(Ordering::Acquire),
        ))
    }

    fn sleep_until(&self, deadline: Instant) -> Sleep {
        Sleep::virtual_timer(VirtualTimer {
            shared: Arc::clone(&self.shared),
            deadline,
            id: None,
        })
    }

    fn as_virtual(&self) -> Option<&VirtualClock> {
        Some(self)
    }
}

impl fmt::Debug for VirtualClock {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let state = self.shared.lock();
        f.debug_struct("VirtualClock")
            .field("now", &state.now)
            .field("sleepers", &state.timers.len())
            .finish()
    }
}

/// One pending wait on a [`VirtualClock`].
pub(super) struct VirtualTimer {
    shared: Arc<Shared>,
    deadline: Instant,
    id: Option<u64>,
}

impl VirtualTimer {
    pub(super) fn poll(&mut self, cx: &mut Context<'_>) -> Poll<()> {
        let mut state = self.shared.lock();
        if state.now >= self.deadline {
            if let Some(id) = self.id.take() {
                state.timers.remove(&(self.deadline, id));
            }
            return Poll::Ready(());
        }
        let id = *self.id.get_or_insert_with(|| {
            state.next_id += 1;
            state.next_id
        });
        state.timers.insert((self.deadline, id), cx.waker().clone());
        Poll::Pending
    }
}

impl Drop for VirtualTimer {
    fn drop(&mut self) {
        if let Some(id) = self.id {
            self.shared.lock().timers.remove(&(self.deadline, id));
        }
    }
}
