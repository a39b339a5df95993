//! What sets the deadlock diagnosis going: on virtual time, a watcher the clock tells before
//! each move, so that a cycle is named at the instant it closed; on any other clock, a
//! watchdog task that looks every [`BOUND`] of the cell's time. Either way the diagnosis
//! looks only if a wait has begun since its last look.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Weak};
use std::time::Duration;

use imrs_ports::clock::BeforeAdvance;

use crate::shared::CellShared;

/// On a clock other than a virtual one, the longest a deadlock cycle goes unnamed.
pub(crate) const BOUND: Duration = Duration::from_millis(100);

/// The virtual clock's watcher of one cell: it does not keep the cell alive.
struct Watcher {
    armed: Arc<AtomicBool>,
    cell: Weak<CellShared>,
}

impl BeforeAdvance for Watcher {
    fn before_advance(&self) -> bool {
        // The usual case, no wait begun since the last move: one load.
        if self.armed.load(Ordering::Relaxed) {
            let Some(cell) = self.cell.upgrade() else {
                return false;
            };
            cell.diagnose();
        }
        self.cell.strong_count() > 0
    }
}

/// Sets the diagnosis of `cell` going, once. On a clock other than a virtual one this needs
/// a tokio runtime, and waits for the first module's start if there is none yet.
pub(crate) fn watch(cell: &Arc<CellShared>) {
    if cell.watched.load(Ordering::Acquire) || cell.watched.swap(true, Ordering::AcqRel) {
        return;
    }
    if let Some(clock) = cell.clock.as_virtual() {
        clock.before_advance(Arc::new(Watcher {
            armed: Arc::clone(&cell.armed),
            cell: Arc::downgrade(cell),
        }));
        return;
    }
    let Ok(runtime) = tokio::runtime::Handle::try_current() else {
        cell.watched.store(false, Ordering::Release);
        return;
    };
    let clock = Arc::clone(&cell.clock);
    let cell = Arc::downgrade(cell);
    runtime.spawn(async move {
        loop {
            clock.sleep(BOUND).await;
            let Some(cell) = cell.upgrade() else {
                return;
            };
            cell.diagnose();
        }
    });
}
