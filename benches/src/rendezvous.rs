//! The round-trip drivers of the rendezvous benches: IMRS on one processor, on two tasks,
//! across threads and on TIGHT ports; tokio mpsc + oneshot asks, kameo, ractor, crossbeam
//! and atomic spins as baselines. Shared by `benches/rendezvous.rs` and the
//! `cross_thread_runs` program.
//!
//! Every driver moves its `[u8; N]` message by value, as an IMRS port does, and each
//! baseline runs on the same kind of runtime, with as many threads, as the IMRS case it
//! stands beside:
//!
//! - two tasks on one current-thread runtime (the asker in `block_on`, the server spawned):
//!   [`imrs_same_thread_tasks`], [`tokio_ask_current_thread`],
//!   [`kameo_ask_current_thread`], [`ractor_call_current_thread`];
//! - both ends in one spawned task of a current-thread runtime: [`imrs_same_thread`] (jobs
//!   of one processor), [`tokio_join_one_task`] (`tokio::join!`), and, nearby,
//!   [`tokio_local_set`] (two tasks of one `LocalSet`);
//! - across threads, the server on a current-thread runtime in a thread of its own and the
//!   asker on a current-thread runtime of the calling thread: [`imrs_cross_thread`],
//!   [`tokio_ask_cross_thread`], [`kameo_ask_cross_thread`], [`ractor_call_cross_thread`].

use std::cell::UnsafeCell;
use std::hint::black_box;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::thread;
use std::time::{Duration, Instant};

use imrs_core::Processor;
use imrs_ports::{Port, PortSpec, Priority, ProcessType, usage};
use tokio::sync::{mpsc, oneshot};

use crate::{Tail, current_thread, peers};

/// A tokio ask: the message, by value, and a oneshot for the answer.
pub type Ask<const N: usize> = ([u8; N], oneshot::Sender<u64>);

/// Runs `iters` round trips of `$round_trip` (an expression to await), timing all of them,
/// and each one into `$tail` when there is one. Without a tail no round trip reads the clock:
/// a read costs tens of nanoseconds, a sizeable part of a short round trip, and the kameo and
/// ractor drivers and the spins beside these read it only around the whole loop too.
macro_rules! round_trips {
    ($iters:expr, $tail:expr, $round_trip:expr) => {{
        let mut tail: Option<&mut Tail> = $tail;
        let start = Instant::now();
        for _ in 0..$iters {
            let one = tail.is_some().then(Instant::now);
            black_box($round_trip.await.unwrap());
            if let (Some(tail), Some(one)) = (tail.as_deref_mut(), one) {
                tail.push(one.elapsed());
            }
        }
        start.elapsed()
    }};
}

/// imrs, both ends on one processor: the modules' own co-scheduling on one thread.
pub fn imrs_same_thread<const N: usize>(iters: u64, tail: Option<&mut Tail>) -> Duration {
    imrs_on_processor::<N>(iters, tail, false)
}

/// As [`imrs_same_thread`], with the processor's message handler at work: both jobs and
/// the port declare priorities, so every wake is lifted and every choice weighs urgency.
pub fn imrs_same_thread_prioritized<const N: usize>(iters: u64) -> Duration {
    imrs_on_processor::<N>(iters, None, true)
}

/// Both ends on one processor, as jobs with priorities (`prioritized`) or without.
pub fn imrs_on_processor<const N: usize>(
    iters: u64,
    tail: Option<&mut Tail>,
    prioritized: bool,
) -> Duration {
    let keep = tail.is_some();
    let (timed, samples) = current_thread().block_on(async move {
        let processor = Processor::new("CPU1");
        let (mut spec, mut server_priority, mut client_priority) = (
            PortSpec::new("P", "SERVER"),
            Priority::DEFAULT,
            Priority::DEFAULT,
        );
        if prioritized {
            spec = spec.priority(1);
            (server_priority, client_priority) = (Priority::declared(3), Priority::declared(2));
        }
        let port = Port::<[u8; N], u64, usage::Receive>::new(spec);
        let mut server = port.owner().unwrap();
        let mut client = port.user_named("CLIENT").unwrap();
        let serving = processor.spawn_with_priority(server_priority, async move {
            for _ in 0..iters {
                let (message, reply) = server.receive().await.unwrap();
                reply.reply(u64::from(message[0]));
            }
        });
        let sending = processor.spawn_with_priority(client_priority, async move {
            let mut samples = Tail::with_capacity(if keep { iters as usize } else { 0 });
            let timed = round_trips!(
                iters,
                keep.then_some(&mut samples),
                client.send(black_box([1u8; N]))
            );
            (timed, samples)
        });
        let timed = sending.await.unwrap();
        serving.await.unwrap();
        timed
    });
    if let Some(tail) = tail {
        tail.absorb(samples);
    }
    timed
}

/// imrs, each end a tokio task of its own on one current-thread runtime: the asker in
/// `block_on`, the server spawned.
pub fn imrs_same_thread_tasks<const N: usize>(iters: u64, tail: Option<&mut Tail>) -> Duration {
    current_thread().block_on(async move {
        let port = Port::<[u8; N], u64, usage::Receive>::new(PortSpec::new("P", "SERVER"));
        let mut server = port.owner().unwrap();
        let mut client = port.user_named("CLIENT").unwrap();
        let serving = tokio::spawn(async move {
            for _ in 0..iters {
                let (message, reply) = server.receive().await.unwrap();
                reply.reply(u64::from(message[0]));
            }
        });
        let timed = round_trips!(iters, tail, client.send(black_box([1u8; N])));
        serving.await.unwrap();
        timed
    })
}

/// The server of a cross-thread round trip: a thread of its own that runs `serve` on a
/// current-thread runtime, parked between messages, as [`imrs_cross_thread`]'s receiver is.
fn server_thread<T: Send + 'static>(
    serve: impl Future<Output = T> + Send + 'static,
) -> thread::JoinHandle<T> {
    thread::spawn(move || current_thread().block_on(serve))
}

/// imrs, the receiver on its own thread (parked between messages, or spinning on TIGHT),
/// the asker on a current-thread runtime of the calling thread.
pub fn imrs_cross_thread<const N: usize>(
    iters: u64,
    process_type: ProcessType,
    tail: Option<&mut Tail>,
) -> Duration {
    let port = Port::<[u8; N], u64, usage::Receive>::new(
        PortSpec::new("P", "SERVER").process_type(process_type),
    );
    let mut server = port.owner().unwrap();
    let mut client = port.user_named("CLIENT").unwrap();
    let serving = server_thread(async move {
        for _ in 0..iters {
            let (message, reply) = server.receive().await.unwrap();
            reply.reply(u64::from(message[0]));
        }
    });
    let timed = current_thread()
        .block_on(async { round_trips!(iters, tail, client.send(black_box([1u8; N]))) });
    serving.join().unwrap();
    timed
}

/// An ask: the message and a oneshot for the answer, the usual tokio actor pattern.
pub async fn ask<const N: usize>(asks: &mpsc::Sender<Ask<N>>) -> Result<u64, &'static str> {
    let (reply, answer) = oneshot::channel();
    asks.send((black_box([1u8; N]), reply))
        .await
        .map_err(|_| "closed")?;
    answer.await.map_err(|_| "dropped")
}

/// The server side of a tokio ask: answers each message with its first byte.
pub async fn serve_asks<const N: usize>(mut inbox: mpsc::Receiver<Ask<N>>) {
    while let Some((message, reply)) = inbox.recv().await {
        let _ = reply.send(u64::from(message[0]));
    }
}

/// tokio mpsc + oneshot, two tasks of one current-thread runtime: the asker in `block_on`,
/// the server spawned, as [`imrs_same_thread_tasks`].
pub fn tokio_ask_current_thread<const N: usize>(iters: u64) -> Duration {
    current_thread().block_on(async move {
        let (asks, inbox) = mpsc::channel::<Ask<N>>(1);
        let serving = tokio::spawn(serve_asks(inbox));
        let timed = round_trips!(iters, None, ask(&asks));
        drop(asks);
        serving.await.unwrap();
        timed
    })
}

/// tokio mpsc + oneshot, both ends futures joined (`tokio::join!`) in one spawned task of a
/// current-thread runtime: tokio's nearest match to two jobs on one processor, which share
/// one task too.
pub fn tokio_join_one_task<const N: usize>(iters: u64) -> Duration {
    current_thread().block_on(async move {
        tokio::spawn(async move {
            let (asks, inbox) = mpsc::channel::<Ask<N>>(1);
            let asking = async move { round_trips!(iters, None, ask(&asks)) };
            let ((), timed) = tokio::join!(serve_asks(inbox), asking);
            timed
        })
        .await
        .unwrap()
    })
}

/// tokio mpsc + oneshot, each end a task of one `LocalSet` on a current-thread runtime: the
/// set polls its own tasks in its own queue, as a processor polls its jobs.
pub fn tokio_local_set<const N: usize>(iters: u64) -> Duration {
    let local = tokio::task::LocalSet::new();
    current_thread().block_on(local.run_until(async move {
        let (asks, inbox) = mpsc::channel::<Ask<N>>(1);
        let serving = tokio::task::spawn_local(serve_asks(inbox));
        let asking = tokio::task::spawn_local(async move { round_trips!(iters, None, ask(&asks)) });
        let timed = asking.await.unwrap();
        serving.await.unwrap();
        timed
    }))
}

/// tokio mpsc + oneshot across threads, placed as [`imrs_cross_thread`]: the server on a
/// current-thread runtime of its own thread, the asker on one of the calling thread.
pub fn tokio_ask_cross_thread<const N: usize>(iters: u64, tail: Option<&mut Tail>) -> Duration {
    let (asks, inbox) = mpsc::channel::<Ask<N>>(1);
    let serving = server_thread(serve_asks(inbox));
    let timed = current_thread().block_on(async { round_trips!(iters, tail, ask(&asks)) });
    drop(asks);
    serving.join().unwrap();
    timed
}

/// kameo's `ask`, the actor on the same current-thread runtime as the asker.
pub fn kameo_ask_current_thread<const N: usize>(iters: u64) -> Duration {
    current_thread().block_on(async move {
        let server = peers::kameo_server();
        let timed = peers::kameo_asks::<N>(&server, iters).await;
        server.kill();
        timed
    })
}

/// ractor's `call!`, the actor on the same current-thread runtime as the caller.
pub fn ractor_call_current_thread<const N: usize>(iters: u64) -> Duration {
    current_thread().block_on(async move {
        let server = peers::ractor_server::<N>().await;
        let timed = peers::ractor_calls::<N>(&server, iters).await;
        server.stop(None);
        timed
    })
}

/// Runs `start` (which spawns an actor and returns its reference) on a current-thread
/// runtime in a thread of its own, and keeps that runtime running until the returned sender
/// is dropped or sent to: the actor's side of a cross-thread round trip.
fn actor_thread<A: Send + 'static, F: Future<Output = A> + Send + 'static>(
    start: impl FnOnce() -> F + Send + 'static,
) -> (A, oneshot::Sender<()>, thread::JoinHandle<()>) {
    let (started, actor) = std::sync::mpsc::channel();
    let (stop, stopped) = oneshot::channel::<()>();
    let serving = server_thread(async move {
        started
            .send(start().await)
            .expect("the asker waits for the actor");
        let _ = stopped.await;
    });
    let actor = actor.recv().expect("the actor starts");
    (actor, stop, serving)
}

/// kameo's `ask` across threads, placed as [`imrs_cross_thread`]: the actor on a
/// current-thread runtime of its own thread, the asker on one of the calling thread.
pub fn kameo_ask_cross_thread<const N: usize>(iters: u64) -> Duration {
    let (server, stop, serving) = actor_thread(|| async { peers::kameo_server() });
    let timed = current_thread().block_on(peers::kameo_asks::<N>(&server, iters));
    server.kill();
    drop(stop);
    serving.join().unwrap();
    timed
}

/// ractor's `call!` across threads, placed as [`imrs_cross_thread`]: the actor on a
/// current-thread runtime of its own thread, the caller on one of the calling thread.
pub fn ractor_call_cross_thread<const N: usize>(iters: u64) -> Duration {
    let (server, stop, serving) = actor_thread(peers::ractor_server::<N>);
    let timed = current_thread().block_on(peers::ractor_calls::<N>(&server, iters));
    server.stop(None);
    drop(stop);
    serving.join().unwrap();
    timed
}

/// crossbeam channels, ping-pong between two threads.
pub fn crossbeam_ping_pong<const N: usize>(iters: u64) -> Duration {
    let (ping, pinged) = crossbeam_channel::bounded::<[u8; N]>(1);
    let (pong, ponged) = crossbeam_channel::bounded::<u64>(1);
    let serving = thread::spawn(move || {
        for message in pinged.iter() {
            pong.send(u64::from(message[0])).unwrap();
        }
    });
    let start = Instant::now();
    for _ in 0..iters {
        ping.send(black_box([1u8; N])).unwrap();
        black_box(ponged.recv().unwrap());
    }
    let timed = start.elapsed();
    drop(ping);
    serving.join().unwrap();
    timed
}

/// Two threads spinning on one atomic: the cache-line floor of a cross-thread round trip.
pub fn atomic_spin_ping_pong(iters: u64, mut tail: Option<&mut Tail>) -> Duration {
    let turn = Arc::new(AtomicU64::new(0));
    let other = Arc::clone(&turn);
    let serving = thread::spawn(move || {
        for round in 0..iters {
            while other.load(Ordering::Acquire) != 2 * round + 1 {
                std::hint::spin_loop();
            }
            other.store(2 * round + 2, Ordering::Release);
        }
    });
    let start = Instant::now();
    for round in 0..iters {
        let one = tail.is_some().then(Instant::now);
        turn.store(2 * round + 1, Ordering::Release);
        while turn.load(Ordering::Acquire) != 2 * round + 2 {
            std::hint::spin_loop();
        }
        if let (Some(tail), Some(one)) = (tail.as_deref_mut(), one) {
            tail.push(one.elapsed());
        }
    }
    let timed = start.elapsed();
    serving.join().unwrap();
    timed
}

/// What the two threads of [`atomic_spin_ping_pong_payload`] share: the turn word, the
/// answer and the message side by side from the start of a cache line, so that an 8-byte
/// message travels on the line that hands over the turn, as it would in a channel slot
/// built for it.
#[repr(C, align(64))]
struct Handover<const N: usize> {
    turn: AtomicU64,
    answer: AtomicU64,
    message: UnsafeCell<[u8; N]>,
}

// SAFETY: `message` is written only by the asker while the turn is even (the server's) and
// read only by the server while it is odd; the Release store and Acquire load of `turn`
// order each write before the read that follows it, so no access to it races.
unsafe impl<const N: usize> Sync for Handover<N> {}

/// [`atomic_spin_ping_pong`] that also moves an `N`-byte request and a `u64` answer, as a
/// TIGHT port does: the asker writes the message before its Release store of the turn, the
/// server copies it out after its Acquire load, and answers with its first byte. The fair
/// floor for a TIGHT round trip of that size.
pub fn atomic_spin_ping_pong_payload<const N: usize>(iters: u64) -> Duration {
    let shared = Arc::new(Handover::<N> {
        turn: AtomicU64::new(0),
        answer: AtomicU64::new(0),
        message: UnsafeCell::new([0; N]),
    });
    let other = Arc::clone(&shared);
    let serving = thread::spawn(move || {
        for round in 0..iters {
            while other.turn.load(Ordering::Acquire) != 2 * round + 1 {
                std::hint::spin_loop();
            }
            // SAFETY: the turn is odd, the asker's write happened before it (Acquire above)
            // and it writes no more until the turn is even again (see `Handover`).
            let message = black_box(unsafe { other.message.get().read() });
            other.answer.store(u64::from(message[0]), Ordering::Relaxed);
            other.turn.store(2 * round + 2, Ordering::Release);
        }
    });
    let start = Instant::now();
    for round in 0..iters {
        // SAFETY: the turn is even: the server read the last message before it handed the
        // turn back (Acquire below, or the start), and reads no more until it is odd.
        unsafe { shared.message.get().write(black_box([1u8; N])) };
        shared.turn.store(2 * round + 1, Ordering::Release);
        while shared.turn.load(Ordering::Acquire) != 2 * round + 2 {
            std::hint::spin_loop();
        }
        black_box(shared.answer.load(Ordering::Relaxed));
    }
    let timed = start.elapsed();
    serving.join().unwrap();
    timed
}
