//! Presence: whether the module behind a port end may still come back.
//!
//! An end that is dropped leaves its side of the port vacant. Whoever waits on that side —
//! a sender, a querier, a receiver — should wait while a new copy of the module may attach
//! (a supervised restart), and fail at once when none ever will, as a client of a dead QNX
//! server is unblocked with an error. Only the module's supervisor knows which: it holds a
//! [`Presence`] for the module, polls the module within it ([`Presence::within`]), and marks it [gone](Presence::set_gone) when the module has ended
//! for good. Every end attached while a presence is entered (and every end
//! [bound](crate::Respond::bind) to one) is held by that module; when its side is vacant and
//! the presence is gone, the waiters on the other side fail with `PeerGone`.
//!
//! Ends attached outside any module (plain tasks, tests) have no presence: their side is
//! gone only when the port itself is closed (no end attached and no declaration left).

use std::cell::Cell;
use std::fmt;
use std::ptr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError, Weak};

use crate::name::Name;

thread_local! {
    /// The presence of the module being polled on this thread, or null: a plain pointer, so
    /// that entering it at every poll of a module is a store into a thread-local that needs
    /// no destructor, and costs no reference count.
    static CURRENT: Cell<*const Presence> = const { Cell::new(ptr::null()) };
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

    /// Runs `body` with `presence` (or none) the current one on this thread: ends attached
    /// meanwhile are held by its module. A closure rather than a guard, so that presences
    /// entered on one thread are left in the order they were entered, whatever the caller.
    #[inline]
    pub fn within<R>(presence: Option<&Arc<Presence>>, body: impl FnOnce() -> R) -> R {
        /// Puts back the presence that was current, also when `body` unwinds.
        struct Restore(*const Presence);
        impl Drop for Restore {
            #[inline]
            fn drop(&mut self) {
                CURRENT.set(self.0);
            }
        }
        let _restore = Restore(CURRENT.replace(presence.map_or(ptr::null(), Arc::as_ptr)));
        body()
    }

    /// The presence entered on this thread, if any.
    pub(crate) fn current() -> Option<Arc<Presence>> {
        let current = CURRENT.get();
        if current.is_null() {
            return None;
        }
        // SAFETY: a pointer other than null in `CURRENT` was put there by `within`, from an
        // `Arc` its caller lends for the whole of `body`, and `within` puts back the one
        // before when `body` returns or unwinds. Calls of `within` on one thread nest (each
        // is a closure call), so the pointer is of an `Arc` that lives now; counting one more
        // reference for the copy returned keeps it alive as long as the copy.
        unsafe {
            Arc::increment_strong_count(current);
            Some(Arc::from_raw(current))
        }
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

#[cfg(test)]
mod tests {
    use super::*;

    fn current_module() -> Option<String> {
        Presence::current().map(|presence| presence.module().to_string())
    }

    #[test]
    fn within_nests_and_restores_even_on_unwind() {
        let outer = Presence::new("OUTER");
        let inner = Presence::new("INNER");
        assert_eq!(current_module(), None);
        Presence::within(Some(&outer), || {
            assert_eq!(current_module().as_deref(), Some("OUTER"));
            Presence::within(Some(&inner), || {
                assert_eq!(current_module().as_deref(), Some("INNER"));
            });
            Presence::within(None, || assert_eq!(current_module(), None));
            let unwound = std::panic::catch_unwind(|| {
                Presence::within(Some(&inner), || panic!("a poll that panics"));
            });
            assert!(unwound.is_err());
            assert_eq!(current_module().as_deref(), Some("OUTER"));
        });
        assert_eq!(current_module(), None);
    }

    #[test]
    fn a_copy_of_the_current_presence_outlives_the_lender() {
        let lent = Presence::new("LENT");
        let copy = Presence::within(Some(&lent), Presence::current).expect("one is current");
        assert_eq!(Arc::strong_count(&lent), 2);
        drop(lent);
        assert_eq!(copy.module().as_str(), "LENT");
        assert_eq!(Arc::strong_count(&copy), 1);
    }
}
