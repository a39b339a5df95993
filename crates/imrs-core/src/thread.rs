//! A thread of control of a module (a task, or an exception handler that runs): the section
//! it is in, which the module's scheduler reads at every suspension point, and the record of
//! the peers it waits on, which the deadlock diagnosis reads once a wait has lasted. One
//! allocation, shared by the thread's `Ctx` and the scheduler.

use std::sync::atomic::{AtomicU32, Ordering};

use imrs_ports::Name;

use crate::order::Rank;
use crate::wait_record::WaitRecord;

#[derive(Debug)]
pub(crate) struct Thread {
    /// The task's (or handler's) name.
    pub(crate) task: Name,
    pub(crate) section: SectionCell,
    pub(crate) waits: WaitRecord,
}

impl Thread {
    /// A thread of task (or handler) `task`, in background code (or its handler) at `rank`.
    pub(crate) fn new(task: Name, rank: Rank) -> Self {
        Self {
            task,
            section: SectionCell::new(rank),
            waits: WaitRecord::default(),
        }
    }
}

/// The section a thread of a module is in, as a rank, and whether it is a *named* section
/// (one the order ranks, such as `GRASP`): read by the module's scheduler at every
/// suspension point.
#[derive(Debug)]
pub(crate) struct SectionCell(AtomicU32);

/// The bit of a [`SectionCell`] that marks a named section; ranks use the bits below it.
const NAMED: u32 = 1 << 31;

impl SectionCell {
    /// A thread in background code or a handler at `rank`: no named section.
    pub(crate) fn new(rank: Rank) -> Self {
        Self(AtomicU32::new(rank.position()))
    }

    pub(crate) fn get(&self) -> Rank {
        Rank::from_raw(self.0.load(Ordering::Relaxed) & !NAMED)
    }

    /// The rank of the named section the thread is in, if it is in one.
    pub(crate) fn named(&self) -> Option<Rank> {
        let raw = self.0.load(Ordering::Relaxed);
        (raw & NAMED != 0).then(|| Rank::from_raw(raw & !NAMED))
    }

    /// Enters a section: a named one at `rank`, or (`None`) one the order does not name,
    /// which keeps the rank of the code around it. Returns what to restore on leaving.
    pub(crate) fn enter(&self, rank: Option<Rank>) -> u32 {
        match rank {
            Some(rank) => self.0.swap(rank.position() | NAMED, Ordering::Relaxed),
            None => self.0.load(Ordering::Relaxed),
        }
    }

    pub(crate) fn restore(&self, raw: u32) {
        self.0.store(raw, Ordering::Relaxed);
    }

    /// Back to background code (or a handler) at `rank`.
    pub(crate) fn set(&self, rank: Rank) {
        self.0.store(rank.position(), Ordering::Relaxed);
    }
}
