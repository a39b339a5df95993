//! The path modules use — `ctx.send`, `ctx.receive`, `ctx.query` — allocates nothing per
//! operation in steady state, with the event log and the deadlock diagnosis on (and the
//! cell not observing, as by default: then a primitive that succeeds is not logged).

// The counting allocator of imrs-ports' own no-allocation test.
#[path = "../../imrs-ports/tests/support/counting_alloc.rs"]
mod counting_alloc;

use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use counting_alloc::allocations;
use imrs_core::prelude::*;
use imrs_ports::RealClock;

const WARM_UP: u32 = 2_000;
const MEASURED: u32 = 1_000;
/// A log that keeps this many events is full after the warm-up: from then on it forgets the
/// oldest as it records the newest, which allocates nothing. (While a log fills up to its
/// capacity it grows by doubling: a few allocations in all, none per operation.)
const KEPT: usize = 1_024;

/// Two modules on one processor: CLIENT sends (or queries) `WARM_UP + MEASURED` times,
/// SERVER receives and replies for as long as the cell runs (or answers in a response handler). Returns the allocations
/// of the measured operations, counted on the one thread that runs them all.
fn allocations_per_ctx_round_trips(query: bool) -> usize {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    runtime.block_on(async move {
        let cell = Cell::new(Arc::new(RealClock::new()));
        cell.events().set_capacity(KEPT);
        let processor = Processor::new("CPU1");
        let measured = Arc::new(AtomicUsize::new(usize::MAX));

        let client = if query {
            // CLIENT owns the query port; SERVER, its user, answers in a response handler.
            let status: Port<u8, u64, usage::Query> =
                cell.port(PortSpec::new("STATUS", "CLIENT")).unwrap();
            let server = ModuleSpec::new("SERVER", 7u64)
                .order([status.handler("STATUS").name(), "SERVER".into()])
                .respond(&status.handler("STATUS"), |state: &u64, ask: u8| {
                    *state + u64::from(ask)
                })
                .task("SERVER", |ctx| async move {
                    ctx.delay(std::time::Duration::from_secs(3600)).await;
                    Ok(())
                });
            cell.start_on(&processor, server).unwrap();
            let (port, seen) = (status.clone(), Arc::clone(&measured));
            ModuleSpec::new("CLIENT", ()).task("CLIENT", move |ctx| {
                let (owner, seen) = (ctx.owner(&port), Arc::clone(&seen));
                async move {
                    let mut status = owner?;
                    for n in 0..WARM_UP {
                        assert_eq!(
                            ctx.query(&mut status, n as u8).await?,
                            7 + u64::from(n as u8)
                        );
                    }
                    let before = allocations();
                    for n in 0..MEASURED {
                        assert_eq!(
                            ctx.query(&mut status, n as u8).await?,
                            7 + u64::from(n as u8)
                        );
                    }
                    seen.store(allocations() - before, Ordering::SeqCst);
                    Ok(())
                }
            })
        } else {
            let feed: Port<[u8; 64], u64, usage::Receive> =
                cell.port(PortSpec::new("FEED", "SERVER")).unwrap();
            let port = feed.clone();
            let server = ModuleSpec::new("SERVER", ()).task("SERVER", move |ctx| {
                let owner = ctx.owner(&port);
                async move {
                    let mut feed = owner?;
                    // Serves for as long as the cell runs: a module that ends allocates
                    // as it winds down, and that is no cost of an operation.
                    loop {
                        let (message, reply) = ctx.receive(&mut feed).await?;
                        reply.reply(u64::from(message[0]));
                    }
                }
            });
            cell.start_on(&processor, server).unwrap();
            let (port, seen) = (feed.clone(), Arc::clone(&measured));
            ModuleSpec::new("CLIENT", ())
                .uses(&feed)
                .task("CLIENT", move |ctx| {
                    let (user, seen) = (ctx.user(&port), Arc::clone(&seen));
                    async move {
                        let mut feed = user?;
                        for n in 0..WARM_UP {
                            assert_eq!(
                                ctx.send(&mut feed, [n as u8; 64]).await?,
                                u64::from(n as u8)
                            );
                        }
                        let before = allocations();
                        for n in 0..MEASURED {
                            assert_eq!(
                                ctx.send(&mut feed, [n as u8; 64]).await?,
                                u64::from(n as u8)
                            );
                        }
                        seen.store(allocations() - before, Ordering::SeqCst);
                        Ok(())
                    }
                })
        };
        let mut client = cell.start_on(&processor, client).unwrap();
        assert_eq!(client.finished().await, ModuleOutcome::Finished);
        // The log was on, and kept the modules' life; a primitive that succeeds is logged
        // only while the cell observes.
        let events = cell.events().snapshot();
        assert!(
            events
                .iter()
                .any(|event| matches!(event.kind, EventKind::TaskStarted))
        );
        assert!(!events.iter().any(|event| matches!(
            event.kind,
            EventKind::Sent { .. }
                | EventKind::Received { .. }
                | EventKind::Queried { .. }
                | EventKind::Responded { .. }
        )));
        measured.load(Ordering::SeqCst)
    })
}

#[test]
fn ctx_send_and_receive_in_steady_state_allocate_nothing() {
    assert_eq!(
        allocations_per_ctx_round_trips(false),
        0,
        "allocations in {MEASURED} ctx round trips"
    );
}

#[test]
fn ctx_query_into_a_response_handler_in_steady_state_allocates_nothing() {
    assert_eq!(
        allocations_per_ctx_round_trips(true),
        0,
        "allocations in {MEASURED} ctx queries"
    );
}
