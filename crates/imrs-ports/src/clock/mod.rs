//! The framework clock: every delay and timeout in IMRS asks a [`Clock`].
//!
//! [`RealClock`] follows the wall clock through tokio's timer. [`VirtualClock`] only moves
//! when it is told to, so tests and the simulation run on virtual time with no real waiting,
//! and the same module code runs on either.

mod instant;
mod real;
mod sleep;
mod virtual_clock;

use std::fmt;
use std::sync::Arc;
use std::time::Duration;

pub use instant::Instant;
pub use real::RealClock;
pub use sleep::Sleep;
pub(crate) use sleep::deadline_passed;
pub use virtual_clock::VirtualClock;

/// A source of time for ports, modules and the simulation.
pub trait Clock: Send + Sync + fmt::Debug + 'static {
    /// The current time on this clock.
    fn now(&self) -> Instant;

    /// A future that completes once this clock reaches `deadline`.
    fn sleep_until(&self, deadline: Instant) -> Sleep;

    /// A future that completes once `duration` has passed on this clock.
    fn sleep(&self, duration: Duration) -> Sleep {
        self.sleep_until(self.now() + duration)
    }

    /// This clock as a [`VirtualClock`], if it is one: a cell on virtual time finds its
    /// deadlocks as they close, rather than on a timer of its own.
    fn as_virtual(&self) -> Option<&VirtualClock> {
        None
    }
}

/// A clock shared by the ports and modules of one cell.
pub type SharedClock = Arc<dyn Clock>;
