//! Many runs at once: each on one thread of as many as there are cores, since a run of the
//! cell uses one.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::thread;

use super::{CellConfig, CellError, Report, run};

/// Runs every config, each on one thread of as many as there are cores; the reports in the
/// configs' order, or the first run's error.
pub fn run_all(configs: &[CellConfig]) -> Result<Vec<Report>, CellError> {
    let threads = thread::available_parallelism().map_or(1, usize::from);
    let next = AtomicUsize::new(0);
    let mut done: Vec<(usize, Result<Report, CellError>)> = thread::scope(|scope| {
        let workers: Vec<_> = (0..threads.min(configs.len()))
            .map(|_| {
                scope.spawn(|| {
                    let mut mine = Vec::new();
                    loop {
                        let index = next.fetch_add(1, Ordering::Relaxed);
                        let Some(config) = configs.get(index) else {
                            break mine;
                        };
                        mine.push((index, run(config)));
                    }
                })
            })
            .collect();
        // A run that panicked panics here, as it would have on this thread.
        (workers.into_iter())
            .flat_map(|worker| {
                worker
                    .join()
                    .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
            })
            .collect()
    });
    done.sort_by_key(|(index, _)| *index);
    done.into_iter().map(|(_, report)| report).collect()
}
