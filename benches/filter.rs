//! Non-blocking sends through the bounded-buffer filter: messages per second, with the owner
//! draining the buffer as GATE does; a tokio bounded mpsc of the same depth as baseline.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use imrs_benches::current_thread;
use imrs_ports::{AnyUser, BoundedBuffer, BoundedBufferPort, PortSpec};

type Frequency = BoundedBufferPort<(i32, f64), AnyUser, 1>;

fn through_filter(iters: u64) -> Duration {
    current_thread().block_on(async move {
        let port = Frequency::declare(PortSpec::new("FREQUENCY", "GATE"), "BOUNDED_BUFFER");
        let mut gate = port.owner().unwrap();
        let mut user = port.user_named("LOAD_IT").unwrap();
        let filter =
            tokio::spawn(BoundedBuffer::<(i32, f64), 20>::new().run(port.filter().unwrap()));
        let start = Instant::now();
        for n in 0..iters {
            user.send(black_box((0, n as f64))).await.unwrap();
            if n % 16 == 15 {
                while gate.send(()).await.unwrap().is_some() {}
            }
        }
        let elapsed = start.elapsed();
        filter.abort();
        elapsed
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
    group.bench_function("bounded_buffer", |b| b.iter_custom(through_filter));
    group.bench_function("tokio_mpsc", |b| b.iter_custom(through_mpsc));
    group.finish();
}

criterion_group! {
    name = filter_benches;
    config = Criterion::default()
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2))
        .sample_size(20);
    targets = benches
}
criterion_main!(filter_benches);
