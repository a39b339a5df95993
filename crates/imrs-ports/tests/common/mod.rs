//! Helpers shared by the integration tests.
#![allow(dead_code, unreachable_pub)]

use std::future::Future;
use std::sync::Arc;

use imrs_ports::{SharedClock, VirtualClock};

/// Runs the test body on tokio's current-thread runtime and then on its multi-thread one.
pub fn on_both_runtimes<F, Fut>(body: F)
where
    F: Fn() -> Fut,
    Fut: Future<Output = ()> + Send + 'static,
{
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .expect("current-thread runtime")
        .block_on(body());
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .expect("multi-thread runtime")
        .block_on(body());
}

/// A virtual clock, and the same clock as the ports take it.
pub fn virtual_clock() -> (VirtualClock, SharedClock) {
    let clock = VirtualClock::new();
    let shared: SharedClock = Arc::new(clock.clone());
    (clock, shared)
}

/// Yields until `count` tasks wait on the virtual clock: the point where advancing the clock
/// fires their timeouts. Never sleeps for real.
pub async fn until_sleepers(clock: &VirtualClock, count: usize) {
    for _ in 0..1_000_000 {
        if clock.sleepers() >= count {
            return;
        }
        tokio::task::yield_now().await;
    }
    panic!(
        "{count} sleeper(s) expected on the virtual clock, found {}",
        clock.sleepers()
    );
}

/// Yields until `ready` holds.
pub async fn until(mut ready: impl FnMut() -> bool) {
    for _ in 0..1_000_000 {
        if ready() {
            return;
        }
        tokio::task::yield_now().await;
    }
    panic!("condition not reached");
}
