//! The slot in which one poster and one server meet: the rendezvous core.
//!
//! A poster (a sender or a querier) puts its request in, a server (a receiver or a response
//! handler) takes it out and later puts an answer in. One atomic state word decides who
//! may touch the request and reply cells; no lock is taken and nothing is allocated.
//!
//! ```text
//!  EMPTY --post--> POSTED --take--> TAKEN --reply--> REPLIED --collect--> EMPTY
//!    ^               |                |  \--no reply--> UNREPLIED --collect--> EMPTY
//!    +---withdraw----+                +--withdraw--> ABANDONED --reply/no reply--> EMPTY
//! ```
//!
//! Only one poster ever posts into a given slot (the port's types make sure of that), but
//! several servers may race to take from it: taking is a compare-and-swap.

use std::mem::MaybeUninit;
use std::task::{Context, Poll};

use crate::loom::{AtomicU8, AtomicU64, AtomicWaker, Ordering, UnsafeCell};

const EMPTY: u8 = 0;
const POSTED: u8 = 1;
const TAKEN: u8 = 2;
const REPLIED: u8 = 3;
const UNREPLIED: u8 = 4;
const ABANDONED: u8 = 5;

/// How a posted request ended, as seen by its poster.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum Answer<Rep> {
    /// The server replied.
    Replied(Rep),
    /// The server dropped the request without replying.
    Unreplied,
}

/// What a poster gets back when it gives up waiting.
#[derive(Debug, PartialEq, Eq)]
pub(crate) enum Withdrawn<Req, Rep> {
    /// No server had taken the request; here it is.
    Unsent(Req),
    /// A server holds the request; its eventual answer goes back to it.
    Abandoned,
    /// The answer came in before the poster gave up.
    Answered(Answer<Rep>),
}

pub(crate) struct Slot<Req, Rep> {
    state: AtomicU8,
    ticket: AtomicU64,
    request: UnsafeCell<MaybeUninit<Req>>,
    reply: UnsafeCell<MaybeUninit<Rep>>,
}

// SAFETY: the cells are only reached through the state machine above, which hands each cell
// to exactly one thread at a time (the poster or the one server that won `take`), with
// acquire/release ordering on every hand-over. Values cross threads, hence `Send` bounds.
unsafe impl<Req: Send, Rep: Send> Sync for Slot<Req, Rep> {}

impl<Req, Rep> Slot<Req, Rep> {
    pub(crate) fn new() -> Self {
        Self {
            state: AtomicU8::new(EMPTY),
            ticket: AtomicU64::new(0),
            request: UnsafeCell::new(MaybeUninit::uninit()),
            reply: UnsafeCell::new(MaybeUninit::uninit()),
        }
    }

    /// Whether a new request may be posted (an abandoned one may still be in a server's hands).
    pub(crate) fn is_free(&self) -> bool {
        self.state.load(Ordering::Acquire) == EMPTY
    }

    /// Poster: waits until the slot is free, registered in `poster` meanwhile.
    pub(crate) fn poll_free(&self, poster: &AtomicWaker, cx: &mut Context<'_>) -> Poll<()> {
        if self.is_free() {
            return Poll::Ready(());
        }
        poster.register_by_ref(cx.waker());
        if self.is_free() {
            Poll::Ready(())
        } else {
            Poll::Pending
        }
    }

    /// Poster: puts a request in a free slot, or hands it back if the slot is not free.
    ///
    /// # Safety
    ///
    /// The caller is the only poster of this slot.
    pub(crate) unsafe fn post(&self, request: Req, ticket: u64) -> Result<(), Req> {
        if !self.is_free() {
            return Err(request);
        }
        // SAFETY: in EMPTY no server touches the request cell, and the caller is the only
        // poster, so this thread has the cell to itself.
        self.request
            .with_mut(|cell| unsafe { (*cell).write(request) });
        self.ticket.store(ticket, Ordering::Relaxed);
        self.state.store(POSTED, Ordering::Release);
        Ok(())
    }

    /// The ticket of the waiting request, if one is waiting: lower tickets came first.
    pub(crate) fn posted_ticket(&self) -> Option<u64> {
        (self.state.load(Ordering::Acquire) == POSTED).then(|| self.ticket.load(Ordering::Relaxed))
    }

    /// Server: takes the waiting request, if there is one and no other server got it first.
    ///
    /// A server that gets `Some` must later call [`Slot::reply`] or [`Slot::unreplied`].
    pub(crate) fn take(&self) -> Option<Req> {
        self.state
            .compare_exchange(POSTED, TAKEN, Ordering::AcqRel, Ordering::Relaxed)
            .ok()?;
        // SAFETY: winning POSTED -> TAKEN hands the request cell to this server; the acquire
        // pairs with the poster's release store of POSTED, so the write is visible. The
        // poster only writes the cell again after the slot is EMPTY.
        Some(
            self.request
                .with_mut(|cell| unsafe { (*cell).assume_init_read() }),
        )
    }

    /// Server: answers the request it took, and wakes the poster registered in `poster`.
    ///
    /// # Safety
    ///
    /// The caller took the current request with [`Slot::take`] and has not answered it.
    ///
    /// Hands the reply back if the poster had given up (timed out, or its module died):
    /// nobody would read it, and the server is told so.
    pub(crate) unsafe fn reply(&self, poster: &AtomicWaker, reply: Rep) -> Result<(), Rep> {
        // SAFETY: while TAKEN or ABANDONED the reply cell belongs to the server (the poster
        // reads it only in REPLIED), and the caller is that server.
        self.reply.with_mut(|cell| unsafe { (*cell).write(reply) });
        let late =
            match self
                .state
                .compare_exchange(TAKEN, REPLIED, Ordering::AcqRel, Ordering::Acquire)
            {
                Ok(_) => None,
                Err(state) => {
                    debug_assert_eq!(state, ABANDONED);
                    // SAFETY: the poster gave up, so nobody will read the reply written just
                    // above: it is taken back, once, before the slot is emptied.
                    let late = self
                        .reply
                        .with_mut(|cell| unsafe { (*cell).assume_init_read() });
                    self.state.store(EMPTY, Ordering::Release);
                    Some(late)
                }
            };
        poster.wake();
        match late {
            None => Ok(()),
            Some(reply) => Err(reply),
        }
    }

    /// Server: drops the request it took without answering, so its poster is not left hanging.
    ///
    /// # Safety
    ///
    /// As for [`Slot::reply`].
    pub(crate) unsafe fn unreplied(&self, poster: &AtomicWaker) {
        if let Err(state) =
            self.state
                .compare_exchange(TAKEN, UNREPLIED, Ordering::AcqRel, Ordering::Acquire)
        {
            debug_assert_eq!(state, ABANDONED);
            self.state.store(EMPTY, Ordering::Release);
        }
        poster.wake();
    }

    /// Poster: the answer to its request, once there is one; frees the slot.
    ///
    /// # Safety
    ///
    /// The caller is the only poster of this slot and has a request in it.
    pub(crate) unsafe fn poll_answer(
        &self,
        poster: &AtomicWaker,
        cx: &mut Context<'_>,
    ) -> Poll<Answer<Rep>> {
        // SAFETY: forwarded from the caller.
        if let Some(answer) = unsafe { self.try_answer() } {
            return Poll::Ready(answer);
        }
        poster.register_by_ref(cx.waker());
        // SAFETY: forwarded from the caller.
        match unsafe { self.try_answer() } {
            Some(answer) => Poll::Ready(answer),
            None => Poll::Pending,
        }
    }

    /// Poster: the answer, if it has come; frees the slot when it has.
    ///
    /// # Safety
    ///
    /// As for [`Slot::poll_answer`].
    pub(crate) unsafe fn try_answer(&self) -> Option<Answer<Rep>> {
        match self.state.load(Ordering::Acquire) {
            REPLIED => {
                // SAFETY: REPLIED hands the reply cell to the poster (acquire pairs with the
                // server's release), and the caller is the poster.
                let reply = self
                    .reply
                    .with_mut(|cell| unsafe { (*cell).assume_init_read() });
                self.state.store(EMPTY, Ordering::Release);
                Some(Answer::Replied(reply))
            }
            UNREPLIED => {
                self.state.store(EMPTY, Ordering::Release);
                Some(Answer::Unreplied)
            }
            _ => None,
        }
    }

    /// Poster: takes its request back if no server has taken it; a request already taken
    /// stays with its server.
    ///
    /// # Safety
    ///
    /// As for [`Slot::poll_answer`].
    pub(crate) unsafe fn withdraw_unsent(&self) -> Option<Req> {
        self.state
            .compare_exchange(POSTED, EMPTY, Ordering::AcqRel, Ordering::Acquire)
            .ok()?;
        // SAFETY: POSTED -> EMPTY by the poster: no server took the request, and none can
        // now; the cell is the poster's again.
        Some(
            self.request
                .with_mut(|cell| unsafe { (*cell).assume_init_read() }),
        )
    }

    /// Poster: gives up on its request (a timeout, a closed port, a dropped future).
    ///
    /// # Safety
    ///
    /// As for [`Slot::poll_answer`].
    pub(crate) unsafe fn withdraw(&self) -> Withdrawn<Req, Rep> {
        loop {
            match self
                .state
                .compare_exchange(POSTED, EMPTY, Ordering::AcqRel, Ordering::Acquire)
            {
                Ok(_) => {
                    // SAFETY: POSTED -> EMPTY by the poster: no server took the request, and
                    // none can now; the cell is the poster's again.
                    let request = self
                        .request
                        .with_mut(|cell| unsafe { (*cell).assume_init_read() });
                    return Withdrawn::Unsent(request);
                }
                Err(TAKEN) => {
                    if self
                        .state
                        .compare_exchange(TAKEN, ABANDONED, Ordering::AcqRel, Ordering::Acquire)
                        .is_ok()
                    {
                        return Withdrawn::Abandoned;
                    }
                    // The server answered in between: collect the answer on the next turn.
                }
                Err(_) => {
                    // SAFETY: forwarded from the caller.
                    if let Some(answer) = unsafe { self.try_answer() } {
                        return Withdrawn::Answered(answer);
                    }
                }
            }
        }
    }
}

impl<Req, Rep> Drop for Slot<Req, Rep> {
    fn drop(&mut self) {
        // `&mut self`: no other thread can reach the slot any more.
        match self.state.load(Ordering::Acquire) {
            // SAFETY: in POSTED the request cell holds a value nobody took.
            POSTED => self
                .request
                .with_mut(|cell| unsafe { (*cell).assume_init_drop() }),
            // SAFETY: in REPLIED the reply cell holds a value nobody collected.
            REPLIED => self
                .reply
                .with_mut(|cell| unsafe { (*cell).assume_init_drop() }),
            _ => {}
        }
    }
}
