//! Where a bridge's wake-ups go.
//!
//! A bridge is woken when the other process notifies (through tokio's reactor), when a
//! module of its own sends, and when a module answers a request that crossed. Waking the
//! bridge's task for each, and the task then waking the module, puts a task switch on every
//! crossing, four to a round trip, which the raw iceoryx2 round trip does not pay. So on a
//! port that parks, the bridge's work is done at once in the thread that wakes it: the
//! reactor's, which then wakes the module itself, or the module's own. The task is woken
//! instead where that thread cannot do it: the bridge is busy elsewhere, or the port is
//! TIGHT, whose spinning waits move the messages in their own turns ([`crate::turn`]).

use std::sync::{Arc, Mutex, OnceLock, TryLockError, Weak};
use std::task::Wake;

/// A bridge's side, as its wake-ups see it.
pub(crate) trait Work: Send + 'static {
    /// Moves what has arrived, either way, and registers the dispatch to be woken when more
    /// does. Must not block. `everything`: looks at all there may be, whatever woke it, so
    /// that a message whose notification was lost waits one tick at most; otherwise only
    /// at what the wake-ups said is there. Whether the bridge is still open: `false` once
    /// its port or its reactor is gone, for good.
    fn work(&mut self, everything: bool) -> bool;
}

/// The waker of a bridge: does the bridge's work where it is woken, or wakes its task.
pub(crate) struct Dispatch {
    side: OnceLock<Weak<Mutex<dyn Work>>>,
    /// Whether the work may be done where the wake-up comes (a port that parks).
    inline: bool,
    task: tokio::sync::Notify,
}

impl Dispatch {
    /// A dispatch that does the work where it is woken if `inline`, and otherwise always
    /// wakes the task.
    pub(crate) fn new(inline: bool) -> Arc<Self> {
        Arc::new(Self {
            side: OnceLock::new(),
            inline,
            task: tokio::sync::Notify::new(),
        })
    }

    /// The side whose work is done. Held weakly: the side holds this dispatch's waker.
    pub(crate) fn serve(&self, side: Weak<Mutex<dyn Work>>) {
        let _set_once = self.side.set(side);
    }

    /// Waits until the task is to do the work.
    pub(crate) async fn woken(&self) {
        self.task.notified().await;
    }

    /// Does the work here, if it can be done here now: `false` if not. Any thread will do,
    /// in the runtime or not (a module may answer from a thread of its own): the work
    /// waits for nothing and starts no timer, as the bridges' ends have no timeout.
    fn work_here(&self) -> bool {
        if !self.inline {
            return false;
        }
        let Some(side) = self.side.get().and_then(Weak::upgrade) else {
            return false;
        };
        // Busy (in another thread, or further up this one): whoever holds it is told below,
        // through the task, and looks again.
        let mut side = match side.try_lock() {
            Ok(side) => side,
            Err(TryLockError::Poisoned(poisoned)) => poisoned.into_inner(),
            Err(TryLockError::WouldBlock) => return false,
        };
        // A bridge found closed here is ended by its task, at its next turn.
        let _open = side.work(false);
        true
    }
}

impl Wake for Dispatch {
    fn wake(self: Arc<Self>) {
        self.wake_by_ref();
    }

    fn wake_by_ref(self: &Arc<Self>) {
        if !self.work_here() {
            self.task.notify_one();
        }
    }
}
