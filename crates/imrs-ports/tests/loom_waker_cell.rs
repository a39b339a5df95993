//! A loom model of the waker cell: the very `src/waker_cell.rs` that ships, compiled against
//! loom's atomics and cells, and checked under every interleaving loom explores. A lost
//! wake leaves a `block_on` waiting for ever, which loom reports as a deadlock.
//!
//! The waiting side is driven by `support/loom_block_on.rs`, whose waker's clones wake the
//! same task by `Waker::will_wake`, as the processor's and tokio's do, so that the model
//! follows the path the ports take: the waker kept in the cell, woken by reference.
#![allow(dead_code, unreachable_pub)]

/// What `waker_cell.rs` reaches as `crate::loom`: loom's versions of the primitives.
mod loom {
    pub(crate) use ::loom::cell::UnsafeCell;
    pub(crate) use ::loom::sync::atomic::{AtomicUsize, Ordering};
}

#[path = "support/loom_block_on.rs"]
mod loom_block_on;
#[path = "../src/waker_cell.rs"]
mod waker_cell;

use std::future::poll_fn;
use std::task::Poll;

use ::loom::sync::Arc;
use ::loom::sync::atomic::{AtomicUsize, Ordering};
use ::loom::thread;
use loom_block_on::block_on;
use waker_cell::WakerCell;

/// A count of messages posted, and the cell the waiting side leaves its waker in.
struct Line {
    posted: AtomicUsize,
    cell: WakerCell,
}

impl Line {
    fn new() -> Arc<Self> {
        Arc::new(Self {
            posted: AtomicUsize::new(0),
            cell: WakerCell::new(),
        })
    }

    /// The poster's side: a message, then the wake.
    fn post(&self) {
        self.posted.fetch_add(1, Ordering::Release);
        self.cell.wake();
    }

    /// The waiting side: until `count` messages are posted, registered meanwhile, with a
    /// look after the registration as every port's poll makes.
    fn wait_for(&self, count: usize) {
        block_on(self.posted_at_least(count));
    }

    /// The wait of [`Line::wait_for`], as a future.
    async fn posted_at_least(&self, count: usize) {
        poll_fn(|cx| {
            if self.posted.load(Ordering::Acquire) >= count {
                return Poll::Ready(());
            }
            self.cell.register(cx.waker());
            if self.posted.load(Ordering::Acquire) >= count {
                Poll::Ready(())
            } else {
                Poll::Pending
            }
        })
        .await;
    }
}

#[test]
fn a_wake_racing_the_registration_is_never_lost() {
    ::loom::model(|| {
        let line = Line::new();
        let poster = {
            let line = Arc::clone(&line);
            thread::spawn(move || line.post())
        };
        line.wait_for(1);
        poster.join().unwrap();
    });
}

#[test]
fn two_wakes_at_once_lose_neither_message() {
    // The second wake may find the first still waking and leave: the waiting side must
    // still see both messages. Three threads: bounded to two preemptions, loom's own advice
    // for models of this size, which covers the wake that is preempted while it reads.
    let mut builder = ::loom::model::Builder::new();
    builder.preemption_bound = Some(2);
    builder.check(|| {
        let line = Line::new();
        let posters: Vec<_> = (0..2)
            .map(|_| {
                let line = Arc::clone(&line);
                thread::spawn(move || line.post())
            })
            .collect();
        line.wait_for(2);
        for poster in posters {
            poster.join().unwrap();
        }
    });
}

#[test]
fn a_waker_kept_in_place_is_woken_again_next_round() {
    // The same task waits twice: the second registration keeps the first one's waker, and
    // the second message still wakes it.
    let mut builder = ::loom::model::Builder::new();
    builder.preemption_bound = Some(3);
    builder.check(|| {
        let line = Line::new();
        let poster = {
            let line = Arc::clone(&line);
            thread::spawn(move || {
                line.post();
                line.post();
            })
        };
        // One task, so one waker, for both waits.
        block_on(async {
            line.posted_at_least(1).await;
            line.posted_at_least(2).await;
        });
        poster.join().unwrap();
    });
}
