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
        let at = self.start + deadline.since_start();
        Sleep::real(tokio::time::sleep_until(at.into()))
    }
}
