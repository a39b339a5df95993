//! The deadlock watchdog of a cell on a clock other than a virtual one: a task that looks
//! at the cell's waits every [`BOUND`] of the cell's time, if a wait has begun since its last
//! look. On virtual time no watchdog runs: a cycle is looked for as its closing wait begins
//! ([`CellShared::wait_began`]).

use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::Duration;

use crate::shared::CellShared;

/// On a clock other than a virtual one, the longest a deadlock cycle goes unnamed.
pub(crate) const BOUND: Duration = Duration::from_millis(100);

/// Starts the watchdog of `cell`, once, where its clock needs one. It needs a tokio runtime,
/// and waits for the first module's start if there is none yet.
pub(crate) fn watch(cell: &Arc<CellShared>) {
    if cell.on_virtual_time
        || cell.watched.load(Ordering::Acquire)
        || cell.watched.swap(true, Ordering::AcqRel)
    {
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
