//! A transport's turn in a spinning wait.
//!
//! A port that crosses processes has a transport beneath it: tasks that carry each message
//! between the module's port and shared memory. A parked wait is woken by those tasks. A
//! spinning wait (a TIGHT port) would rather not be: waking a task, and the task waking a
//! thread, costs more than the whole round trip its spin was meant to save. So a spinning
//! wait gives the transport a turn between its looks, in the module's own thread, and the
//! message moves with no task woken. The transport's tasks stay for the waits that park.

/// What a transport does in the thread of a module whose wait on the port spins
/// ([`Port::pump_with`](crate::transport::PortTransport::pump_with)).
pub trait Pump: Send + Sync + 'static {
    /// A turn, between two looks of a spinning wait: moves what has arrived, either way. It
    /// must not block; a turn that finds the transport busy elsewhere skips.
    fn pump(&self);

    /// The spinning wait stops spinning and parks: whatever the transport held back because
    /// a spinning peer would find it unasked (a wake-up of the other process) goes now.
    fn parking(&self);
}
