//! Many modules at once: 1 000 modules in a ring pass a token, each hop a rendezvous
//! (`ctx.send` answered at once by the next module's `ctx.receive`), on a runtime of 1 and 2
//! threads and of every core; beside it, the same ring of tokio tasks, each hop an mpsc
//! send answered through a oneshot, on the same runtime; and, on one thread, the same ring of
//! kameo actors (each hop an `ask`) and of ractor actors (each hop a `call!`). Every hop
//! carries a `u64` token by value and is answered at once, before the token goes on.
//! One iteration is one hop: criterion's figure per iteration is the time per message, its
//! throughput line messages per second.

#[path = "config.rs"]
mod config;

use std::time::Duration;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use imrs_benches::{benchmarking, imrs_ring, kameo_ring, ractor_ring, tokio_ring};

/// Runs at least one lap (so that every module takes part) and scales the time to `hops`.
fn per_hops(hops: u64, size: usize, run: impl FnOnce(u64) -> Duration) -> Duration {
    let made = hops.max(size as u64);
    run(made).mul_f64(hops as f64 / made as f64)
}

fn ring(c: &mut Criterion) {
    let size = if benchmarking() { 1_000 } else { 10 };
    let cores = std::thread::available_parallelism().map_or(2, usize::from);
    let mut group = c.benchmark_group("ring_1000");
    group.throughput(Throughput::Elements(1));
    let mut counts = vec![1, 2, cores];
    counts.dedup();
    for threads in counts {
        group.bench_function(
            BenchmarkId::new("imrs", format!("{threads}_threads")),
            |b| b.iter_custom(|hops| per_hops(hops, size, |laps| imrs_ring(size, laps, threads))),
        );
        group.bench_function(
            BenchmarkId::new("tokio", format!("{threads}_threads")),
            |b| b.iter_custom(|hops| per_hops(hops, size, |laps| tokio_ring(size, laps, threads))),
        );
        if threads == 1 {
            group.bench_function(BenchmarkId::new("kameo", "1_threads"), |b| {
                b.iter_custom(|hops| per_hops(hops, size, |laps| kameo_ring(size, laps)))
            });
            group.bench_function(BenchmarkId::new("ractor", "1_threads"), |b| {
                b.iter_custom(|hops| per_hops(hops, size, |laps| ractor_ring(size, laps)))
            });
        }
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = config::long_run();
    targets = ring
}
criterion_main!(benches);
