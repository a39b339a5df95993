//! The path modules use: a `ctx.send` → `ctx.receive` → `reply` round trip between two
//! modules, with the event log and the deadlock diagnosis on, beside the raw `End` round
//! trip in the same group: on one processor, and as tasks of a two-worker runtime.

#[path = "config.rs"]
mod config;

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use imrs_benches::{Timed, ctx_modules, ctx_on_processor, current_thread, new_cell, runtime};
use imrs_core::prelude::*;

/// Two modules, each a task of its own on a two-worker runtime, talking through `ctx`.
fn ctx_multi_thread(iters: u64) -> Duration {
    runtime(2).block_on(async move {
        let cell = new_cell();
        let timed = Timed::default();
        let (server, client) = ctx_modules(&cell, iters, &timed);
        let mut server = cell.start(server).unwrap();
        let mut client = cell.start(client).unwrap();
        assert_eq!(client.finished().await, ModuleOutcome::Finished);
        assert_eq!(server.finished().await, ModuleOutcome::Finished);
        *timed.lock().unwrap()
    })
}

/// The raw `End` round trip: two futures that hold the ends themselves.
fn raw_ends(iters: u64) -> (impl Future<Output = ()>, impl Future<Output = Duration>) {
    let feed = Port::<[u8; 8], u64, usage::Receive>::new(PortSpec::new("FEED", "SERVER"));
    let mut server = feed.owner().unwrap();
    let mut client = feed.user_named("CLIENT").unwrap();
    let serving = async move {
        for _ in 0..iters {
            let (message, reply) = server.receive().await.unwrap();
            reply.reply(u64::from(message[0]));
        }
    };
    let sending = async move {
        let start = Instant::now();
        for _ in 0..iters {
            black_box(client.send(black_box([1u8; 8])).await.unwrap());
        }
        start.elapsed()
    };
    (serving, sending)
}

fn raw_on_processor(iters: u64) -> Duration {
    current_thread().block_on(async move {
        let processor = Processor::new("CPU1");
        let (serving, sending) = raw_ends(iters);
        let serving = processor.spawn(serving);
        let timed = processor.spawn(sending).await.unwrap();
        serving.await.unwrap();
        timed
    })
}

fn raw_multi_thread(iters: u64) -> Duration {
    runtime(2).block_on(async move {
        let (serving, sending) = raw_ends(iters);
        let serving = tokio::spawn(serving);
        let timed = tokio::spawn(sending).await.unwrap();
        serving.await.unwrap();
        timed
    })
}

fn ctx(c: &mut Criterion) {
    let mut group = c.benchmark_group("ctx_same_thread");
    group.bench_function("ctx", |b| b.iter_custom(ctx_on_processor));
    group.bench_function("raw_end", |b| b.iter_custom(raw_on_processor));
    group.finish();
    let mut group = c.benchmark_group("ctx_multi_thread");
    group.bench_function("ctx", |b| b.iter_custom(ctx_multi_thread));
    group.bench_function("raw_end", |b| b.iter_custom(raw_multi_thread));
    group.finish();
}

criterion_group! {
    name = benches;
    config = config::primitive();
    targets = ctx
}
criterion_main!(benches);
