//! The switch that kills or stops a module's running copy from outside: held by its
//! supervisor, its handles and the cell, and looked at by the copy at every poll.

use std::sync::atomic::{AtomicBool, Ordering};
use std::task::{Context, Waker};

use atomic_waker::AtomicWaker;

/// Kills a running module from outside: its future ends at its next poll.
#[derive(Debug, Default)]
pub(crate) struct KillSwitch {
    killed: AtomicBool,
    stopped: AtomicBool,
    /// Woken by the kill that ends a copy: once per copy at most, which is what lets a copy
    /// register its waker only when the waker changes ([`ModuleRun`]'s `kill_waker`).
    waker: AtomicWaker,
}

impl KillSwitch {
    /// Kills the current copy; a supervised module may get a new one.
    pub(crate) fn kill(&self) {
        self.killed.store(true, Ordering::Release);
        self.waker.wake();
    }

    /// Kills the current copy and asks for no new one.
    pub(crate) fn stop(&self) {
        self.stopped.store(true, Ordering::Release);
        self.kill();
    }

    pub(crate) fn is_stopped(&self) -> bool {
        self.stopped.load(Ordering::Acquire)
    }

    pub(crate) fn rearm(&self) {
        self.killed.store(false, Ordering::Release);
    }

    /// Whether the copy is killed; if not, `cx`'s waker is registered for the kill, unless
    /// `registered` (the waker this copy registered last) will wake the same task. A kill
    /// ends the copy, so the waker registered is taken by a wake only once per copy, and
    /// skipping the registration (two compare-and-swaps at every poll) loses no kill.
    #[inline]
    pub(crate) fn poll_killed(&self, cx: &mut Context<'_>, registered: &mut Option<Waker>) -> bool {
        if !registered
            .as_ref()
            .is_some_and(|waker| waker.will_wake(cx.waker()))
        {
            self.waker.register(cx.waker());
            *registered = Some(cx.waker().clone());
        }
        // After the registration: a kill that this load misses wakes the waker registered.
        self.killed.load(Ordering::Acquire)
    }
}
