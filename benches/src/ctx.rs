//! Two modules that talk through `ctx`, for the benches and profiles of the path modules use.

use std::hint::black_box;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use imrs_core::prelude::*;
use imrs_ports::RealClock;

use crate::current_thread;

/// Where the client module leaves its timing.
pub type Timed = Arc<Mutex<Duration>>;

/// A bench cell's log keeps this many events: full after the first round trips, as in a long run.
pub const KEPT: usize = 4_096;

/// SERVER receives and replies `iters` times; CLIENT sends `iters` times and times it.
pub fn ctx_modules(cell: &Cell, iters: u64, timed: &Timed) -> (ModuleSpec<()>, ModuleSpec<()>) {
    let feed: Port<[u8; 8], u64, usage::Receive> =
        cell.port(PortSpec::new("FEED", "SERVER")).unwrap();
    let port = feed.clone();
    let server = ModuleSpec::new("SERVER", ()).task("SERVER", move |ctx| {
        let owner = ctx.owner(&port);
        async move {
            let mut feed = owner?;
            for _ in 0..iters {
                let (message, reply) = ctx.receive(&mut feed).await?;
                reply.reply(u64::from(message[0]));
            }
            Ok(())
        }
    });
    let (port, timed) = (feed.clone(), Arc::clone(timed));
    let client = ModuleSpec::new("CLIENT", ())
        .uses(&feed)
        .task("CLIENT", move |ctx| {
            let (user, timed) = (ctx.user(&port), Arc::clone(&timed));
            async move {
                let mut feed = user?;
                let start = Instant::now();
                for _ in 0..iters {
                    black_box(ctx.send(&mut feed, black_box([1u8; 8])).await?);
                }
                *timed.lock().unwrap() = start.elapsed();
                Ok(())
            }
        });
    (server, client)
}

/// A cell on the wall clock whose log keeps [`KEPT`] events.
pub fn new_cell() -> Cell {
    let cell = Cell::new(Arc::new(RealClock::new()));
    cell.events().set_capacity(KEPT);
    cell
}

/// Two modules on one processor, talking through `ctx`.
pub fn ctx_on_processor(iters: u64) -> Duration {
    current_thread().block_on(async move {
        let cell = new_cell();
        let timed = Timed::default();
        let (server, client) = ctx_modules(&cell, iters, &timed);
        let processor = Processor::new("CPU1");
        let mut server = cell.start_on(&processor, server).unwrap();
        let mut client = cell.start_on(&processor, client).unwrap();
        assert_eq!(client.finished().await, ModuleOutcome::Finished);
        assert_eq!(server.finished().await, ModuleOutcome::Finished);
        *timed.lock().unwrap()
    })
}
