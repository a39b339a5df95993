//! What a module's tasks and handlers share: its name, state and order, the cell, the
//! children it costarted, and the exceptions and restarts raised and not yet taken by its
//! scheduler.

use std::collections::VecDeque;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use imrs_ports::{Instant, ModuleState, Name};

use crate::event::{Event, EventKind};
use crate::exception::Exception;
use crate::order::Order;
use crate::shared::{CellShared, Children};

/// What a module's tasks and handlers share.
pub(crate) struct ModuleShared<S> {
    pub(crate) name: Name,
    pub(crate) parent: Option<Name>,
    pub(crate) state: Arc<ModuleState<S>>,
    pub(crate) order: Order,
    pub(crate) cell: Arc<CellShared>,
    /// The modules this copy costarted, stopped when it ends.
    pub(crate) children: Children,
    raised: Mutex<VecDeque<Exception>>,
    restarts: Mutex<Vec<Name>>,
    /// Set while `raised` or `restarts` may hold something, so that the scheduler, which
    /// looks after every poll, takes no lock when (as nearly always) there is nothing.
    pending: AtomicBool,
}

impl<S> ModuleShared<S> {
    pub(crate) fn new(
        spec_name: Name,
        parent: Option<Name>,
        state: Arc<ModuleState<S>>,
        order: Order,
        cell: Arc<CellShared>,
        children: Children,
    ) -> Self {
        Self {
            name: spec_name,
            parent,
            state,
            order,
            cell,
            children,
            raised: Mutex::new(VecDeque::new()),
            restarts: Mutex::new(Vec::new()),
            pending: AtomicBool::new(false),
        }
    }

    pub(crate) fn event(&self, task: Option<&Name>, kind: EventKind) {
        if self.logged() {
            self.event_at(self.cell.clock.now(), task, kind);
        }
    }

    /// Whether an event made now would be seen: the log keeps or streams it, or `tracing`
    /// takes it. When not, an event costs nothing, not even its clock read.
    pub(crate) fn logged(&self) -> bool {
        self.cell.events.is_wanted() || crate::event::traced()
    }

    /// As [`ModuleShared::event`], at `at`: for a caller that has just read the clock.
    pub(crate) fn event_at(&self, at: Instant, task: Option<&Name>, kind: EventKind) {
        self.cell.events.record(Event {
            at,
            module: self.name.clone(),
            task: task.cloned(),
            kind,
        });
    }

    /// Asks the scheduler to kill task `task` (if it runs) and start a new copy of it.
    pub(crate) fn request_restart(&self, task: Name) {
        lock(&self.restarts).push(task);
        self.pending.store(true, Ordering::Release);
    }

    pub(crate) fn raise(&self, exception: Exception) {
        self.event(
            exception.task.as_ref(),
            EventKind::ExceptionRaised {
                exception: exception.name.clone(),
            },
        );
        lock(&self.raised).push_back(exception);
        self.pending.store(true, Ordering::Release);
    }

    /// Takes the first raised exception that `may_start` allows now.
    pub(crate) fn take_raised(&self, may_start: impl Fn(&Exception) -> bool) -> Option<Exception> {
        if !self.pending.load(Ordering::Acquire) {
            return None;
        }
        let mut raised = lock(&self.raised);
        let position = raised.iter().position(may_start)?;
        raised.remove(position)
    }

    /// Whether an exception or a restart request may be waiting: a load, no lock.
    pub(crate) fn has_pending(&self) -> bool {
        self.pending.load(Ordering::Acquire)
    }

    /// Whether any raised exception waits for its handler.
    pub(crate) fn has_raised(&self) -> bool {
        self.pending.load(Ordering::Acquire) && !lock(&self.raised).is_empty()
    }

    /// The tasks that were asked to restart since the last call. Also clears the `pending`
    /// flag, unless exceptions still wait (whoever pushes sets it again after pushing).
    pub(crate) fn take_restart_requests(&self) -> Vec<Name> {
        // Looked at after every poll of every thread: a load, not a swap, in the usual case
        // of nothing pending, so that it costs no read-modify-write.
        if !self.pending.load(Ordering::Acquire) || !self.pending.swap(false, Ordering::AcqRel) {
            return Vec::new();
        }
        let requests = std::mem::take(&mut *lock(&self.restarts));
        if !lock(&self.raised).is_empty() {
            self.pending.store(true, Ordering::Release);
        }
        requests
    }
}

fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    // Only ever held for one push or pop: never left half-done by a panic.
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
}
