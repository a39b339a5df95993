//! Restart policies for failed tasks and modules, as robot-cell supervisors expect: a
//! bounded number of restarts with a growing delay between them.

use std::time::Duration;

/// How a failed task or module is restarted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RestartPolicy {
    /// How many times a new copy is started before giving up.
    pub max_restarts: u32,
    /// The delay before the first restart.
    pub backoff: Duration,
    /// Each further delay is the previous one times this factor.
    pub factor: u32,
    /// The longest delay.
    pub max_backoff: Duration,
}

impl RestartPolicy {
    /// Never restart: a failure is final.
    pub const NEVER: RestartPolicy = RestartPolicy {
        max_restarts: 0,
        backoff: Duration::ZERO,
        factor: 1,
        max_backoff: Duration::ZERO,
    };

    /// Up to `max_restarts` restarts, the first after `backoff`, each next one twice as late,
    /// at most a minute apart.
    pub const fn restart(max_restarts: u32, backoff: Duration) -> Self {
        Self {
            max_restarts,
            backoff,
            factor: 2,
            max_backoff: Duration::from_secs(60),
        }
    }

    /// The delay before restart number `attempt` (from 1), or `None` if the policy is spent.
    pub fn delay_before(&self, attempt: u32) -> Option<Duration> {
        if attempt == 0 || attempt > self.max_restarts {
            return None;
        }
        let growth = self.factor.saturating_pow(attempt - 1);
        Some(self.backoff.saturating_mul(growth).min(self.max_backoff))
    }
}

impl Default for RestartPolicy {
    fn default() -> Self {
        Self::NEVER
    }
}
