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

#[path = "ipc/alternating.rs"]
mod alternating;
#[path = "ipc/peers.rs"]
mod peers;
#[path = "ipc/raw.rs"]
mod raw;
#[path = "ipc/round_trips.rs"]
mod round_trips;

use std::time::Duration;

use alternating::alternating;
use iceoryx2::prelude::ZeroCopySend;
use imrs_ipc::FromBytes;
use peers::{PEER, Peer, peer, start_peer};
use raw::{ONE_ID, Wait, raw_round_trips};
use round_trips::{broadcasts, imrs_round_trips, in_task, loaned_round_trips};

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
