//! The n-way rendezvous `waitfor`, for n = 2, 4, 16, 64 and 256 tasks: the time of one round;
//! beside each, a round of tokio's `Barrier` for as many tasks, which shows what the runtime
//! itself adds as n grows (more tasks woken per round, more task state to go through).
//!
//! Each task's combining function reads one message (`getmess`), so that the figure is the
//! rendezvous' own cost: a function that folds over the whole pool makes every round O(n²)
//! by itself, whatever the rendezvous costs.

#[path = "config.rs"]
mod config;

use std::sync::Arc;
use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use imrs_benches::current_thread;
use imrs_core::WaitFor;
use imrs_ports::RealClock;

/// `rounds` rounds of a waitfor of `n` tasks; the time from the first call to the last return.
fn rounds(n: usize, rounds: u64) -> Duration {
    current_thread().block_on(async move {
        let names: Vec<String> = (0..n).map(|i| format!("T{i}")).collect();
        let barrier = WaitFor::<u64>::new("MEET", names.clone(), Arc::new(RealClock::new()))
            .expect("distinct members");
        let start = Instant::now();
        let tasks: Vec<_> = names
            .into_iter()
            .map(|name| {
                let barrier = barrier.clone();
                tokio::spawn(async move {
                    for round in 0..rounds {
                        let own = barrier
                            .waitfor(&name, round, |pool| pool.getmess(&name).copied(), None)
                            .await
                            .unwrap();
                        std::hint::black_box(own);
                    }
                })
            })
            .collect();
        for task in tasks {
            task.await.unwrap();
        }
        start.elapsed()
    })
}

/// `rounds` rounds of a tokio `Barrier` of `n` tasks, timed the same way.
fn barrier_rounds(n: usize, rounds: u64) -> Duration {
    current_thread().block_on(async move {
        let barrier = Arc::new(tokio::sync::Barrier::new(n));
        let start = Instant::now();
        let tasks: Vec<_> = (0..n)
            .map(|_| {
                let barrier = Arc::clone(&barrier);
                tokio::spawn(async move {
                    for _ in 0..rounds {
                        std::hint::black_box(barrier.wait().await.is_leader());
                    }
                })
            })
            .collect();
        for task in tasks {
            task.await.unwrap();
        }
        start.elapsed()
    })
}

fn benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("waitfor");
    for n in [2, 4, 16, 64, 256] {
        group.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter_custom(|iters| rounds(n, iters))
        });
        group.bench_function(BenchmarkId::new("tokio_barrier", n), |b| {
            b.iter_custom(|iters| barrier_rounds(n, iters))
        });
    }
    group.finish();
}

criterion_group! {
    name = waitfor_benches;
    config = config::primitive();
    targets = benches
}
criterion_main!(waitfor_benches);
