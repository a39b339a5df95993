//! Helpers shared by the benchmarks: runtimes, round-trip drivers, and tail-latency records.
//!
//! Every figure is meant to be read as a ratio to a baseline measured in the same process and
//! the same run (`cargo run -p imrs-benches --bin ratio_table` prints the table).

pub mod ctx;
pub mod idle;
pub mod peers;
pub mod rendezvous;
pub mod ring;

pub use ctx::{KEPT, Timed, ctx_modules, ctx_on_processor, new_cell};
pub use idle::{IdleModules, IdleTasks, idle_modules, idle_tokio_tasks, resident_bytes};
pub use ring::{imrs_ring, kameo_ring, ractor_ring, runtime, tokio_ring};

use std::path::PathBuf;
use std::time::{Duration, Instant};

/// A current-thread tokio runtime with timers.
pub fn current_thread() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .expect("a runtime starts")
}

/// Whether criterion runs for real (`cargo bench`) rather than once in test mode.
pub fn benchmarking() -> bool {
    std::env::args().any(|arg| arg == "--bench")
}

/// The directory criterion writes its estimates into (`target/criterion`).
pub fn criterion_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("CARGO_TARGET_DIR") {
        return PathBuf::from(dir).join("criterion");
    }
    let exe = std::env::current_exe().expect("the benchmark knows its path");
    exe.ancestors()
        .find(|dir| dir.file_name().is_some_and(|name| name == "target"))
        .map(|target| target.join("criterion"))
        .unwrap_or_else(|| PathBuf::from("target/criterion"))
}

/// Single round-trip latencies of one case, and their percentiles.
#[derive(Debug, Default)]
pub struct Tail {
    samples: Vec<Duration>,
}

impl Tail {
    /// Room for `count` samples, allocated before timing starts.
    pub fn with_capacity(count: usize) -> Self {
        Self {
            samples: Vec::with_capacity(count),
        }
    }

    /// Times one round trip.
    pub fn time<R>(&mut self, round_trip: impl FnOnce() -> R) -> R {
        let start = Instant::now();
        let result = round_trip();
        self.samples.push(start.elapsed());
        result
    }

    /// Adds a sample timed elsewhere.
    pub fn push(&mut self, sample: Duration) {
        self.samples.push(sample);
    }

    /// Adds the samples of `other`, e.g. timed inside a task that had to own its record.
    pub fn absorb(&mut self, other: Tail) {
        self.samples.extend(other.samples);
    }

    /// The `p`-th percentile (0 to 100).
    pub fn percentile(&mut self, p: f64) -> Duration {
        if self.samples.is_empty() {
            return Duration::ZERO;
        }
        self.samples.sort_unstable();
        let index = ((p / 100.0) * (self.samples.len() - 1) as f64).round() as usize;
        self.samples[index.min(self.samples.len() - 1)]
    }

    /// Prints p50, p99 and p99.9 of `case`, and saves them beside criterion's estimates for
    /// the ratio table.
    pub fn report(mut self, case: &str) {
        let (p50, p99, p999) = (
            self.percentile(50.0),
            self.percentile(99.0),
            self.percentile(99.9),
        );
        println!(
            "tail {case}: p50 {} ns, p99 {} ns, p99.9 {} ns ({} round trips)",
            p50.as_nanos(),
            p99.as_nanos(),
            p999.as_nanos(),
            self.samples.len()
        );
        let dir = criterion_dir().join("tail");
        if std::fs::create_dir_all(&dir).is_ok() {
            let file = dir.join(format!("{}.txt", case.replace('/', "_")));
            let text = format!(
                "{} {} {}\n",
                p50.as_nanos(),
                p99.as_nanos(),
                p999.as_nanos()
            );
            let _ = std::fs::write(file, text);
        }
    }
}
