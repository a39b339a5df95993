//! The step grid the chip line and the hand are stepped on, shared so that both land their
//! steps on the same instants of the clock.

use std::time::Duration;

use imrs_ports::Instant;

/// The step grid: the first multiple of `step` after `now`.
pub(crate) fn next_step_after(now: Instant, step: Duration) -> Instant {
    let step = step.as_nanos();
    let now = now.since_start().as_nanos();
    let next = (now / step + 1) * step;
    Instant::from_start(Duration::from_nanos(next as u64))
}
