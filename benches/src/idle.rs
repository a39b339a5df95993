//! Idle modules and idle tokio tasks, for the measure of memory per module.

use std::sync::Arc;
use std::time::{Duration, Instant};

use imrs_core::prelude::*;
use imrs_ports::RealClock;

/// The process's resident memory, in bytes, from `/proc/self/statm`; `None` where there is
/// no such file.
pub fn resident_bytes() -> Option<usize> {
    let statm = std::fs::read_to_string("/proc/self/statm").ok()?;
    let pages: usize = statm.split_whitespace().nth(1)?.parse().ok()?;
    // Every Linux this runs on in CI uses 4 KiB pages.
    Some(pages * 4096)
}

/// What keeps idle modules alive: their cell, handles and ports.
pub type IdleModules = (Cell, Vec<ModuleHandle>, Vec<Port<u64, u64, usage::Receive>>);

/// Starts `count` modules, each owning a port and waiting in `ctx.receive` on it; returns
/// them, once every one is waiting, and the time it took.
pub async fn idle_modules(count: usize) -> (IdleModules, Duration) {
    let cell = Cell::new(Arc::new(RealClock::new()));
    cell.events().set_capacity(1_024);
    let start = Instant::now();
    let mut ports = Vec::with_capacity(count);
    let mut handles = Vec::with_capacity(count);
    for i in 0..count {
        let port = Port::<u64, u64, usage::Receive>::new(PortSpec::new(
            format!("IDLE{i}"),
            format!("M{i}"),
        ));
        let own = port.clone();
        let spec = ModuleSpec::new(format!("M{i}"), ()).task(format!("M{i}"), move |ctx| {
            let owner = ctx.owner(&own);
            async move {
                let mut own = owner?;
                loop {
                    let (message, reply) = ctx.receive(&mut own).await?;
                    reply.reply(message);
                }
            }
        });
        handles.push(cell.start(spec).expect("module names are unique"));
        ports.push(port);
    }
    // The last module answers only once it waits in its receive, and modules start in the
    // order they were spawned: then every one is parked there.
    let last = ports.last().expect("at least one module");
    let mut asker = last.user_named("ASKER").expect("the last port has room");
    assert_eq!(asker.send(7).await.expect("the last module answers"), 7);
    drop(asker);
    let started = start.elapsed();
    ((cell, handles, ports), started)
}

/// What keeps idle tokio tasks alive: the senders of their channels.
pub type IdleTasks = Vec<tokio::sync::mpsc::Sender<(u64, tokio::sync::oneshot::Sender<u64>)>>;

/// The same count of tokio tasks, each waiting on an mpsc receiver for asks.
pub async fn idle_tokio_tasks(count: usize) -> (IdleTasks, Duration) {
    let start = Instant::now();
    let mut senders = Vec::with_capacity(count);
    for _ in 0..count {
        let (asks, mut inbox) =
            tokio::sync::mpsc::channel::<(u64, tokio::sync::oneshot::Sender<u64>)>(1);
        tokio::spawn(async move {
            while let Some((message, reply)) = inbox.recv().await {
                let _ = reply.send(message);
            }
        });
        senders.push(asks);
    }
    let (reply, answer) = tokio::sync::oneshot::channel();
    let last = senders.last().expect("at least one task");
    last.send((7, reply)).await.expect("the last task listens");
    assert_eq!(answer.await.expect("the last task answers"), 7);
    (senders, start.elapsed())
}
