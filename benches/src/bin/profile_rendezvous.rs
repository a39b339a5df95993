//! Same-thread round trips in a loop, for a profiler (`valgrind --tool=callgrind`), so that
//! the ratio table's figures can be traced to where the time goes. Both ends run on one
//! processor, as in `rendezvous_same_thread/imrs_one_processor`; with `query`, the round
//! trips are queries into a response handler of an idle module, as in
//! `query/responder_idle`; with `ctx`, two modules talking through `ctx.send` and
//! `ctx.receive`, as in `ctx_same_thread/ctx`; with `ring`, hops around a ring of 1 000
//! modules on one thread, as in `ring_1000/imrs/1_threads`; with `prioritized` and
//! `unprioritized`, the round trips of `rendezvous_same_thread/imrs_one_processor_prioritized`
//! and of the same without priorities; with `tight`, TIGHT round trips across two threads,
//! as in `rendezvous_tight/imrs`, for `perf record` (their cost is in the cache lines that
//! cross between cores, which callgrind does not see).
//!
//! ```text
//! cargo build --release -p imrs-benches --bin profile_rendezvous
//! valgrind --tool=callgrind target/release/profile_rendezvous 100000 [query|ctx|ring|prioritized|unprioritized]
//! perf record -g target/release/profile_rendezvous 2000000 tight
//! ```

use std::hint::black_box;

use imrs_benches::current_thread;
use imrs_benches::rendezvous::{imrs_cross_thread, imrs_on_processor};
use imrs_core::prelude::*;
use imrs_ports::{ProcessType, RealClock};

fn main() {
    let round_trips: u64 = std::env::args()
        .nth(1)
        .and_then(|n| n.parse().ok())
        .unwrap_or(100_000);
    let mode = std::env::args().nth(2);
    if mode.as_deref() == Some("query") {
        queries(round_trips);
    } else if mode.as_deref() == Some("ring") {
        black_box(imrs_benches::imrs_ring(1_000, round_trips, 1));
    } else if mode.as_deref() == Some("ctx") {
        black_box(imrs_benches::ctx_on_processor(round_trips));
    } else if let Some(prioritized @ ("prioritized" | "unprioritized")) = mode.as_deref() {
        let on = prioritized == "prioritized";
        black_box(imrs_on_processor::<8>(round_trips, None, on));
    } else if mode.as_deref() == Some("tight") {
        black_box(imrs_cross_thread::<8>(
            round_trips,
            ProcessType::Tight,
            None,
        ));
    } else {
        rendezvous(round_trips);
    }
}

fn queries(round_trips: u64) {
    current_thread().block_on(async move {
        let cell = Cell::new(std::sync::Arc::new(RealClock::new()));
        let processor = Processor::new("CPU1");
        let port: Port<u64, u64, usage::Query> = cell
            .port(PortSpec::new("STATUS", "ASKER"))
            .expect("a new cell has no STATUS");
        let responder = ModuleSpec::new("ROBOT", 7u64)
            .order(["STATUS.STATE", "ROBOT"])
            .respond(&port.handler("STATE"), |s: &u64, q: u64| s + q)
            .task("ROBOT", |_ctx| std::future::pending());
        let robot = cell.start_on(&processor, responder).unwrap();
        let mut asker = port.owner().expect("a new port has no owner yet");
        processor
            .spawn(async move {
                for n in 0..round_trips {
                    black_box(asker.query(black_box(n)).await.expect("the robot answers"));
                }
            })
            .await
            .expect("the asker finishes");
        robot.stop();
    });
}

fn rendezvous(round_trips: u64) {
    current_thread().block_on(async move {
        let processor = Processor::new("CPU1");
        let port = Port::<[u8; 8], u64, usage::Receive>::new(PortSpec::new("P", "SERVER"));
        let mut server = port.owner().expect("a new port has no owner yet");
        let mut client = port
            .user_named("CLIENT")
            .expect("a new port has room for a user");
        let serving = processor.spawn(async move {
            for _ in 0..round_trips {
                let (message, reply) = server.receive().await.expect("the client sends");
                reply.reply(u64::from(message[0]));
            }
        });
        let sending = processor.spawn(async move {
            for _ in 0..round_trips {
                black_box(
                    client
                        .send(black_box([1u8; 8]))
                        .await
                        .expect("the server replies"),
                );
            }
        });
        sending.await.expect("the client finishes");
        serving.await.expect("the server finishes");
    });
}
