//! Presence: whether the module behind a port end may still come back.
//!
//! An end that is dropped leaves its side of the port vacant. Whoever waits on that side —
//! a sender, a querier, a receiver — should wait while a new copy of the module may attach
//! (a supervised restart), and fail at once when none ever will, as a client of a dead QNX
//! server is unblocked with an error. Only the module's supervisor knows which: it holds a
//! [`Presence`] for the module, enters it around every poll of the module
//! ([`Presence::enter`]), and marks it [gone](Presence::set_gone) when the module has ended
//! for good. Every end attached while a presence is entered (and every end
//! [bound](crate::Respond::bind) to one) is held by that module; when its side is vacant and
//! the presence is gone, the waiters on the other side fail with `PeerGone`.
//!
//! Ends attached outside any module (plain tasks, tests) have no presence: their side is
//! gone only when the port itself is closed (no end attached and no declaration left).

use std::cell::Cell;
use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError, Weak};

use crate::name::Name;

thread_local! {
    /// The presence of the module being polled on this thread, if any.
    static CURRENT: Cell<Option<Arc<Presence>>> = const { Cell::new(None) };
}

/// Something to wake when a presence is gone: a port whose side it held.
pub(crate) trait Watcher: Send + Sync {
    /// Wakes everyone waiting on the port, so that each looks again at its peer.
    fn wake_all(&self);
}

/// The life of one module across its copies: live (or coming back), or gone for good.
pub struct Presence {
    module: Name,
    gone: AtomicBool,
    /// The ports this module has held, woken when it is gone.
    watchers: Mutex<Vec<Weak<dyn Watcher>>>,
}

impl Presence {
    /// The presence of module `module`, live.
    pub fn new(module: impl Into<Name>) -> Arc<Self> {
        Arc::new(Self {
            module: module.into(),
            gone: AtomicBool::new(false),
            watchers: Mutex::new(Vec::new()),
        })
    }

    /// The module.
    pub fn module(&self) -> &Name {
        &self.module
    }

    /// Whether the module has ended for good.
    pub fn is_gone(&self) -> bool {
        self.gone.load(Ordering::Acquire)
    }

    /// Marks the module as ended for good, and wakes everyone waiting on a port it held.
    pub fn set_gone(&self) {
        self.gone.store(true, Ordering::Release);
        let watchers = std::mem::take(&mut *self.watchers());
        for watcher in watchers.iter().filter_map(Weak::upgrade) {
            watcher.wake_all();
        }
    }

    /// Makes `presence` the current one on this thread until the returned guard leaves: ends
    /// attached meanwhile are held by its module. Moves the `Arc` in and out, so entering
    /// costs no reference count.
    pub fn enter(presence: Option<Arc<Presence>>) -> Entered {
        Entered {
            previous: Some(CURRENT.replace(presence)),
        }
    }

    /// The presence entered on this thread, if any.
    pub(crate) fn current() -> Option<Arc<Presence>> {
        CURRENT.with(|current| {
            let presence = current.take();
            let copy = presence.clone();
            current.set(presence);
            copy
        })
    }

    /// Wakes `watcher` when this presence is gone. A port is watched once, however often the
    /// module re-attaches to it.
    pub(crate) fn watch(&self, watcher: Weak<dyn Watcher>) {
        let mut watchers = self.watchers();
        watchers.retain(|known| known.strong_count() > 0);
        if !watchers.iter().any(|known| Weak::ptr_eq(known, &watcher)) {
            watchers.push(watcher);
        }
    }

    fn watchers(&self) -> MutexGuard<'_, Vec<Weak<dyn Watcher>>> {
        // Each critical section is one push, scan or take: a panic cannot leave it half-done.
        self.watchers.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

impl fmt::Debug for Presence {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Presence")
            .field("module", &self.module)
            .field("gone", &self.is_gone())
            .finish_non_exhaustive()
    }
}

/// A presence entered on this thread; see [`Presence::enter`].
#[must_use = "leave the presence to get it back"]
#[derive(Debug)]
pub struct Entered {
    previous: Option<Option<Arc<Presence>>>,
}

impl Entered {
    /// Restores the presence that was current before, and hands back the one entered.
    pub fn leave(mut self) -> Option<Arc<Presence>> {
        let previous = self.previous.take().expect("left once");
        CURRENT.replace(previous)
    }
}

impl Drop for Entered {
    fn drop(&mut self) {
        // Left without `leave` (a panic unwinding through the poll): restore anyway.
        if let Some(previous) = self.previous.take() {
            drop(CURRENT.replace(previous));
        }
    }
}
