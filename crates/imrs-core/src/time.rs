//! Running a cell on virtual time.

use std::time::Duration;

use imrs_ports::{Clock, Instant, VirtualClock};

/// Drives `clock` up to `until`: whenever every task of the runtime is idle, the clock jumps
/// to the next timer. Returns the time reached.
///
/// Idleness is read from tokio's own paused clock, so run this on a current-thread runtime
/// built with `start_paused(true)` (tokio's `test-util` feature): then tokio lets this driver go on only once nothing else
/// can run, and a cell runs as fast as it computes and the same way every time. (On other
/// runtimes it still advances the clock, but without that guarantee.)
pub async fn drive(clock: &VirtualClock, until: Instant) -> Instant {
    loop {
        // Returns only when the runtime is idle: the paused clock auto-advances then.
        tokio::time::sleep(Duration::from_nanos(1)).await;
        match clock.next_deadline() {
            Some(next) if next <= until => clock.advance_to(next),
            _ => {
                clock.advance_to(until);
                // Let whatever `until` woke run before returning.
                tokio::time::sleep(Duration::from_nanos(1)).await;
                return clock.now();
            }
        }
    }
}
