//! One write's fate, shared by the writer and every copy of its value in the readers' queues.

use std::sync::{Mutex, MutexGuard, PoisonError};
use std::task::Waker;

/// Where a write stands. It leaves `Pending` once, to `Read` (the writer proceeds) or to
/// `Withdrawn` (the writer gave up first); whoever moves it first wins.
#[derive(Debug)]
pub(crate) enum Fate {
    Pending(Option<Waker>),
    Read,
    Withdrawn,
}

#[derive(Debug)]
pub(crate) struct Ticket(Mutex<Fate>);

impl Ticket {
    pub(crate) fn new() -> Self {
        Self(Mutex::new(Fate::Pending(None)))
    }

    /// The innermost lock: nothing else is locked while it is held.
    pub(crate) fn lock(&self) -> MutexGuard<'_, Fate> {
        self.0.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// A reader took a copy: the first read releases the writer. False if the write was
    /// withdrawn, so the copy must be skipped.
    pub(crate) fn read(&self) -> bool {
        let mut fate = self.lock();
        match std::mem::replace(&mut *fate, Fate::Read) {
            Fate::Pending(waker) => {
                drop(fate);
                waker.into_iter().for_each(Waker::wake);
                true
            }
            Fate::Read => true,
            Fate::Withdrawn => {
                *fate = Fate::Withdrawn;
                false
            }
        }
    }

    /// The writer gives up: true if nobody had read the value yet (it is now withdrawn).
    pub(crate) fn withdraw(&self) -> bool {
        let mut fate = self.lock();
        if matches!(*fate, Fate::Pending(_)) {
            *fate = Fate::Withdrawn;
            true
        } else {
            false
        }
    }

    /// Wakes the writer to look again (an input it writes to was closed).
    pub(crate) fn nudge(&self) {
        if let Fate::Pending(waker) = &mut *self.lock() {
            waker.take().into_iter().for_each(Waker::wake);
        }
    }
}
