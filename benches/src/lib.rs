//! Helpers shared by the benchmarks: runtimes, round-trip drivers, and tail-latency records.
//!
//! Every figure is meant to be read as a ratio to a baseline measured in the same process and
//! the same run (`cargo run -p imrs-benches --bin ratio_table` prints the table).

pub mod peers;
pub mod rendezvous;

use std::hint::black_box;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use imrs_core::prelude::*;
use imrs_ports::RealClock;

/// A current-thread tokio runtime with timers.
pub fn current_thread() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .expect("a runtime starts")
}

/// Whether criterion runs for real (`cargo bench`) rather than once in test mode.
pub fn benchmarking() -> bool {
    std::env::args().any(|arg| arg == "--bench")
}

/// The directory criterion writes its estimates into (`target/criterion`).
pub fn criterion_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("CARGO_TARGET_DIR") {
        return PathBuf::from(dir).join("criterion");
    }
    let exe = std::env::current_exe().expect("the benchmark knows its path");
    exe.ancestors()
        .find(|dir| dir.file_name().is_some_and(|name| name == "target"))
        .map(|target| target.join("criterion"))
        .unwrap_or_else(|| PathBuf::from("target/criterion"))
}

/// Single round-trip latencies of one case, and their percentiles.
#[derive(Debug, Default)]
pub struct Tail {
    samples: Vec<Duration>,
}

impl Tail {
    /// Room for `count` samples, allocated before timing starts.
    pub fn with_capacity(count: usize) -> Self {
        Self {
            samples: Vec::with_capacity(count),
        }
    }

    /// Times one round trip.
    pub fn time<R>(&mut self, round_trip: impl FnOnce() -> R) -> R {
        let start = Instant::now();
        let result = round_trip();
        self.samples.push(start.elapsed());
        result
    }

    /// Adds a sample timed elsewhere.
    pub fn push(&mut self, sample: Duration) {
        self.samples.push(sample);
    }

    /// Adds the samples of `other`, e.g. timed inside a task that had to own its record.
    pub fn absorb(&mut self, other: Tail) {
        self.samples.extend(other.samples);
    }

    /// The `p`-th percentile (0 to 100).
    pub fn percentile(&mut self, p: f64) -> Duration {
        if self.samples.is_empty() {
            return Duration::ZERO;
        }
        self.samples.sort_unstable();
        let index = ((p / 100.0) * (self.samples.len() - 1) as f64).round() as usize;
        self.samples[index.min(self.samples.len() - 1)]
    }

    /// Prints p50, p99 and p99.9 of `case`, and saves them beside criterion's estimates for
    /// the ratio table.
    pub fn report(mut self, case: &str) {
        let (p50, p99, p999) = (
            self.percentile(50.0),
            self.percentile(99.0),
            self.percentile(99.9),
        );
        println!(
            "tail {case}: p50 {} ns, p99 {} ns, p99.9 {} ns ({} round trips)",
            p50.as_nanos(),
            p99.as_nanos(),
            p999.as_nanos(),
            self.samples.len()
        );
        let dir = criterion_dir().join("tail");
        if std::fs::create_dir_all(&dir).is_ok() {
            let file = dir.join(format!("{}.txt", case.replace('/', "_")));
            let text = format!(
                "{} {} {}\n",
                p50.as_nanos(),
                p99.as_nanos(),
                p999.as_nanos()
            );
            let _ = std::fs::write(file, text);
        }
    }
}

/// Where the client module leaves its timing.
pub type Timed = Arc<Mutex<Duration>>;

/// A bench cell's log keeps this many events: full after the first round trips, as in a long run.
pub const KEPT: usize = 4_096;

/// SERVER receives and replies `iters` times; CLIENT sends `iters` times and times it.
pub fn ctx_modules(cell: &Cell, iters: u64, timed: &Timed) -> (ModuleSpec<()>, ModuleSpec<()>) {
    let feed = Port::<[u8; 8], u64, usage::Receive>::declare(
        PortSpec::new("FEED", "SERVER").clock(cell.clock().clone()),
    );
    let port = feed.clone();
    let server = ModuleSpec::new("SERVER", ())
        .owns(&feed)
        .task("SERVER", move |ctx| {
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

/// When the token was first sent, and how long its last hop took to land.
#[derive(Default)]
struct Lap {
    start: Option<Instant>,
    timed: Option<Duration>,
}

type Shared = Arc<Mutex<Lap>>;

/// A runtime of `threads` threads: current-thread for one.
pub fn runtime(threads: usize) -> tokio::runtime::Runtime {
    let mut builder = if threads == 1 {
        tokio::runtime::Builder::new_current_thread()
    } else {
        let mut builder = tokio::runtime::Builder::new_multi_thread();
        builder.worker_threads(threads);
        builder
    };
    builder.enable_all().build().expect("a runtime starts")
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
        .owns(&own)
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
            .map(|i| Port::declare(PortSpec::new(format!("P{i}"), format!("M{i}"))))
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
        let port = Port::<u64, u64, usage::Receive>::declare(PortSpec::new(
            format!("IDLE{i}"),
            format!("M{i}"),
        ));
        let own = port.clone();
        let spec =
            ModuleSpec::new(format!("M{i}"), ())
                .owns(&port)
                .task(format!("M{i}"), move |ctx| {
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
