//! How urgent a wake is: the priority of the port whose message caused it.
//!
//! Seed 000 §5.1 wants a processor's message handler to pick the next thread "based on task,
//! message, and communication channel priorities". A [`Waker`](std::task::Waker) carries no
//! such thing, so a port that wakes a peer for a message says, for the length of the wake,
//! which priority it was declared with; an executor's waker reads it with [`waking`].
//! Ports declared without a priority say nothing, and cost nothing.

use std::cell::Cell;

use crate::priority::Priority;

thread_local! {
    /// The priority of the port whose wake this thread is running, if any.
    static WAKING: Cell<Priority> = const { Cell::new(Priority::DEFAULT) };
}

/// The priority of the port whose message causes the wake that this thread is running now:
/// [`Priority::DEFAULT`] outside such a wake, or for a port declared without a priority.
///
/// Read it inside [`Wake::wake`](std::task::Wake::wake): the executor can then lift the
/// woken task for its next poll, as [`Processor`](../imrs_core/struct.Processor.html) does.
pub fn waking() -> Priority {
    WAKING.get()
}

/// Runs `wake` with [`waking`] saying `priority`.
pub(crate) fn wake_at(priority: Priority, wake: impl FnOnce()) {
    if priority == Priority::DEFAULT {
        wake();
        return;
    }
    let before = WAKING.replace(priority);
    // Restored even if a waker panics, so that no later wake is lifted by mistake.
    let _restore = Restore(before);
    wake();
}

struct Restore(Priority);

impl Drop for Restore {
    fn drop(&mut self) {
        WAKING.set(self.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_wake_says_its_port_priority_and_forgets_it_after() {
        assert_eq!(waking(), Priority::DEFAULT);
        let mut seen = None;
        wake_at(Priority::declared(1), || seen = Some(waking()));
        assert_eq!(seen, Some(Priority::declared(1)));
        assert_eq!(waking(), Priority::DEFAULT);
    }

    #[test]
    fn nested_wakes_restore_the_outer_priority() {
        let mut inner = None;
        let mut outer_after = None;
        wake_at(Priority::declared(3), || {
            wake_at(Priority::declared(1), || inner = Some(waking()));
            outer_after = Some(waking());
        });
        assert_eq!(inner, Some(Priority::declared(1)));
        assert_eq!(outer_after, Some(Priority::declared(3)));
    }
}
