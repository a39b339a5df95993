//! In steady state a rendezvous allocates nothing: counted by a global allocator.

use std::time::Duration;

use imrs_ports::{Port, PortSpec, usage};

// Shared with imrs-core's processor test, which counts the same way.
#[path = "support/counting_alloc.rs"]
mod counting_alloc;

use counting_alloc::allocations;

/// Round trips between two tasks on one thread: `warm_up` first, then `measured`, counting
/// the allocations of the measured ones alone.
fn allocations_per_round_trips(
    spec: PortSpec,
    user_timeout: Option<Duration>,
    warm_up: u32,
    measured: u32,
) -> usize {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    runtime.block_on(async move {
        let port = Port::<[u8; 64], u64, usage::Receive>::new(spec);
        let mut owner = port.owner().unwrap();
        let mut user = port.user_named("USER").unwrap();
        if let Some(timeout) = user_timeout {
            user = user.with_timeout(timeout);
        }
        let total = warm_up + measured;
        let server = tokio::spawn(async move {
            for _ in 0..total {
                let (message, reply) = owner.receive().await.unwrap();
                reply.reply(u64::from(message[0]));
            }
        });
        for n in 0..warm_up {
            assert_eq!(user.send([n as u8; 64]).await.unwrap(), u64::from(n as u8));
        }
        let before = allocations();
        for n in 0..measured {
            assert_eq!(user.send([n as u8; 64]).await.unwrap(), u64::from(n as u8));
        }
        let after = allocations();
        server.await.unwrap();
        after - before
    })
}

#[test]
fn a_rendezvous_in_steady_state_allocates_nothing() {
    let allocated = allocations_per_round_trips(PortSpec::new("P", "OWNER"), None, 100, 1_000);
    assert_eq!(allocated, 0, "allocations in 1000 round trips");
}

#[test]
fn a_timed_rendezvous_on_the_real_clock_allocates_nothing() {
    // Timeouts on both ends. They never fire (the round trips complete at once); their
    // timers live inline in the send and receive futures.
    let hour = Duration::from_secs(3600);
    let spec = PortSpec::new("P", "OWNER").owner_timeout(hour);
    let allocated = allocations_per_round_trips(spec, Some(hour), 100, 1_000);
    assert_eq!(allocated, 0, "allocations in 1000 timed round trips");
}
