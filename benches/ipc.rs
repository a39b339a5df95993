//! The rendezvous round trip between two processes: an IMRS port carried by `imrs-ipc`
//! (the user's send, through the bridges, to the owner's receive and back), beside a raw
//! iceoryx2 request-response round trip that waits on iceoryx2 events — the same payloads,
//! the same two processes, the same run. Each case: p50, p99 and p99.9 over its round
//! trips, and the ratios the targets are stated in. Beside the raw round trip as iceoryx2
//! sets it up by default, one whose events have one id, as the IMRS bridges size theirs:
//! each wake-up clears every id an event service allows.
//!
//! The same round trips on ports of messages built in place (`Shared`): the sender builds
//! each message in a sample of shared memory loaned from its port, the owner reads it
//! there, and its reply is copied once into the sample that carries it back.
//!
//! Then the round trips again, taking turns one round trip at a time in one task, so that
//! whatever else the shared machine does meanwhile weighs on all alike: raw iceoryx2 with
//! its client blocking its thread on the reply event, raw iceoryx2 with both ends waiting
//! in tokio tasks through the reactor (as the IMRS bridges wait), the IMRS port, and the
//! IMRS port loaned, 8 B and 64 KiB. Run one case after the other, a case's figures move by
//! a fifth from run to run with the machine's load, and on a quiet machine jump between
//! where the scheduler happens to wake threads; taking turns, their ratios move far less.
//!
//! Then `SENDALL` broadcasts from this process to one user in a peer started for them, 8 B
//! and 64 KiB, by value and built in place, each timed to its first reply; and broadcasts
//! built in place to two users, each in a peer of its own, timed to the last reply, and
//! the 64 KiB ones again built on the heap, which the port copies into one sample for both.
//!
//! Then the TIGHT cases, each against a peer started only for it (a spinning peer would
//! otherwise take processor time from the other cases): an IMRS port declared TIGHT, beside
//! a raw iceoryx2 round trip whose client and server both spin. They need a processor for
//! each end, and are left out of a run that has one.
//!
//! Each IMRS case runs where a module runs, in a task on the runtime's workers; each raw
//! case in a thread of its own. Where the processes run, and how many threads each has,
//! weighs on every case that waits, in ways the port does not decide: started under
//! `taskset -c 0`, the bench and its peers share one processor, and a wake-up never has to
//! reach another; `IMRS_IPC_BENCH_WORKERS=1` gives each process's runtime one worker
//! rather than two.
//!
//! `cargo bench --bench ipc` measures 20 000 round trips a case; `cargo test` runs 200, so
//! that the benchmark cannot rot. The peers are this same binary, started again with
//! `IMRS_IPC_BENCH_PEER` set.

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use imrs_ipc::{FromBytes, Imported, IpcError, Remote, Wire, export, import};
use imrs_ports::{AnyUser, End, Port, PortSpec, ProcessType, Shared, usage};
use tokio::io::Interest;
use tokio::io::unix::AsyncFd;

type Svc = ipc_threadsafe::Service;

#[derive(Debug, Clone, Copy, Default, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("imrs_benches::Small")]
struct Small {
    value: u64,
}

#[derive(Debug, Clone, Copy, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("imrs_benches::Large")]
struct Large {
    bytes: [u8; 65536],
}

impl Default for Large {
    fn default() -> Self {
        Self { bytes: [0; 65536] }
    }
}

const PEER: &str = "IMRS_IPC_BENCH_PEER";
/// The suffix of a raw part whose events have one id, as the IMRS bridges' do.
const ONE_ID: &str = "-one-id";
const TIGHT: &str = "IMRS_IPC_BENCH_TIGHT";
/// The raw part served by a task of the peer's runtime.
const TASK_PART: &str = "task-one-id";
/// Set, to the module's name, for a peer that listens to the `SENDALL` ports.
const LISTEN: &str = "IMRS_IPC_BENCH_LISTEN";
/// How many workers each process's runtime has, if not two.
const WORKERS: &str = "IMRS_IPC_BENCH_WORKERS";

fn main() {
    if let Ok(cell) = std::env::var(PEER) {
        peer(&cell);
        return;
    }
    let rounds = if std::env::args().any(|arg| arg == "--bench") {
        20_000
    } else {
        200
    };
    let cell = format!("bench-{}", std::process::id());
    let runtime = runtime();
    let mut child = start_peer(&cell, Peer::Parked);
    let raw_small = raw_round_trips::<Small>(&cell, "small", rounds, Wait::Events);
    let raw_large = raw_round_trips::<Large>(&cell, "large", rounds, Wait::Events);
    let raw_small_one_id =
        raw_round_trips::<Small>(&cell, &format!("small{ONE_ID}"), rounds, Wait::Events);
    let imrs_small = in_task(&runtime, imrs_round_trips::<Small>(&cell, "SMALL", rounds));
    let imrs_large = in_task(&runtime, imrs_round_trips::<Large>(&cell, "LARGE", rounds));
    let loaned_small = in_task(
        &runtime,
        loaned_round_trips::<Small>(&cell, "SMALL_LOANED", rounds),
    );
    let loaned_large = in_task(
        &runtime,
        loaned_round_trips::<Large>(&cell, "LARGE_LOANED", rounds),
    );
    let [
        raw_alternating,
        raw_task_alternating,
        imrs_alternating,
        loaned_small_alternating,
        loaned_large_alternating,
    ] = runtime
        .block_on(runtime.spawn(alternating(cell.clone(), rounds)))
        .expect("the round trips ran");
    let _ = child.kill();
    let _ = child.wait();

    // Two ends spinning need a processor each: on one, each spins out its turns while the
    // other waits for the processor, which measures the scheduler, not the port.
    let processors = std::thread::available_parallelism().map_or(1, usize::from);
    let spinning = (processors > 1).then(|| {
        let tight_cell = format!("{cell}-tight");
        let mut child = start_peer(&tight_cell, Peer::RawSpinning);
        let raw_spin = raw_round_trips::<Small>(&tight_cell, "small", rounds, Wait::Spin);
        let _ = child.kill();
        let _ = child.wait();
        let mut child = start_peer(&tight_cell, Peer::Tight);
        let imrs_tight = in_task(
            &runtime,
            imrs_round_trips::<Small>(&tight_cell, "SMALL", rounds),
        );
        let _ = child.kill();
        let _ = child.wait();
        (raw_spin, imrs_tight)
    });

    let [
        news_small,
        news_large,
        news_loaned_small,
        news_loaned_large,
        pair_small,
        pair_large,
        pair_large_heap,
    ] = broadcasts(&runtime, &cell, rounds);

    println!("round trip between two processes, {rounds} each   p50      p99      p99.9");
    for (name, times) in [
        ("raw iceoryx2, events, 8 B", &raw_small),
        ("raw iceoryx2, events of one id, 8 B", &raw_small_one_id),
        ("IMRS port over iceoryx2, 8 B", &imrs_small),
        ("raw iceoryx2, events, 64 KiB", &raw_large),
        ("IMRS port over iceoryx2, 64 KiB", &imrs_large),
        ("IMRS port, loaned, 8 B", &loaned_small),
        ("IMRS port, loaned, 64 KiB", &loaned_large),
    ] {
        let [p50, p99, p999] = percentiles(times);
        println!("  {name:<38} {p50:>8.1?} {p99:>8.1?} {p999:>8.1?}");
    }
    if let Some((raw_spin, imrs_tight)) = &spinning {
        for (name, times) in [
            ("raw iceoryx2, both spinning, 8 B", raw_spin),
            ("IMRS TIGHT port, 8 B", imrs_tight),
        ] {
            let [p50, p99, p999] = percentiles(times);
            println!("  {name:<38} {p50:>8.1?} {p99:>8.1?} {p999:>8.1?}");
        }
    }
    println!("SENDALL to one user in another process, each broadcast to its first reply:");
    for (name, times) in [
        ("IMRS SENDALL, 8 B", &news_small),
        ("IMRS SENDALL, 64 KiB", &news_large),
        ("IMRS SENDALL, loaned, 8 B", &news_loaned_small),
        ("IMRS SENDALL, loaned, 64 KiB", &news_loaned_large),
    ] {
        let [p50, p99, p999] = percentiles(times);
        println!("  {name:<38} {p50:>8.1?} {p99:>8.1?} {p999:>8.1?}");
    }
    println!("SENDALL to two users in two other processes, each broadcast to its last reply:");
    for (name, times) in [
        ("IMRS SENDALL, loaned, 8 B", &pair_small),
        ("IMRS SENDALL, loaned, 64 KiB", &pair_large),
        ("IMRS SENDALL, on the heap, 64 KiB", &pair_large_heap),
    ] {
        let [p50, p99, p999] = percentiles(times);
        println!("  {name:<38} {p50:>8.1?} {p99:>8.1?} {p999:>8.1?}");
    }
    println!("the round trips again, taking turns one round trip at a time (8 B unless said):");
    for (name, times) in [
        ("raw iceoryx2, events of one id", &raw_alternating),
        ("raw iceoryx2, waited on in a task", &raw_task_alternating),
        ("IMRS port over iceoryx2", &imrs_alternating),
        ("IMRS port, loaned", &loaned_small_alternating),
        ("IMRS port, loaned, 64 KiB", &loaned_large_alternating),
    ] {
        let [p50, p99, p999] = percentiles(times);
        println!("  {name:<38} {p50:>8.1?} {p99:>8.1?} {p999:>8.1?}");
    }
    let ratio = |a: &[Duration], b: &[Duration]| {
        let (a, b) = (percentiles(a), percentiles(b));
        (0..3).map(move |i| a[i].as_secs_f64() / b[i].as_secs_f64())
    };
    let show = |ratios: Vec<f64>| format!("{:.2} / {:.2} / {:.2}", ratios[0], ratios[1], ratios[2]);
    println!(
        "  IMRS 8 B vs raw 8 B (target: no worse than raw on a parked port)   {}",
        show(ratio(&imrs_small, &raw_small).collect())
    );
    println!(
        "  IMRS 8 B vs raw 8 B with events of one id, as IMRS sizes them        {}",
        show(ratio(&imrs_small, &raw_small_one_id).collect())
    );
    println!(
        "  IMRS 8 B vs raw 8 B of one id, taking turns (target: no worse)     {}",
        show(ratio(&imrs_alternating, &raw_alternating).collect())
    );
    println!(
        "  raw waited on in a task vs raw 8 B of one id, taking turns         {}",
        show(ratio(&raw_task_alternating, &raw_alternating).collect())
    );
    println!(
        "  IMRS 64 KiB vs IMRS 8 B, by value                                  {}",
        show(ratio(&imrs_large, &imrs_small).collect())
    );
    println!(
        "  IMRS 64 KiB loaned vs IMRS 8 B loaned (target: within 1.5)         {}",
        show(ratio(&loaned_large, &loaned_small).collect())
    );
    println!(
        "  IMRS 64 KiB loaned vs IMRS 8 B loaned, taking turns (target: 1.5)  {}",
        show(ratio(&loaned_large_alternating, &loaned_small_alternating).collect())
    );
    println!(
        "  IMRS 64 KiB loaned vs IMRS 8 B by value                            {}",
        show(ratio(&loaned_large, &imrs_small).collect())
    );
    println!(
        "  IMRS 8 B loaned vs raw 8 B                                         {}",
        show(ratio(&loaned_small, &raw_small).collect())
    );
    println!(
        "  SENDALL 64 KiB vs 8 B, by value                                    {}",
        show(ratio(&news_large, &news_small).collect())
    );
    println!(
        "  SENDALL 64 KiB vs 8 B, loaned                                      {}",
        show(ratio(&news_loaned_large, &news_loaned_small).collect())
    );
    println!(
        "  SENDALL to two users, 64 KiB vs 8 B, loaned                        {}",
        show(ratio(&pair_large, &pair_small).collect())
    );
    println!(
        "  SENDALL to two users, 64 KiB on the heap vs loaned                 {}",
        show(ratio(&pair_large_heap, &pair_large).collect())
    );
    match &spinning {
        Some((raw_spin, imrs_tight)) => println!(
            "  IMRS TIGHT 8 B vs raw spinning 8 B (target: within 1.2)            {}",
            show(ratio(imrs_tight, raw_spin).collect())
        ),
        None => println!(
            "  TIGHT cases not run: this run has one processor, and two ends spinning need two"
        ),
    }
}

/// What a peer serves.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Peer {
    /// Both IMRS ports and both raw services, all waiting on events.
    Parked,
    /// One raw service, spinning.
    RawSpinning,
    /// One IMRS port declared TIGHT.
    Tight,
    /// A user of `SENDALL` ports, echoing each broadcast: LISTENER, the one user of four
    /// and one of the two users of two more; or LISTENER_2, the other of those two.
    Listener(&'static str),
}

/// Starts a peer for `cell` serving `what`, and waits until it serves.
fn start_peer(cell: &str, what: Peer) -> std::process::Child {
    let mut command = Command::new(std::env::current_exe().expect("this binary"));
    command.env(PEER, cell).stdout(Stdio::piped());
    match what {
        Peer::Parked => {}
        Peer::RawSpinning => {
            command.env(TIGHT, "raw");
        }
        Peer::Tight => {
            command.env(TIGHT, "imrs");
        }
        Peer::Listener(module) => {
            command.env(LISTEN, module);
        }
    }
    let mut child = command.spawn().expect("the peer starts");
    let mut line = String::new();
    BufReader::new(child.stdout.take().expect("piped"))
        .read_line(&mut line)
        .expect("the peer speaks");
    assert_eq!(line.trim(), "ready", "the peer failed: {line}");
    child
}

/// How a raw round trip's two ends wait.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Wait {
    /// On iceoryx2 events, each side notifying the other.
    Events,
    /// Looking again at once, yielding the processor between looks: nobody notifies.
    Spin,
}

/// Each process's runtime: two workers (or as many as `IMRS_IPC_BENCH_WORKERS` says, which
/// the peers inherit), with stacks large enough for 64 KiB messages, which the bridges'
/// futures copy by value — more than tokio's 2 MiB default holds in a debug build.
fn runtime() -> tokio::runtime::Runtime {
    let workers = match std::env::var(WORKERS) {
        Err(_) => 2,
        Ok(workers) => match workers.parse::<usize>() {
            Ok(workers) if workers > 0 => workers,
            _ => {
                eprintln!("{WORKERS}={workers:?}: give a number of workers, 1 or more");
                std::process::exit(2);
            }
        },
    };
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(workers)
        .thread_stack_size(32 << 20)
        .enable_all()
        .build()
        .expect("a tokio runtime")
}

fn percentiles(times: &[Duration]) -> [Duration; 3] {
    let mut sorted = times.to_vec();
    sorted.sort_unstable();
    let at = |q: f64| sorted[((sorted.len() as f64 * q) as usize).min(sorted.len() - 1)];
    [at(0.5), at(0.99), at(0.999)]
}

/// The peer: owns both IMRS ports (echoing), and serves both raw services; or serves one
/// spinning raw service; or owns one TIGHT IMRS port.
fn peer(cell: &str) {
    let what = match std::env::var(TIGHT).as_deref() {
        Ok("raw") => Peer::RawSpinning,
        Ok(_) => Peer::Tight,
        Err(_) => match std::env::var(LISTEN).as_deref() {
            Ok("LISTENER") => Peer::Listener("LISTENER"),
            Ok(_) => Peer::Listener("LISTENER_2"),
            Err(_) => Peer::Parked,
        },
    };
    let raw: &[&str] = match what {
        Peer::Parked => &["small", "large", "small-one-id"],
        Peer::RawSpinning => &["small"],
        Peer::Tight | Peer::Listener(_) => &[],
    };
    let wait = if what == Peer::RawSpinning {
        Wait::Spin
    } else {
        Wait::Events
    };
    for part in raw {
        let (cell, part) = (cell.to_owned(), *part);
        std::thread::spawn(move || match part {
            "large" => raw_server::<Large>(&cell, part, wait),
            _ => raw_server::<Small>(&cell, part, wait),
        });
    }
    let runtime = runtime();
    runtime.block_on(async {
        let remote = Remote::new(cell).expect("a cell name");
        if what == Peer::Parked {
            tokio::spawn(raw_task_server(cell.to_owned()));
        }
        let _echoes = match what {
            Peer::Parked => vec![
                echo::<Small>(&remote, "SMALL", ProcessType::Indep),
                echo::<Large>(&remote, "LARGE", ProcessType::Indep),
                loaned_echo::<Small>(&remote, "SMALL_LOANED"),
                loaned_echo::<Large>(&remote, "LARGE_LOANED"),
            ],
            Peer::RawSpinning => Vec::new(),
            Peer::Tight => vec![echo::<Small>(&remote, "SMALL", ProcessType::Tight)],
            Peer::Listener("LISTENER") => vec![
                listen::<Small>(&remote, "NEWS_SMALL"),
                listen::<Large>(&remote, "NEWS_LARGE"),
                loaned_listen::<Small>(&remote, "NEWS_SMALL_LOANED", "LISTENER"),
                loaned_listen::<Large>(&remote, "NEWS_LARGE_LOANED", "LISTENER"),
                loaned_listen::<Small>(&remote, "PAIR_SMALL", "LISTENER"),
                loaned_listen::<Large>(&remote, "PAIR_LARGE", "LISTENER"),
            ],
            Peer::Listener(module) => vec![
                loaned_listen::<Small>(&remote, "PAIR_SMALL", module),
                loaned_listen::<Large>(&remote, "PAIR_LARGE", module),
            ],
        };
        // Give the raw servers a moment to open their services.
        tokio::time::sleep(Duration::from_millis(200)).await;
        println!("ready");
        // It serves until it is killed.
        std::future::pending::<()>().await;
    });
}

fn echo<T: Wire>(
    remote: &Remote,
    name: &str,
    process_type: ProcessType,
) -> tokio::task::JoinHandle<()> {
    let port: Port<T, T, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new(name, "ECHO").process_type(process_type));
    let exported = export(remote, &port).expect("exported");
    let mut owner = port.owner().expect("the owner's end");
    tokio::spawn(async move {
        let _exported = exported;
        while let Ok((message, reply)) = owner.receive().await {
            reply.reply(message);
        }
    })
}

/// The one user of `SENDALL` port `name` (owner CAMERA), LISTENER, answering each
/// broadcast with itself.
fn listen<T: Wire>(remote: &Remote, name: &str) -> tokio::task::JoinHandle<()> {
    echo_broadcasts(
        import::<Imported<T, T, usage::SendAll>, _>(remote, name, "CAMERA", "LISTENER"),
        "LISTENER",
    )
}

/// The same for `module`, a user of a port of messages built in place: each read where it
/// lies, and answered with itself, copied once into the reply's sample.
fn loaned_listen<T: Wire>(
    remote: &Remote,
    name: &str,
    module: &str,
) -> tokio::task::JoinHandle<()> {
    echo_broadcasts(
        import::<Imported<Shared<T>, Shared<T>, usage::SendAll>, _>(remote, name, "CAMERA", module),
        module,
    )
}

/// Answers each broadcast on `imported` with itself, as its user `module`.
fn echo_broadcasts<M: Send + 'static>(
    imported: Result<Imported<M, M, usage::SendAll>, IpcError>,
    module: &str,
) -> tokio::task::JoinHandle<()> {
    let imported = imported.expect("imported");
    let mut listener = imported.port().user_named(module).expect("the user's end");
    tokio::spawn(async move {
        let _imported = imported;
        while let Ok((message, reply)) = listener.receive().await {
            reply.reply(message);
        }
    })
}

/// An echo of messages built in place: each read where its sender built it, and answered
/// with itself, copied once into the reply's sample.
fn loaned_echo<T: Wire>(remote: &Remote, name: &str) -> tokio::task::JoinHandle<()> {
    let port: Port<Shared<T>, Shared<T>, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new(name, "ECHO"));
    let exported = export(remote, &port).expect("exported");
    let mut owner = port.owner().expect("the owner's end");
    tokio::spawn(async move {
        let _exported = exported;
        while let Ok((message, reply)) = owner.receive().await {
            reply.reply(message);
        }
    })
}

/// `rounds` round trips, each timed, after a tenth as many to warm up. A macro, not an
/// async closure: the round trips run in a task, and the future of an async closure that
/// borrows the port's end is not `Send` for every lifetime, as a task needs.
macro_rules! timed {
    ($rounds:expr, $round_trip:block) => {{
        for _ in 0..$rounds / 10 {
            $round_trip
        }
        let mut times = Vec::with_capacity($rounds);
        for _ in 0..$rounds {
            let start = Instant::now();
            $round_trip
            times.push(start.elapsed());
        }
        times
    }};
}

/// Runs `round_trips` where a module runs: in a task on the runtime's workers.
fn in_task(
    runtime: &tokio::runtime::Runtime,
    round_trips: impl Future<Output = Vec<Duration>> + Send + 'static,
) -> Vec<Duration> {
    runtime
        .block_on(runtime.spawn(round_trips))
        .expect("the round trips ran")
}

/// Broadcasts on four `SENDALL` ports of this process to their one user, a peer started for
/// them: 8 B and 64 KiB, by value and built in place; each timed to its first reply. Then
/// on two more, built in place, to two users, each in a peer of its own; each timed to its
/// last reply.
fn broadcasts(runtime: &tokio::runtime::Runtime, cell: &str, rounds: usize) -> [Vec<Duration>; 7] {
    let cell = format!("{cell}-news");
    let remote = Remote::new(&cell).expect("a cell name");
    let _entered = runtime.enter();
    let small = Port::<Small, Small, usage::SendAll, AnyUser, 1>::new(PortSpec::new(
        "NEWS_SMALL",
        "CAMERA",
    ));
    let large = Port::<Large, Large, usage::SendAll, AnyUser, 1>::new(PortSpec::new(
        "NEWS_LARGE",
        "CAMERA",
    ));
    let loaned_small = Port::<Shared<Small>, Shared<Small>, usage::SendAll, AnyUser, 1>::new(
        PortSpec::new("NEWS_SMALL_LOANED", "CAMERA"),
    );
    let loaned_large = Port::<Shared<Large>, Shared<Large>, usage::SendAll, AnyUser, 1>::new(
        PortSpec::new("NEWS_LARGE_LOANED", "CAMERA"),
    );
    let pair = |name: &str| PortSpec::new(name, "CAMERA").user_list(["LISTENER", "LISTENER_2"]);
    let pair_small =
        Port::<Shared<Small>, Shared<Small>, usage::SendAll, AnyUser, 2>::new(pair("PAIR_SMALL"));
    let pair_large =
        Port::<Shared<Large>, Shared<Large>, usage::SendAll, AnyUser, 2>::new(pair("PAIR_LARGE"));
    let _exported = [
        export(&remote, &small),
        export(&remote, &large),
        export(&remote, &loaned_small),
        export(&remote, &loaned_large),
        export(&remote, &pair_small),
        export(&remote, &pair_large),
    ]
    .map(|exported| exported.expect("exported"));
    let mut child = start_peer(&cell, Peer::Listener("LISTENER"));
    let mut second = start_peer(&cell, Peer::Listener("LISTENER_2"));
    let times = [
        in_task(runtime, broadcast_times(small.owner().unwrap(), rounds)),
        in_task(runtime, broadcast_times(large.owner().unwrap(), rounds)),
        in_task(
            runtime,
            shared_broadcast_times(loaned_small.owner().unwrap(), 1, rounds, loaned),
        ),
        in_task(
            runtime,
            shared_broadcast_times(loaned_large.owner().unwrap(), 1, rounds, loaned),
        ),
        in_task(
            runtime,
            shared_broadcast_times(pair_small.owner().unwrap(), 2, rounds, loaned),
        ),
        in_task(
            runtime,
            shared_broadcast_times(pair_large.owner().unwrap(), 2, rounds, loaned),
        ),
        in_task(
            runtime,
            shared_broadcast_times(pair_large.owner().unwrap(), 2, rounds, on_heap),
        ),
    ];
    for child in [&mut child, &mut second] {
        let _ = child.kill();
        let _ = child.wait();
    }
    times
}

/// `rounds` broadcasts of `T::default()` to the port's users, each timed to its first reply.
async fn broadcast_times<T: Wire>(
    mut owner: End<T, T, usage::SendAll>,
    rounds: usize,
) -> Vec<Duration> {
    timed!(rounds, {
        let mut news = owner.send_all(T::default()).await.expect("an answer");
        std::hint::black_box(std::mem::take(&mut news.first));
    })
}

/// The owner's end of a `SENDALL` port of messages built in place.
type Camera<T> = End<Shared<T>, Shared<T>, usage::SendAll>;

/// A broadcast built in a loan of the port: a sample of shared memory, sent as it is.
fn loaned<T: Wire>(owner: &mut Camera<T>) -> Shared<T> {
    owner.loan().expect("a loan")
}

/// A broadcast built on the heap: the port copies it into one sample for all its users.
fn on_heap<T: Wire>(_: &mut Camera<T>) -> Shared<T> {
    Shared::new(T::default())
}

/// `rounds` broadcasts, each made by `build`, and timed to the last of the replies of its
/// `users` users.
async fn shared_broadcast_times<T: Wire>(
    mut owner: Camera<T>,
    users: usize,
    rounds: usize,
    build: fn(&mut Camera<T>) -> Shared<T>,
) -> Vec<Duration> {
    timed!(rounds, {
        let message = build(&mut owner);
        let mut news = owner.send_all(message).await.expect("an answer");
        std::hint::black_box(&*std::mem::take(&mut news.first));
        for _ in 1..users {
            let (_, reply) = news.next_reply().await.expect("every user answers");
            std::hint::black_box(&*reply);
        }
    })
}

/// Round trips of messages built in place: each loaned from the port (zeroed, in shared
/// memory), sent, and its reply read where the owner's process wrote it.
fn loaned_round_trips<T: Wire>(
    cell: &str,
    port: &str,
    rounds: usize,
) -> impl Future<Output = Vec<Duration>> + Send + 'static {
    let (cell, port) = (cell.to_owned(), port.to_owned());
    async move { loaned_round_trips_of::<T>(&cell, &port, rounds).await }
}

async fn loaned_round_trips_of<T: Wire>(cell: &str, port: &str, rounds: usize) -> Vec<Duration> {
    let remote = Remote::new(cell).expect("a cell name");
    let imported =
        import::<Imported<Shared<T>, Shared<T>, usage::Receive>, _>(&remote, port, "ECHO", "ASKER")
            .expect("imported");
    let mut asker = imported.port().user_named("ASKER").expect("the user's end");
    timed!(rounds, {
        let message = asker.loan().expect("a loan");
        let reply = asker.send(message).await.expect("a round trip");
        std::hint::black_box(&*reply);
    })
}

fn imrs_round_trips<T: Wire>(
    cell: &str,
    port: &str,
    rounds: usize,
) -> impl Future<Output = Vec<Duration>> + Send + 'static {
    let (cell, port) = (cell.to_owned(), port.to_owned());
    async move { imrs_round_trips_of::<T>(&cell, &port, rounds).await }
}

async fn imrs_round_trips_of<T: Wire>(cell: &str, port: &str, rounds: usize) -> Vec<Duration> {
    let remote = Remote::new(cell).expect("a cell name");
    let imported = import::<Imported<T, T, usage::Receive>, _>(&remote, port, "ECHO", "ASKER")
        .expect("imported");
    let mut asker = imported.port().user_named("ASKER").expect("the user's end");
    timed!(rounds, {
        std::hint::black_box(asker.send(T::default()).await.expect("a round trip"));
    })
}

type RawService<T> =
    iceoryx2::service::port_factory::request_response::PortFactory<Svc, T, (), T, ()>;
type RawEvents = iceoryx2::service::port_factory::event::PortFactory<Svc>;

/// The raw services of `part`: the request-response service and its two events, on a node
/// that must live as long as they are used.
fn raw_services<T: Wire>(
    cell: &str,
    part: &str,
) -> (Node<Svc>, RawService<T>, RawEvents, RawEvents) {
    let node = NodeBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<Svc>()
        .expect("a node");
    let name = |what: &str| {
        ServiceName::new(&format!("raw/{cell}/{part}/{what}")).expect("a service name")
    };
    let service = node
        .service_builder(&name("messages"))
        .request_response::<T, T>()
        .open_or_create()
        .expect("the service");
    let event = |what: &str| {
        let events = node.service_builder(&name(what)).event();
        // As the IMRS bridges size theirs: one event id, which a wake-up clears, rather
        // than the default 256.
        let events = if part.ends_with(ONE_ID) {
            events.event_id_max_value(0)
        } else {
            events
        };
        events.open_or_create().expect("events")
    };
    let (requested, replied) = (event("requested"), event("replied"));
    (node, service, requested, replied)
}

/// A raw iceoryx2 server: waits on its request event (or spins), answers a copy, notifies
/// (unless the client spins too).
fn raw_server<T: Wire>(cell: &str, part: &str, wait: Wait) {
    let (_node, service, requested, replied) = raw_services::<T>(cell, part);
    let server = service.server_builder().create().expect("a server");
    let listener = requested.listener_builder().create().expect("a listener");
    let notifier = replied.notifier_builder().create().expect("a notifier");
    loop {
        match wait {
            Wait::Events => {
                if listener.blocking_wait(|_| {}).is_err() {
                    return;
                }
            }
            Wait::Spin => std::thread::yield_now(),
        }
        while let Ok(Some(request)) = server.receive() {
            let payload = *request.payload();
            let _ = request.send_copy(payload);
            if wait == Wait::Events {
                let _ = notifier.notify();
            }
        }
    }
}

fn raw_round_trips<T: Wire>(cell: &str, part: &str, rounds: usize, wait: Wait) -> Vec<Duration> {
    let (_node, service, requested, replied) = raw_services::<T>(cell, part);
    let client = service.client_builder().create().expect("a client");
    let listener = replied.listener_builder().create().expect("a listener");
    let notifier = requested.notifier_builder().create().expect("a notifier");
    let round_trip = || {
        let pending = client.send_copy(T::default()).expect("sent");
        if wait == Wait::Events {
            let _ = notifier.notify();
        }
        loop {
            if let Ok(Some(response)) = pending.receive() {
                return std::hint::black_box(*response.payload());
            }
            match wait {
                Wait::Events => {
                    let _ = listener.timed_wait(|_| {}, Duration::from_millis(50));
                }
                Wait::Spin => std::thread::yield_now(),
            }
        }
    };
    for _ in 0..rounds / 10 {
        round_trip();
    }
    (0..rounds)
        .map(|_| {
            let start = Instant::now();
            round_trip();
            start.elapsed()
        })
        .collect()
}

/// A listener's socket, as tokio's reactor names it.
struct Socket(std::os::fd::RawFd);

impl std::os::fd::AsRawFd for Socket {
    fn as_raw_fd(&self) -> std::os::fd::RawFd {
        self.0
    }
}

/// `listener`'s wake-ups, through tokio's reactor: a task waits for them with no thread of
/// its own, as the IMRS bridges do.
fn readiness(listener: &Listener<Svc>) -> AsyncFd<Socket> {
    // SAFETY: `native_handle` only reads the number of the listener's own socket.
    let raw = unsafe { listener.file_descriptor().native_handle() };
    // SAFETY: the socket is open for as long as `listener` lives, and each caller drops the
    // registration before the listener.
    unsafe { AsyncFd::register_with_interest(Socket(raw), Interest::READABLE) }
        .expect("registered with the reactor")
}

/// Waits in a task until `listener` is notified, and takes its notifications.
async fn notified(socket: &AsyncFd<Socket>, listener: &Listener<Svc>) {
    let mut ready = socket.readable().await.expect("the reactor runs");
    ready.clear_ready();
    let _ = listener.try_wait(|_| {});
}

/// A raw iceoryx2 server in a tokio task, waiting on its request event through the reactor.
async fn raw_task_server(cell: String) {
    let (_node, service, requested, replied) = raw_services::<Small>(&cell, TASK_PART);
    let server = service.server_builder().create().expect("a server");
    let listener = requested.listener_builder().create().expect("a listener");
    let notifier = replied.notifier_builder().create().expect("a notifier");
    let socket = readiness(&listener);
    loop {
        notified(&socket, &listener).await;
        while let Ok(Some(request)) = server.receive() {
            let payload = *request.payload();
            let _ = request.send_copy(payload);
            let _ = notifier.notify();
        }
    }
}

/// The 8 B round trips, one of each in turn, `rounds` times in one task, so that whatever
/// else the machine does weighs on all three alike: a raw round trip whose client blocks
/// its thread on the reply event (events of one id, as the IMRS bridges size theirs); a raw
/// round trip whose client and server wait in tasks, through tokio's reactor; and an IMRS
/// port's.
async fn alternating(cell: String, rounds: usize) -> [Vec<Duration>; 5] {
    struct Raw {
        _node: Node<Svc>,
        client: iceoryx2::port::client::Client<Svc, Small, (), Small, ()>,
        listener: Listener<Svc>,
        notifier: iceoryx2::port::notifier::Notifier<Svc>,
    }
    let raw = |part: &str| {
        let (node, service, requested, replied) = raw_services::<Small>(&cell, part);
        Raw {
            _node: node,
            client: service.client_builder().create().expect("a client"),
            listener: replied.listener_builder().create().expect("a listener"),
            notifier: requested.notifier_builder().create().expect("a notifier"),
        }
    };
    let (blocking, in_task) = (raw(&format!("small{ONE_ID}")), raw(TASK_PART));
    let socket = readiness(&in_task.listener);
    let remote = Remote::new(&cell).expect("a cell name");
    let imported =
        import::<Imported<Small, Small, usage::Receive>, _>(&remote, "SMALL", "ECHO", "ASKER")
            .expect("imported");
    let mut asker = imported.port().user_named("ASKER").expect("the user's end");
    let loaned_small = import::<Imported<Shared<Small>, Shared<Small>, usage::Receive>, _>(
        &remote,
        "SMALL_LOANED",
        "ECHO",
        "ASKER",
    )
    .expect("imported");
    let mut small_asker = loaned_small
        .port()
        .user_named("ASKER")
        .expect("the user's end");
    let loaned_large = import::<Imported<Shared<Large>, Shared<Large>, usage::Receive>, _>(
        &remote,
        "LARGE_LOANED",
        "ECHO",
        "ASKER",
    )
    .expect("imported");
    let mut large_asker = loaned_large
        .port()
        .user_named("ASKER")
        .expect("the user's end");
    let mut times: [Vec<Duration>; 5] = Default::default();
    for round in 0..rounds + rounds / 10 {
        let start = Instant::now();
        let pending = blocking.client.send_copy(Small::default()).expect("sent");
        let _ = blocking.notifier.notify();
        while !matches!(pending.receive(), Ok(Some(_))) {
            let _ = blocking
                .listener
                .timed_wait(|_| {}, Duration::from_millis(50));
        }
        let raw_blocking = start.elapsed();

        let start = Instant::now();
        let pending = in_task.client.send_copy(Small::default()).expect("sent");
        let _ = in_task.notifier.notify();
        while !matches!(pending.receive(), Ok(Some(_))) {
            notified(&socket, &in_task.listener).await;
        }
        let raw_in_task = start.elapsed();

        let start = Instant::now();
        std::hint::black_box(asker.send(Small::default()).await.expect("a round trip"));
        let imrs = start.elapsed();

        let start = Instant::now();
        let message = small_asker.loan().expect("a loan");
        std::hint::black_box(&*small_asker.send(message).await.expect("a round trip"));
        let loaned_small = start.elapsed();

        let start = Instant::now();
        let message = large_asker.loan().expect("a loan");
        std::hint::black_box(&*large_asker.send(message).await.expect("a round trip"));
        let loaned_large = start.elapsed();
        // The first tenth warms up.
        if round >= rounds / 10 {
            let round = [raw_blocking, raw_in_task, imrs, loaned_small, loaned_large];
            for (times, time) in times.iter_mut().zip(round) {
                times.push(time);
            }
        }
    }
    drop(socket);
    times
}
