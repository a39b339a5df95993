//! How far behind the wall clock the processes of a run across processes fell.
//!
//! Across processes the cell runs on the wall clock sped up by `--speed`: a process that
//! does not get a processor when its timer comes due lives that delay, multiplied by the
//! speed, in the cell's time. At ×60, a timer 10 ms late is 0.6 s of simulated time, and a
//! peer waiting on a 2-second timeout may meet a timeout that the same cell, on a machine
//! that kept up, would not have met. So each process measures how late its runtime's timer
//! wakes it, and the report says the worst and where, so that a timeout the machine caused
//! can be told from one the cell did.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

use crate::report::Report;

/// How often the probe sets its timer: often enough to catch a stall of a few ticks.
const PROBE: Duration = Duration::from_millis(10);

/// The cell's shortest timeout, in simulated time: LET_1_GO's and ASK_CHILD1/2's (see
/// `ports.rs`; a test checks that it still is).
pub(crate) const SHORTEST_TIMEOUT: Duration = Duration::from_secs(2);

/// How late a process's runtime woke its timer, at worst, while its probe ran.
#[derive(Debug, Default)]
pub(crate) struct Lateness {
    worst_micros: Arc<AtomicU64>,
}

impl Lateness {
    /// Measures on the current tokio runtime, as one of its tasks (so that it waits for a
    /// worker as the modules' tasks do), from when `start` completes (the cell's time zero:
    /// a process's start-up is not the cell's) until the runtime ends.
    pub(crate) fn probe(start: impl Future<Output = ()> + Send + 'static) -> Self {
        let lateness = Self::default();
        let worst = Arc::clone(&lateness.worst_micros);
        tokio::spawn(async move {
            start.await;
            loop {
                let due = tokio::time::Instant::now() + PROBE;
                tokio::time::sleep_until(due).await;
                let late = tokio::time::Instant::now().saturating_duration_since(due);
                let micros = u64::try_from(late.as_micros()).unwrap_or(u64::MAX);
                worst.fetch_max(micros, Ordering::Relaxed);
            }
        });
        lateness
    }

    /// The worst so far, in wall time.
    pub(crate) fn worst(&self) -> Duration {
        Duration::from_micros(self.worst_micros.load(Ordering::Relaxed))
    }
}

/// The line, beside [`crate::speed_line`], on whether the processes of a run across
/// processes kept up with its speed: the worst lateness, and the process it was in. A
/// lateness beyond a quarter of the cell's shortest timeout, in simulated time, warns that
/// the run's timeouts may be the machine's. `None` for a run in one process.
pub fn keeping_up_line(report: &Report) -> Option<String> {
    verdict(report.processes?, &report.lateness)
}

/// The line for a run at `speed` whose processes were late at worst by `lateness`
/// (`(process, wall seconds)`); `None` if no process measured.
fn verdict(speed: f64, lateness: &[(String, f64)]) -> Option<String> {
    let (process, worst) = lateness
        .iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(process, worst)| (process.as_str(), *worst))?;
    let simulated = worst * speed;
    let shown = format!(
        "timers woke at worst {:.1} ms late ({simulated:.2} s simulated), in {process}",
        worst * 1000.0
    );
    let limit = SHORTEST_TIMEOUT.as_secs_f64() / 4.0;
    Some(if simulated <= limit {
        format!("kept up with x {speed}: {shown}")
    } else {
        format!(
            "FELL BEHIND x {speed}: {shown}, beyond a quarter of the cell's shortest timeout \
             ({} s): a timeout in this run may be the machine's, not the cell's; choose a \
             lower --speed",
            SHORTEST_TIMEOUT.as_secs_f64()
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test(start_paused = true)]
    async fn a_runtime_held_up_past_the_probes_timer_is_measured_late() {
        let lateness = Lateness::probe(std::future::ready(()));
        // Let the probe set its timer, then hold the runtime's clock up: tokio's paused
        // clock jumps 50 ms, past the probe's deadline 10 ms out, before the probe runs.
        tokio::task::yield_now().await;
        tokio::time::advance(Duration::from_millis(50)).await;
        tokio::task::yield_now().await;
        let worst = lateness.worst();
        assert!(
            worst >= Duration::from_millis(40) && worst <= Duration::from_millis(41),
            "{worst:?}"
        );
        // Ticks on time leave the worst as it was.
        tokio::time::sleep(Duration::from_millis(100)).await;
        assert_eq!(lateness.worst(), worst);
    }

    #[test]
    fn the_shortest_timeout_is_that_of_the_cells_ports() {
        use imrs_ports::{SharedClock, VirtualClock};
        use imrs_sim::Line;

        use crate::ports::LinePorts;

        let clock: SharedClock = Arc::new(VirtualClock::new());
        let ports = LinePorts::new(Line::A, &clock);
        let timeouts = [
            ports.let_1_go.owner().unwrap().timeout(),
            ports.ask_child1.owner().unwrap().timeout(),
            ports.ask_child2.owner().unwrap().timeout(),
            ports.pallet_in_place.owner().unwrap().timeout(),
            ports.card_in_place.owner().unwrap().timeout(),
            ports.ready_to_chip.owner().unwrap().timeout(),
            ports.share_feeder.owner().unwrap().timeout(),
        ];
        assert_eq!(timeouts.iter().flatten().min(), Some(&SHORTEST_TIMEOUT));
    }

    #[test]
    fn the_line_names_the_latest_process_and_warns_past_a_quarter_of_the_shortest_timeout() {
        assert_eq!(verdict(60.0, &[]), None);
        let kept = verdict(60.0, &[("world".into(), 0.001), ("line B".into(), 0.008)]).unwrap();
        assert_eq!(
            kept,
            "kept up with x 60: timers woke at worst 8.0 ms late (0.48 s simulated), in line B"
        );
        let behind = verdict(60.0, &[("line A".into(), 0.009), ("world".into(), 0.002)]).unwrap();
        assert!(
            behind.starts_with(
                "FELL BEHIND x 60: timers woke at worst 9.0 ms late (0.54 s simulated), in line A"
            ),
            "{behind}"
        );
        assert!(behind.contains("choose a lower --speed"), "{behind}");
    }
}
