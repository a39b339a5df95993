//! How a module ended, told once by its supervisor to every [`ModuleHandle`] of it.
//!
//! A watch channel would do, but it carries a value lock and eight wait lists for its many
//! readers — several hundred bytes in every module, for news that comes once.
//!
//! [`ModuleHandle`]: crate::ModuleHandle

use std::sync::{Arc, Mutex, PoisonError};

use tokio::sync::Notify;

/// The outcome cell shared by a module's supervisor and its handles.
#[derive(Debug, Default)]
pub(crate) struct Outcome {
    told: Mutex<Option<ModuleOutcome>>,
    changed: Notify,
}

impl Outcome {
    /// The outcome, if the module has ended.
    pub(crate) fn get(&self) -> Option<ModuleOutcome> {
        // One read or one write at a time: never left half-done.
        self.told
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
    }

    /// Waits until the module has ended.
    pub(crate) async fn wait(&self) -> ModuleOutcome {
        loop {
            let changed = self.changed.notified();
            tokio::pin!(changed);
            // Registered before the look, so that an outcome told in between is not missed.
            changed.as_mut().enable();
            if let Some(outcome) = self.get() {
                return outcome;
            }
            changed.await;
        }
    }

    fn tell(&self, outcome: ModuleOutcome) {
        let mut told = self.told.lock().unwrap_or_else(PoisonError::into_inner);
        if told.is_none() {
            *told = Some(outcome);
        }
        drop(told);
        self.changed.notify_waiters();
    }
}

/// The supervisor's side: tells the outcome once; if the supervisor is dropped without
/// telling (its runtime shut down), the module counts as killed.
#[derive(Debug)]
pub(crate) struct Teller(Option<Arc<Outcome>>);

impl Teller {
    pub(crate) fn new(outcome: &Arc<Outcome>) -> Self {
        Self(Some(Arc::clone(outcome)))
    }

    pub(crate) fn tell(mut self, outcome: ModuleOutcome) {
        if let Some(cell) = self.0.take() {
            cell.tell(outcome);
        }
    }
}

impl Drop for Teller {
    fn drop(&mut self) {
        if let Some(cell) = self.0.take() {
            cell.tell(ModuleOutcome::Killed);
        }
    }
}

/// How a module ended for good.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ModuleOutcome {
    /// Every task finished.
    Finished,
    /// It failed, and its restart policy was spent.
    Failed(String),
    /// It was stopped, or killed with no restart left.
    Killed,
}
