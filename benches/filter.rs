//! Non-blocking sends through the bounded-buffer filter: messages per second, with the owner
//! draining the buffer as GATE does; the filter as a tokio task of its own and as a job on
//! one processor with its two peers; a tokio bounded mpsc of the same depth as baseline.
//! A filter is a task between two rendezvous: every message costs a rendezvous in and,
//! drained, one out, where the mpsc costs a queue write and read in one task.

#[path = "config.rs"]
mod config;

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use imrs_benches::current_thread;
use imrs_core::Processor;
use imrs_ports::{AnyUser, BoundedBuffer, BoundedBufferPort, PortSpec};

type Frequency = BoundedBufferPort<(i32, f64), AnyUser, 1>;

/// The user sends `iters` messages through the filter, and the owner drains the buffer
/// every 16: the filter a tokio task of its own, or (`processor`) a job on one processor with
/// the user and the owner, as modules that talk at every message would be placed.
fn through_filter(iters: u64, processor: bool) -> Duration {
    current_thread().block_on(async move {
        let port = Frequency::new(PortSpec::new("FREQUENCY", "GATE"), "BOUNDED_BUFFER");
        let mut gate = port.owner().unwrap();
        let mut user = port.user_named("LOAD_IT").unwrap();
        let filter = BoundedBuffer::<(i32, f64), 20>::new().run(port.filter().unwrap());
        let traffic = async move {
            let start = Instant::now();
            for n in 0..iters {
                user.send(black_box((0, n as f64))).await.unwrap();
                if n % 16 == 15 {
                    while gate.send(()).await.unwrap().is_some() {}
                }
            }
            start.elapsed()
        };
        if processor {
            let cpu = Processor::new("CPU1");
            // Dropped with the runtime once the traffic is timed.
            drop(cpu.spawn(filter));
            cpu.spawn(traffic).await.unwrap()
        } else {
            let filter = tokio::spawn(filter);
            let elapsed = traffic.await;
            filter.abort();
            elapsed
        }
    })
}

fn through_mpsc(iters: u64) -> Duration {
    current_thread().block_on(async move {
        let (sender, mut receiver) = tokio::sync::mpsc::channel::<(i32, f64)>(20);
        let start = Instant::now();
        for n in 0..iters {
            sender.send(black_box((0, n as f64))).await.unwrap();
            if n % 16 == 15 {
                while receiver.try_recv().is_ok() {}
            }
        }
        start.elapsed()
    })
}

fn benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("filter");
    group.throughput(Throughput::Elements(1));
    group.bench_function("bounded_buffer", |b| {
        b.iter_custom(|n| through_filter(n, false))
    });
    group.bench_function("bounded_buffer_on_processor", |b| {
        b.iter_custom(|n| through_filter(n, true))
    });
    group.bench_function("tokio_mpsc", |b| b.iter_custom(through_mpsc));
    group.finish();
}

criterion_group! {
    name = filter_benches;
    config = config::primitive();
    targets = benches
}
criterion_main!(filter_benches);
