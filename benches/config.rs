//! The criterion settings the bench files share, so that every group of a kind measures
//! the same way. Each bench file includes this module (`#[path]`) and uses one of the two,
//! hence the `dead_code` allowances.

use std::time::Duration;

use criterion::Criterion;

/// For a primitive's round trips: many short samples.
#[allow(dead_code)]
pub(crate) fn primitive() -> Criterion {
    Criterion::default()
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2))
        .sample_size(20)
}

/// For a long run per iteration (a ring of modules, a simulated hour): fewer, longer samples.
#[allow(dead_code)]
pub(crate) fn long_run() -> Criterion {
    Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3))
        .sample_size(10)
}
