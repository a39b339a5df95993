//! Helpers shared by the integration tests.
#![allow(dead_code, unreachable_pub)]

use std::time::Duration;

use imrs_ports::Instant;

/// `n` seconds.
pub fn secs(n: u64) -> Duration {
    Duration::from_secs(n)
}

/// The instant `n` seconds after the clock started.
pub fn at(n: u64) -> Instant {
    Instant::from_start(secs(n))
}

/// A current-thread runtime on tokio's paused clock, as `imrs_core::time::drive` wants it.
pub fn paused_runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .start_paused(true)
        .build()
        .unwrap()
}

/// A two-worker multi-thread runtime on the wall clock, for the tests that cross threads.
pub fn multi_thread_runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .unwrap()
}

/// CHIP_IT's order, from the Appendix.
pub const CHIP_IT_ORDER: [&str; 6] = [
    "READY_TO_CHIP.TIMEOUT",
    "SHARE_FEEDER.TIMEOUT",
    "CHIP_IT",
    "GRASP",
    "SHARE_FEEDER1.CRIT_SECTION",
    "INSERT",
];
