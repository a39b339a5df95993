//! Many modules at once: 1 000 modules in a ring pass a token, each hop a rendezvous
//! (`ctx.send` answered at once by the next module's `ctx.receive`), on a runtime of 1 and 2
//! threads and of every core; beside it, the same ring of tokio tasks, each hop an mpsc
//! send answered through a oneshot. One iteration is one hop: criterion's figure per
//! iteration is the time per message, its throughput line messages per second.

#[path = "config.rs"]
mod config;

use std::time::{Duration, Instant};

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use imrs_benches::{benchmarking, imrs_ring, runtime};
use tokio::sync::{mpsc, oneshot};

type Hop = (u64, oneshot::Sender<()>);

/// The same ring as tokio tasks: each hop an mpsc send, answered through a oneshot.
fn tokio_ring(size: usize, hops: u64, threads: usize) -> Duration {
    let runtime = runtime(threads);
    let timed = runtime.block_on(async {
        let (senders, receivers): (Vec<_>, Vec<_>) =
            (0..size).map(|_| mpsc::channel::<Hop>(1)).unzip();
        let (done, finished) = oneshot::channel();
        let mut done = Some(done);
        let mut first = None;
        for (i, mut inbox) in receivers.into_iter().enumerate() {
            let next = senders[(i + 1) % size].clone();
            // Task `t % size` receives token `t`: the last hop lands at `hops % size`.
            let done = if i == (hops % size as u64) as usize {
                done.take()
            } else {
                None
            };
            if i == 0 {
                first = Some(next.clone());
            }
            tokio::spawn(async move {
                while let Some((token, ack)) = inbox.recv().await {
                    let _ = ack.send(());
                    if token == hops {
                        if let Some(done) = done {
                            let _ = done.send(());
                        }
                        return;
                    }
                    let (ack, acked) = oneshot::channel();
                    if next.send((token + 1, ack)).await.is_err() {
                        return;
                    }
                    let _ = acked.await;
                }
            });
        }
        let first = first.expect("a ring has a first task");
        let start = Instant::now();
        let (ack, acked) = oneshot::channel();
        first.send((1, ack)).await.expect("the ring listens");
        let _ = acked.await;
        finished.await.expect("the last hop landed");
        start.elapsed()
    });
    drop(runtime);
    timed
}

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
    }
    group.finish();
}

criterion_group! {
    name = benches;
    config = config::long_run();
    targets = ring
}
criterion_main!(benches);
