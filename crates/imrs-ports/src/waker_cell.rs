//! The cell in which one side of a port leaves its waker for the other side to wake.
//!
//! `atomic_waker::AtomicWaker` takes the waker out to wake it, so a side that waits again
//! must clone its waker back in: at every message, a clone and a drop of the waker, each
//! an atomic read-modify-write of the task's reference count. This cell keeps the waker
//! and wakes it by reference: a side that registers the same task again only arms the
//! cell, and a wake reads the waker in place.
//!
//! A wake still wakes only a waker armed since the last wake, as `AtomicWaker` does: a side
//! that got its answer without waiting is not woken for nothing.
//!
//! The state word holds three things: `ARMED`, set by a registration and taken by the wake
//! that wakes it; `REGISTERING`, held by the one side that registers; and the number of
//! wakes reading the cell now. A wake reads the cell only after taking `ARMED`, and a
//! registration writes it only after taking `ARMED` away with no wake reading, so the
//! write never meets a read. Every change of the word is a read-modify-write, so that a
//! registration and a wake are always ordered one way or the other: either the wake finds
//! the cell armed, or the registration's look at the port after arming sees the wake's
//! message.
//!
//! `tests/loom_waker_cell.rs` checks this very file under every interleaving loom explores.

use std::task::Waker;

use crate::loom::{AtomicUsize, Ordering, UnsafeCell};

/// A waker was registered since the last wake.
const ARMED: usize = 1;
/// A side is registering its waker.
const REGISTERING: usize = 2;
/// One wake reading the cell: the count of them is kept in the bits from here up.
const READER: usize = 4;

/// A waker kept in place and woken by reference.
pub(crate) struct WakerCell {
    state: AtomicUsize,
    waker: UnsafeCell<Option<Waker>>,
}

// SAFETY: the cell is written only by the side holding REGISTERING, and only once it has
// taken ARMED away while no wake was reading; a wake reads it only while it counts as a
// reader, which it becomes by taking ARMED. Each hand-over is an acquire/release pair on
// the state word. A `Waker` is `Send + Sync`.
unsafe impl Sync for WakerCell {}

impl Default for WakerCell {
    fn default() -> Self {
        Self::new()
    }
}

impl WakerCell {
    pub(crate) fn new() -> Self {
        Self {
            state: AtomicUsize::new(0),
            waker: UnsafeCell::new(None),
        }
    }

    /// Arms the cell to wake `waker`'s task at the next wake. A waker that wakes the same
    /// task as the one kept is not cloned: the kept one is armed again.
    pub(crate) fn register(&self, waker: &Waker) {
        // Most often nobody is armed or reading: the first guess is an idle word.
        let before = self.update(0, Ordering::Acquire, |state| state | REGISTERING);
        if before & REGISTERING != 0 {
            // Two sides register at once, which no end does: this one's task is woken to
            // look again, as `AtomicWaker` does, and the cell is left to the other.
            waker.wake_by_ref();
            return;
        }
        // SAFETY: with REGISTERING, no other side writes the cell; wakes only read it.
        let kept = self
            .waker
            .with(|cell| unsafe { (*cell).as_ref().is_some_and(|kept| kept.will_wake(waker)) });
        if !kept {
            // No new wake may read the cell while it is written: take ARMED away first.
            let state = self.state.fetch_and(!ARMED, Ordering::AcqRel);
            if state >= READER {
                // A wake is reading the old waker right now (the task changed as a wake
                // ran): the cell cannot be written yet. Woken, this task registers again.
                self.state.fetch_and(!REGISTERING, Ordering::Release);
                waker.wake_by_ref();
                return;
            }
            // SAFETY: REGISTERING, no wake reading, and none can start (ARMED is clear): this
            // thread has the cell to itself. The acquire above pairs with the last reader's
            // release, so its read came before this write.
            self.waker
                .with_mut(|cell| unsafe { *cell = Some(waker.clone()) });
        }
        // Armed, and REGISTERING let go, in one step. The release publishes the cell to the
        // wake that takes ARMED; the acquire makes this side's look at the port after it see
        // the message of any wake ordered before it, which found the cell unarmed.
        self.update(REGISTERING, Ordering::AcqRel, |state| {
            (state | ARMED) & !REGISTERING
        });
    }

    /// Wakes, by reference, the waker armed since the last wake, if one is.
    pub(crate) fn wake(&self) {
        // Unarmed, the word is written back as it was: still a read-modify-write, so that a
        // registration ordered after it sees this wake's message.
        let before = self.update(ARMED, Ordering::AcqRel, |state| {
            if state & ARMED == 0 {
                state
            } else {
                (state & !ARMED) + READER
            }
        });
        if before & ARMED == 0 {
            return;
        }
        // SAFETY: this wake took ARMED and counts as a reader: no registration writes the
        // cell until the count is back to zero. The acquire above pairs with the release
        // of the registration that armed it, so the waker written is the one read.
        self.waker.with(|cell| unsafe {
            if let Some(waker) = &*cell {
                waker.wake_by_ref();
            }
        });
        self.state.fetch_sub(READER, Ordering::Release);
    }

    /// Changes the state word by `change`, in one compare-and-swap where `guess` is what it
    /// holds, as it mostly is; returns the word as it was.
    fn update(&self, guess: usize, order: Ordering, change: impl Fn(usize) -> usize) -> usize {
        let mut state = guess;
        loop {
            match self
                .state
                .compare_exchange(state, change(state), order, Ordering::Relaxed)
            {
                Ok(before) => return before,
                Err(actual) => state = actual,
            }
        }
    }
}

impl std::fmt::Debug for WakerCell {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WakerCell")
            .field("state", &self.state.load(Ordering::Relaxed))
            .finish_non_exhaustive()
    }
}
