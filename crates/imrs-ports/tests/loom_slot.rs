//! A loom model of the rendezvous slot: the very `src/slot.rs` that ships, compiled against
//! loom's atomics, cells and wakers, and checked under every interleaving loom explores.
#![allow(dead_code, unreachable_pub)]

/// What `slot.rs` reaches as `crate::loom`: loom's versions of the primitives.
mod loom {
    pub(crate) use ::loom::cell::UnsafeCell;
    pub(crate) use ::loom::future::AtomicWaker;
    pub(crate) use ::loom::sync::atomic::{AtomicU8, AtomicU64, Ordering};
}

#[path = "../src/slot.rs"]
mod slot;

use std::future::poll_fn;
use std::sync::Arc as StdArc;

use ::loom::sync::Arc;
use ::loom::thread;
use slot::{Answer, Slot, Withdrawn};

/// A slot with its poster's waker, which the port keeps on another cache line.
struct Paired {
    slot: Slot<Counted, Counted>,
    poster: ::loom::future::AtomicWaker,
}

impl Paired {
    fn new() -> Self {
        Self {
            slot: Slot::new(),
            poster: ::loom::future::AtomicWaker::new(),
        }
    }
}

impl std::ops::Deref for Paired {
    type Target = Slot<Counted, Counted>;

    fn deref(&self) -> &Self::Target {
        &self.slot
    }
}

/// A payload that counts its live copies, to catch a leak or a double drop.
#[derive(Debug)]
struct Counted(u32, StdArc<()>);

fn counted(n: u32, live: &StdArc<()>) -> Counted {
    Counted(n, StdArc::clone(live))
}

/// Takes the request, spinning politely until the poster has posted it.
fn take_eventually(slot: &Slot<Counted, Counted>) -> Counted {
    loop {
        if let Some(request) = slot.take() {
            return request;
        }
        thread::yield_now();
    }
}

#[test]
fn a_reply_reaches_the_waiting_poster() {
    ::loom::model(|| {
        let live = StdArc::new(());
        let slot = Arc::new(Paired::new());
        let server = {
            let (slot, live) = (Arc::clone(&slot), live.clone());
            thread::spawn(move || {
                let request = take_eventually(&slot);
                // SAFETY: this thread took the request and answers it once.
                let _ = unsafe { slot.slot.reply(&slot.poster, counted(request.0 + 1, &live)) };
            })
        };
        // SAFETY: this thread is the slot's only poster.
        unsafe { slot.post(counted(1, &live), 0) }.unwrap();
        // SAFETY: as above; the request is in the slot.
        let answer = ::loom::future::block_on(poll_fn(|cx| unsafe {
            slot.slot.poll_answer(&slot.poster, cx)
        }));
        match answer {
            Answer::Replied(reply) => assert_eq!(reply.0, 2),
            Answer::Unreplied => panic!("the server replied"),
        }
        server.join().unwrap();
        assert!(slot.is_free());
        drop(slot);
        assert_eq!(
            StdArc::strong_count(&live),
            1,
            "a payload leaked or was dropped twice"
        );
    });
}

#[test]
fn a_dropped_request_unblocks_the_poster() {
    ::loom::model(|| {
        let live = StdArc::new(());
        let slot = Arc::new(Paired::new());
        let server = {
            let slot = Arc::clone(&slot);
            thread::spawn(move || {
                drop(take_eventually(&slot));
                // SAFETY: this thread took the request and answers it once.
                unsafe { slot.slot.unreplied(&slot.poster) };
            })
        };
        // SAFETY: this thread is the slot's only poster.
        unsafe { slot.post(counted(1, &live), 0) }.unwrap();
        // SAFETY: as above.
        let answer = ::loom::future::block_on(poll_fn(|cx| unsafe {
            slot.slot.poll_answer(&slot.poster, cx)
        }));
        assert!(matches!(answer, Answer::Unreplied));
        server.join().unwrap();
        assert!(slot.is_free());
        drop(slot);
        assert_eq!(StdArc::strong_count(&live), 1);
    });
}

#[test]
fn a_withdrawal_racing_a_take_and_reply_loses_and_duplicates_nothing() {
    ::loom::model(|| {
        let live = StdArc::new(());
        let slot = Arc::new(Paired::new());
        // SAFETY: this thread is the slot's only poster.
        unsafe { slot.post(counted(7, &live), 0) }.unwrap();
        let server = {
            let (slot, live) = (Arc::clone(&slot), live.clone());
            thread::spawn(move || {
                let Some(request) = slot.take() else {
                    return false;
                };
                // SAFETY: this thread took the request and answers it once.
                let _ = unsafe {
                    slot.slot
                        .reply(&slot.poster, counted(request.0 * 10, &live))
                };
                true
            })
        };
        // The poster gives up (a timeout) while the server may be taking or replying.
        // SAFETY: this thread is the poster and its request is in the slot.
        let withdrawn = unsafe { slot.withdraw() };
        let served = server.join().unwrap();
        match withdrawn {
            Withdrawn::Unsent(request) => {
                assert!(!served, "a request came back that a server also got");
                assert_eq!(request.0, 7);
            }
            Withdrawn::Abandoned => assert!(served),
            Withdrawn::Answered(Answer::Replied(reply)) => {
                assert!(served);
                assert_eq!(reply.0, 70);
            }
            Withdrawn::Answered(Answer::Unreplied) => panic!("the server always replies"),
        }
        // Whatever happened, the slot is free for the next request once the server is done.
        assert!(slot.is_free());
        drop(slot);
        assert_eq!(
            StdArc::strong_count(&live),
            1,
            "a payload leaked or was dropped twice"
        );
    });
}

#[test]
fn two_servers_never_both_take_one_request() {
    ::loom::model(|| {
        let live = StdArc::new(());
        let slot = Arc::new(Paired::new());
        // SAFETY: this thread is the slot's only poster.
        unsafe { slot.post(counted(1, &live), 0) }.unwrap();
        let servers: Vec<_> = (0..2)
            .map(|_| {
                let slot = Arc::clone(&slot);
                thread::spawn(move || {
                    let request = slot.take()?;
                    // SAFETY: this thread took the request and answers it once.
                    unsafe { slot.slot.unreplied(&slot.poster) };
                    Some(request.0)
                })
            })
            .collect();
        let takers: Vec<_> = servers
            .into_iter()
            .filter_map(|server| server.join().unwrap())
            .collect();
        assert_eq!(takers, [1]);
        // SAFETY: this thread is the poster and its request is in the slot.
        let answer = unsafe { slot.try_answer() };
        assert!(matches!(answer, Some(Answer::Unreplied)));
        drop(slot);
        assert_eq!(StdArc::strong_count(&live), 1);
    });
}
