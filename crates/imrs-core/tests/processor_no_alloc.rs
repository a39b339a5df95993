//! Two ends of a rendezvous on one processor allocate nothing per round trip: a processor
//! allocates when a job is placed on it, never when one job wakes another.

// The counting allocator of imrs-ports' own no-allocation test.
#[path = "../../imrs-ports/tests/support/counting_alloc.rs"]
mod counting_alloc;

use counting_alloc::allocations;
use imrs_core::Processor;
use imrs_ports::{Port, PortSpec, usage};

#[test]
fn a_rendezvous_on_one_processor_in_steady_state_allocates_nothing() {
    // Long enough for the processor to have yielded to the runtime on its turn budget: the
    // first such yield costs one allocation (with 100 warm-up round trips the measured ones
    // saw exactly one, whether 1 000 or 10 000 of them), none after.
    const WARM_UP: u32 = 1_000;
    const MEASURED: u32 = 1_000;
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    let allocated = runtime.block_on(async {
        let processor = Processor::new("CPU1");
        let port = Port::<[u8; 64], u64, usage::Receive>::new(PortSpec::new("P", "OWNER"));
        let mut owner = port.owner().unwrap();
        let mut user = port.user_named("USER").unwrap();
        let serving = processor.spawn(async move {
            for _ in 0..WARM_UP + MEASURED {
                let (message, reply) = owner.receive().await.unwrap();
                reply.reply(u64::from(message[0]));
            }
        });
        // Counted inside the job: the counter is per thread, and a current-thread runtime
        // polls the processor's task on this one.
        let sending = processor.spawn(async move {
            for n in 0..WARM_UP {
                assert_eq!(user.send([n as u8; 64]).await.unwrap(), u64::from(n as u8));
            }
            let before = allocations();
            for n in 0..MEASURED {
                assert_eq!(user.send([n as u8; 64]).await.unwrap(), u64::from(n as u8));
            }
            allocations() - before
        });
        let allocated = sending.await.unwrap();
        serving.await.unwrap();
        allocated
    });
    assert_eq!(allocated, 0, "allocations in {MEASURED} round trips");
}
