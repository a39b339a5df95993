use std::time::{Duration, SystemTime};

use super::{Clock, Instant, Sleep};

/// The wall clock, through tokio's timer: at its own pace, or sped up by a constant factor.
///
/// Sleeping needs a tokio runtime with its time driver enabled (`enable_time` or
/// `enable_all`).
///
/// Several processes agree on one time with [`RealClock::from_epoch`]: each clock's
/// [`Instant::ZERO`] is the same moment of the system clock, and each runs at the same speed,
/// so a cell split over processes keeps one time without a message between them.
#[derive(Debug, Clone, Copy)]
pub struct RealClock {
    start: std::time::Instant,
    speed: f64,
}

impl RealClock {
    /// The greatest speed-up: beyond it a tick of tokio's millisecond timer is more than
    /// ten simulated seconds, and a cell's timeouts mean little.
    pub const MAX_SPEED: f64 = 10_000.0;

    /// A clock whose [`Instant::ZERO`] is now, running at the wall clock's pace.
    pub fn new() -> Self {
        Self {
            start: std::time::Instant::now(),
            speed: 1.0,
        }
    }

    /// A clock whose [`Instant::ZERO`] is the moment `epoch` of the system clock (past or
    /// future; before it the clock reads zero) and that runs `speed` times as fast as the
    /// wall clock. `None` unless `speed` is a number from 1 to [`Self::MAX_SPEED`], or if `epoch`
    /// lies further than a year from now.
    pub fn from_epoch(epoch: SystemTime, speed: f64) -> Option<Self> {
        if !(speed.is_finite() && (1.0..=Self::MAX_SPEED).contains(&speed)) {
            return None;
        }
        let year = Duration::from_secs(365 * 24 * 3600);
        let (monotonic, system) = (std::time::Instant::now(), SystemTime::now());
        let start = match epoch.duration_since(system) {
            // The epoch is still to come.
            Ok(ahead) if ahead <= year => monotonic.checked_add(ahead)?,
            Ok(_) => return None,
            Err(past) if past.duration() <= year => monotonic.checked_sub(past.duration())?,
            Err(_) => return None,
        };
        Some(Self { start, speed })
    }

    /// How many times as fast as the wall clock it runs.
    pub fn speed(&self) -> f64 {
        self.speed
    }
}

impl Default for RealClock {
    fn default() -> Self {
        Self::new()
    }
}

impl Clock for RealClock {
    fn now(&self) -> Instant {
        let elapsed = std::time::Instant::now().saturating_duration_since(self.start);
        if self.speed == 1.0 {
            return Instant::from_start(elapsed);
        }
        Instant::from_start(elapsed.mul_f64(self.speed))
    }

    fn sleep_until(&self, deadline: Instant) -> Sleep {
        // A deadline past what the system clock can name (a `Duration::MAX` timeout) is
        // as good as never: thirty years out.
        let never = Duration::from_secs(30 * 365 * 24 * 3600);
        let wall = if self.speed == 1.0 {
            // Exact, with no round trip through a float.
            deadline.since_start()
        } else {
            Duration::try_from_secs_f64(deadline.since_start().as_secs_f64() / self.speed)
                .unwrap_or(never)
        };
        let at = self
            .start
            .checked_add(wall)
            .unwrap_or_else(|| std::time::Instant::now() + never);
        Sleep::real(tokio::time::sleep_until(at.into()))
    }
}
