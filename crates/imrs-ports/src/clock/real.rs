use std::time::Duration;

use super::{Clock, Instant, Sleep};

/// The wall clock, through tokio's timer.
///
/// Sleeping needs a tokio runtime with its time driver enabled (`enable_time` or
/// `enable_all`).
#[derive(Debug, Clone, Copy)]
pub struct RealClock {
    start: std::time::Instant,
}

impl RealClock {
    /// A clock whose [`Instant::ZERO`] is now.
    pub fn new() -> Self {
        Self {
            start: std::time::Instant::now(),
        }
    }
}

impl Default for RealClock {
    fn default() -> Self {
        Self::new()
    }
}

impl Clock for RealClock {
    fn now(&self) -> Instant {
        Instant::from_start(self.start.elapsed())
    }

    fn sleep_until(&self, deadline: Instant) -> Sleep {
        // A deadline past what the system clock can name (a `Duration::MAX` timeout) is
        // as good as never: thirty years out.
        let never = Duration::from_secs(30 * 365 * 24 * 3600);
        let at = self
            .start
            .checked_add(deadline.since_start())
            .unwrap_or_else(|| std::time::Instant::now() + never);
        Sleep::real(tokio::time::sleep_until(at.into()))
    }
}
