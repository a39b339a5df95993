//! Same-thread round trips in a loop, for a profiler (`valgrind --tool=callgrind`), so that
//! the ratio table's figures can be traced to where the time goes. Both ends run on one
//! processor, as in `rendezvous_same_thread/imrs`.
//!
//! ```text
//! cargo build --release -p imrs-benches --bin profile_rendezvous
//! valgrind --tool=callgrind target/release/profile_rendezvous 100000
//! ```

use std::hint::black_box;

use imrs_benches::current_thread;
use imrs_core::Processor;
use imrs_ports::{Port, PortSpec, usage};

fn main() {
    let round_trips: u64 = std::env::args()
        .nth(1)
        .and_then(|n| n.parse().ok())
        .unwrap_or(100_000);
    current_thread().block_on(async move {
        let processor = Processor::new("CPU1");
        let port = Port::<[u8; 8], u64, usage::Receive>::declare(PortSpec::new("P", "SERVER"));
        let mut server = port.owner().expect("a new port has no owner yet");
        let mut client = port
            .user_named("CLIENT")
            .expect("a new port has room for a user");
        processor.spawn(async move {
            for _ in 0..round_trips {
                let (message, reply) = server.receive().await.expect("the client sends");
                reply.reply(u64::from(message[0]));
            }
        });
        let (done, finished) = tokio::sync::oneshot::channel();
        processor.spawn(async move {
            for _ in 0..round_trips {
                black_box(
                    client
                        .send(black_box([1u8; 8]))
                        .await
                        .expect("the server replies"),
                );
            }
            let _ = done.send(());
        });
        finished.await.expect("the client finishes");
    });
}
