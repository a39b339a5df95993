//! The round-trip drivers of the rendezvous benches: IMRS on one processor, on two tasks,
//! across threads and on TIGHT ports; tokio mpsc + oneshot asks, kameo, ractor, crossbeam
//! and atomic spins as baselines. Shared by `benches/rendezvous.rs` and the
//! `cross_thread_runs` program.

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
/// and each one into `$tail` when there is one.
macro_rules! round_trips {
    ($iters:expr, $tail:expr, $round_trip:expr) => {{
        let mut tail: Option<&mut Tail> = $tail;
        let start = Instant::now();
        for _ in 0..$iters {
            let one = Instant::now();
            black_box($round_trip.await.unwrap());
            if let Some(tail) = tail.as_deref_mut() {
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

/// imrs, each end a tokio task of its own on one current-thread runtime.
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

/// imrs, the receiver on its own thread (parked between messages, or spinning on TIGHT).
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
    let serving = thread::spawn(move || {
        current_thread().block_on(async move {
            for _ in 0..iters {
                let (message, reply) = server.receive().await.unwrap();
                reply.reply(u64::from(message[0]));
            }
        })
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

/// tokio mpsc + oneshot, server task on the same current-thread runtime.
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

/// tokio mpsc + oneshot, server on a multi-thread runtime, asked from another thread.
pub fn tokio_ask_multi_thread<const N: usize>(iters: u64, tail: Option<&mut Tail>) -> Duration {
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()
        .unwrap();
    let (asks, inbox) = mpsc::channel::<Ask<N>>(1);
    runtime.spawn(serve_asks(inbox));
    current_thread().block_on(async { round_trips!(iters, tail, ask(&asks)) })
}

/// kameo's `ask`, the actor on the same current-thread runtime.
pub fn kameo_ask_current_thread<const N: usize>(iters: u64) -> Duration {
    current_thread().block_on(async move {
        let server = peers::kameo_server();
        let timed = peers::kameo_asks::<N>(&server, iters).await;
        server.kill();
        timed
    })
}

/// ractor's `call!`, the actor on the same current-thread runtime.
pub fn ractor_call_current_thread<const N: usize>(iters: u64) -> Duration {
    current_thread().block_on(async move {
        let server = peers::ractor_server::<N>().await;
        let timed = peers::ractor_calls::<N>(&server, iters).await;
        server.stop(None);
        timed
    })
}

/// A one-worker multi-thread runtime for the server side of the cross-thread peers.
pub fn server_runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()
        .unwrap()
}

/// kameo's `ask`, the actor on a multi-thread runtime, asked from another thread.
pub fn kameo_ask_multi_thread<const N: usize>(iters: u64) -> Duration {
    let runtime = server_runtime();
    let server = runtime.block_on(async { peers::kameo_server() });
    let timed = current_thread().block_on(peers::kameo_asks::<N>(&server, iters));
    server.kill();
    timed
}

/// ractor's `call!`, the actor on a multi-thread runtime, called from another thread.
pub fn ractor_call_multi_thread<const N: usize>(iters: u64) -> Duration {
    let runtime = server_runtime();
    let server = runtime.block_on(peers::ractor_server::<N>());
    let timed = current_thread().block_on(peers::ractor_calls::<N>(&server, iters));
    server.stop(None);
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
        let one = Instant::now();
        turn.store(2 * round + 1, Ordering::Release);
        while turn.load(Ordering::Acquire) != 2 * round + 2 {
            std::hint::spin_loop();
        }
        if let Some(tail) = tail.as_deref_mut() {
            tail.push(one.elapsed());
        }
    }
    let timed = start.elapsed();
    serving.join().unwrap();
    timed
}

/// [`atomic_spin_ping_pong`] that also moves an `N`-byte request, as a TIGHT port does: the
/// asker writes it word by word before it hands over the turn, the server reads it all back
/// before it answers. The fair floor for a TIGHT round trip of that size.
pub fn atomic_spin_ping_pong_payload<const N: usize>(iters: u64) -> Duration {
    let words = N.div_ceil(8);
    let shared = Arc::new((
        AtomicU64::new(0),
        (0..words).map(|_| AtomicU64::new(0)).collect::<Vec<_>>(),
    ));
    let other = Arc::clone(&shared);
    let serving = thread::spawn(move || {
        let (turn, payload) = &*other;
        let mut read = vec![0u64; payload.len()];
        for round in 0..iters {
            while turn.load(Ordering::Acquire) != 2 * round + 1 {
                std::hint::spin_loop();
            }
            for (into, word) in read.iter_mut().zip(payload) {
                *into = word.load(Ordering::Relaxed);
            }
            black_box(&read);
            turn.store(2 * round + 2, Ordering::Release);
        }
    });
    let (turn, payload) = &*shared;
    let message = black_box([1u8; N]);
    let start = Instant::now();
    for round in 0..iters {
        for (word, bytes) in payload.iter().zip(message.chunks(8)) {
            let mut eight = [0u8; 8];
            eight[..bytes.len()].copy_from_slice(bytes);
            word.store(u64::from_ne_bytes(eight), Ordering::Relaxed);
        }
        turn.store(2 * round + 1, Ordering::Release);
        while turn.load(Ordering::Acquire) != 2 * round + 2 {
            std::hint::spin_loop();
        }
    }
    let timed = start.elapsed();
    serving.join().unwrap();
    timed
}
