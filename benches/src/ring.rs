//! A ring of modules passing a token, for the ring bench and its profile.

use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use imrs_core::prelude::*;
use imrs_ports::RealClock;

/// When the token was first sent, and how long its last hop took to land.
#[derive(Default)]
struct Lap {
    start: Option<Instant>,
    timed: Option<Duration>,
}

type Shared = Arc<Mutex<Lap>>;

/// A runtime of `threads` threads: current-thread for one.
pub fn runtime(threads: usize) -> tokio::runtime::Runtime {
    if threads == 1 {
        return crate::current_thread();
    }
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(threads)
        .enable_all()
        .build()
        .expect("a runtime starts")
}

/// Module `i` of a ring of `size`: receives the token on its own port, answers, and passes it
/// on to module `i + 1`, until `hops` hops are made. Module 0 sends the token first.
fn ring_module(
    i: usize,
    ports: &[Port<u64, (), usage::Receive>],
    hops: u64,
    lap: &Shared,
) -> ModuleSpec<()> {
    let (own, next) = (ports[i].clone(), ports[(i + 1) % ports.len()].clone());
    let lap = Arc::clone(lap);
    ModuleSpec::new(format!("M{i}"), ())
        .uses(&next)
        .task(format!("M{i}"), move |ctx| {
            let (owner, user, lap) = (ctx.owner(&own), ctx.user(&next), Arc::clone(&lap));
            async move {
                let (mut own, mut next) = (owner?, user?);
                if i == 0 {
                    lap.lock().unwrap().start = Some(Instant::now());
                    ctx.send(&mut next, 1).await?;
                }
                loop {
                    let (token, reply) = ctx.receive(&mut own).await?;
                    reply.reply(());
                    if token == hops {
                        let mut lap = lap.lock().unwrap();
                        lap.timed = lap.start.map(|start| start.elapsed());
                        return Ok(());
                    }
                    ctx.send(&mut next, token + 1).await?;
                }
            }
        })
}

/// `hops` hops around a ring of `size` modules on a runtime of `threads` threads.
pub fn imrs_ring(size: usize, hops: u64, threads: usize) -> Duration {
    let lap = Shared::default();
    let runtime = runtime(threads);
    runtime.block_on(async {
        let cell = Cell::new(Arc::new(RealClock::new()));
        // The ring's events stream to no one; keep few, as a long-running cell would.
        cell.events().set_capacity(1_024);
        let ports: Vec<Port<u64, (), usage::Receive>> = (0..size)
            .map(|i| {
                cell.port(PortSpec::new(format!("P{i}"), format!("M{i}")))
                    .unwrap()
            })
            .collect();
        let mut handles = Vec::with_capacity(size);
        // Module 0 last, so that every other is listening when the token starts.
        for i in (0..size).rev() {
            handles.push(cell.start(ring_module(i, &ports, hops, &lap)).unwrap());
        }
        let last = (hops % size as u64) as usize;
        let mut finisher = handles.swap_remove(size - 1 - last);
        finisher.finished().await;
    });
    // Dropping the runtime drops the modules still waiting for a token.
    drop(runtime);
    let lap = lap.lock().unwrap();
    lap.timed.expect("the last hop landed")
}
