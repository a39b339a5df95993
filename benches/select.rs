//! `select` over 8 ports of different priorities, with one ready and with all ready.

#[path = "config.rs"]
mod config;

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use imrs_benches::current_thread;
use imrs_ports::{End, Port, PortSpec, select, usage};

type Inbox = Port<u32, (), usage::Receive>;

/// `iters` selects, each served after `ready` of the 8 ports got a message.
fn selects(iters: u64, ready: usize) -> Duration {
    current_thread().block_on(async move {
        let ports: Vec<Inbox> = (0..8u32)
            .map(|n| Inbox::new(PortSpec::new(format!("P{n}"), "OWNER").priority(n + 1)))
            .collect();
        let mut owners: Vec<End<u32, (), usage::Receive>> =
            ports.iter().map(|p| p.owner().unwrap()).collect();
        let mut users: Vec<End<u32, (), usage::Send>> = ports
            .iter()
            .map(|p| p.user_named("USER").unwrap())
            .collect();
        let mut elapsed = Duration::ZERO;
        for _ in 0..iters {
            // Post `ready` sends (the lowest-priority ports first), then time the select.
            let mut sends: Vec<_> = users
                .iter_mut()
                .rev()
                .take(ready)
                .map(|user| Box::pin(user.send(1)))
                .collect();
            let mut cx = std::task::Context::from_waker(std::task::Waker::noop());
            for send in &mut sends {
                assert!(send.as_mut().poll(&mut cx).is_pending());
            }
            let [a, b, c, d, e, f, g, h] = &mut owners[..] else {
                unreachable!()
            };
            let start = Instant::now();
            let served = select()
                .or(&mut *a, |(m, r)| (m, r))
                .or(&mut *b, |(m, r)| (m, r))
                .or(&mut *c, |(m, r)| (m, r))
                .or(&mut *d, |(m, r)| (m, r))
                .or(&mut *e, |(m, r)| (m, r))
                .or(&mut *f, |(m, r)| (m, r))
                .or(&mut *g, |(m, r)| (m, r))
                .or(&mut *h, |(m, r)| (m, r))
                .await
                .unwrap();
            elapsed += start.elapsed();
            black_box(served.0);
            served.1.reply(());
            // Drain the others so the next round starts empty.
            drop(sends);
        }
        elapsed
    })
}

fn benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("select");
    group.bench_function("8_ports_one_ready", |b| b.iter_custom(|n| selects(n, 1)));
    group.bench_function("8_ports_all_ready", |b| b.iter_custom(|n| selects(n, 8)));
    group.finish();
}

criterion_group! {
    name = select_benches;
    config = config::primitive();
    targets = benches
}
criterion_main!(select_benches);
