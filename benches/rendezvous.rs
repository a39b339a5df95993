//! A send → receive → reply round trip, for an 8-byte and a 1 KiB message moved by value,
//! every baseline beside the IMRS case it matches, in the same group:
//!
//! - `rendezvous_same_thread`, one thread: IMRS with each end a task of its own (the asker in
//!   `block_on`, the server spawned) beside tokio mpsc + oneshot "ask", kameo's `ask` and
//!   ractor's `call!` placed the same way; IMRS with both ends jobs of one processor (one
//!   task) beside tokio's two ends joined in one task (`tokio::join!`) and two tasks of one
//!   `LocalSet`; and the processor with priorities on.
//! - `rendezvous_cross_thread_cold`: the server on a current-thread runtime in a thread of its
//!   own, parked between messages, the asker on a current-thread runtime of the bench's
//!   thread, for IMRS, tokio, kameo and ractor alike; a crossbeam ping-pong.
//! - `rendezvous_tight`: a TIGHT port across two threads beside two threads spinning on one
//!   atomic, and spinning on one that carries the message on its cache line.

#[path = "config.rs"]
mod config;

use std::time::Duration;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use imrs_benches::rendezvous::*;
use imrs_benches::{Tail, benchmarking};
use imrs_ports::ProcessType;

fn sizes<const N: usize>(c: &mut Criterion, size: &str) {
    let mut group = c.benchmark_group("rendezvous_same_thread");
    group.bench_function(BenchmarkId::new("imrs_two_tasks", size), |b| {
        b.iter_custom(|n| imrs_same_thread_tasks::<N>(n, None))
    });
    group.bench_function(BenchmarkId::new("tokio_two_tasks", size), |b| {
        b.iter_custom(tokio_ask_current_thread::<N>)
    });
    group.bench_function(BenchmarkId::new("kameo_ask", size), |b| {
        b.iter_custom(kameo_ask_current_thread::<N>)
    });
    group.bench_function(BenchmarkId::new("ractor_call", size), |b| {
        b.iter_custom(ractor_call_current_thread::<N>)
    });
    group.bench_function(BenchmarkId::new("imrs_one_processor", size), |b| {
        b.iter_custom(|n| imrs_same_thread::<N>(n, None))
    });
    group.bench_function(
        BenchmarkId::new("imrs_one_processor_prioritized", size),
        |b| b.iter_custom(imrs_same_thread_prioritized::<N>),
    );
    group.bench_function(BenchmarkId::new("tokio_join_one_task", size), |b| {
        b.iter_custom(tokio_join_one_task::<N>)
    });
    group.bench_function(BenchmarkId::new("tokio_local_set", size), |b| {
        b.iter_custom(tokio_local_set::<N>)
    });
    group.finish();

    let mut group = c.benchmark_group("rendezvous_cross_thread_cold");
    group.bench_function(BenchmarkId::new("imrs", size), |b| {
        b.iter_custom(|n| imrs_cross_thread::<N>(n, ProcessType::Loose, None))
    });
    group.bench_function(BenchmarkId::new("tokio_ask", size), |b| {
        b.iter_custom(|n| tokio_ask_cross_thread::<N>(n, None))
    });
    group.bench_function(BenchmarkId::new("kameo_ask", size), |b| {
        b.iter_custom(kameo_ask_cross_thread::<N>)
    });
    group.bench_function(BenchmarkId::new("ractor_call", size), |b| {
        b.iter_custom(ractor_call_cross_thread::<N>)
    });
    group.bench_function(BenchmarkId::new("crossbeam_ping_pong", size), |b| {
        b.iter_custom(crossbeam_ping_pong::<N>)
    });
    group.finish();

    let mut group = c.benchmark_group("rendezvous_tight");
    group.bench_function(BenchmarkId::new("imrs", size), |b| {
        b.iter_custom(|n| imrs_cross_thread::<N>(n, ProcessType::Tight, None))
    });
    group.bench_function(BenchmarkId::new("atomic_spin_ping_pong", size), |b| {
        b.iter_custom(|n| atomic_spin_ping_pong(n, None))
    });
    group.bench_function(
        BenchmarkId::new("atomic_spin_ping_pong_payload", size),
        |b| b.iter_custom(atomic_spin_ping_pong_payload::<N>),
    );
    group.finish();
}

/// A round-trip driver: `n` round trips, each timed into the tail when one is given.
type TimedRun = fn(u64, Option<&mut Tail>) -> Duration;

/// p50, p99 and p99.9 of single round trips: robot cells care about the worst case.
fn tails() {
    let count = if benchmarking() { 20_000 } else { 50 };
    let cases: [(&str, TimedRun); 6] = [
        ("rendezvous_same_thread/imrs_one_processor/8B", |n, t| {
            imrs_same_thread::<8>(n, t)
        }),
        ("rendezvous_same_thread/imrs_two_tasks/8B", |n, t| {
            imrs_same_thread_tasks::<8>(n, t)
        }),
        ("rendezvous_cross_thread_cold/imrs/8B", |n, t| {
            imrs_cross_thread::<8>(n, ProcessType::Loose, t)
        }),
        ("rendezvous_cross_thread_cold/tokio_ask/8B", |n, t| {
            tokio_ask_cross_thread::<8>(n, t)
        }),
        ("rendezvous_tight/imrs/8B", |n, t| {
            imrs_cross_thread::<8>(n, ProcessType::Tight, t)
        }),
        (
            "rendezvous_tight/atomic_spin_ping_pong/8B",
            atomic_spin_ping_pong,
        ),
    ];
    for (case, run) in cases {
        let mut tail = Tail::with_capacity(count);
        run(count as u64, Some(&mut tail));
        tail.report(case);
    }
}

fn rendezvous(c: &mut Criterion) {
    sizes::<8>(c, "8B");
    sizes::<1024>(c, "1KiB");
    tails();
}

criterion_group! {
    name = benches;
    config = config::primitive();
    targets = rendezvous
}
criterion_main!(benches);
