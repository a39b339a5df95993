//! A query into a response handler through the order scheduler, with the responder idle and
//! with the responder in a lower-ranked section at a suspension point; the same-thread
//! send/receive/reply round trip as baseline. Both ends of each run on one processor.

#[path = "config.rs"]
mod config;

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use imrs_benches::current_thread;
use imrs_core::prelude::*;
use imrs_ports::RealClock;

/// `iters` queries of a module whose task is `busy` (in INSERT, yielding at every turn) or
/// idle (parked in its background code).
fn query(iters: u64, busy: bool) -> Duration {
    current_thread().block_on(async move {
        let cell = Cell::new(std::sync::Arc::new(RealClock::new()));
        let port: Port<u64, u64, usage::Query> =
            cell.port(PortSpec::new("STATUS", "ASKER")).unwrap();
        let responder = ModuleSpec::new("ROBOT", 7u64)
            // The handler outranks the background (idle: parked there) and INSERT (busy).
            .order(["STATUS.STATE", "ROBOT", "INSERT"])
            .respond(&port.handler("STATE"), |s: &u64, q: u64| s + q)
            .task("ROBOT", move |ctx| async move {
                if busy {
                    // In INSERT, ranked below the handler: each suspension point admits it.
                    ctx.section(&Section::new("INSERT"), async {
                        loop {
                            tokio::task::yield_now().await;
                        }
                    })
                    .await;
                }
                std::future::pending::<()>().await;
                Ok(())
            });
        // Asker and responder on one processor, as the same-thread rendezvous below.
        let processor = Processor::new("CPU1");
        let robot = cell.start_on(&processor, responder).unwrap();
        let mut asker = port.owner().unwrap();
        let asking = processor.spawn(async move {
            let start = Instant::now();
            for n in 0..iters {
                black_box(asker.query(black_box(n)).await.unwrap());
            }
            start.elapsed()
        });
        let timed = asking.await.unwrap();
        robot.stop();
        timed
    })
}

/// The same-thread rendezvous, for the ratio.
fn rendezvous(iters: u64) -> Duration {
    current_thread().block_on(async move {
        let port = Port::<u64, u64, usage::Receive>::new(PortSpec::new("P", "SERVER"));
        let mut server = port.owner().unwrap();
        let mut client = port.user_named("CLIENT").unwrap();
        let processor = Processor::new("CPU1");
        let serving = processor.spawn(async move {
            for _ in 0..iters {
                let (n, reply) = server.receive().await.unwrap();
                reply.reply(n + 7);
            }
        });
        let sending = processor.spawn(async move {
            let start = Instant::now();
            for n in 0..iters {
                black_box(client.send(black_box(n)).await.unwrap());
            }
            start.elapsed()
        });
        let timed = sending.await.unwrap();
        serving.await.unwrap();
        timed
    })
}

fn benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("query");
    group.bench_function("responder_idle", |b| b.iter_custom(|n| query(n, false)));
    group.bench_function("responder_in_lower_section", |b| {
        b.iter_custom(|n| query(n, true))
    });
    group.bench_function("same_thread_rendezvous", |b| b.iter_custom(rendezvous));
    group.finish();
}

criterion_group! {
    name = query_benches;
    config = config::primitive();
    targets = benches
}
criterion_main!(query_benches);
