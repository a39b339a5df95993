//! The bounded buffer of GATE's FREQUENCY port: a filter that makes a blocking send
//! non-blocking.

use std::any::Any;
use std::collections::VecDeque;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use super::{FilterEnds, FilteredPort};
use crate::inline::ServeInline;
use crate::receive::{Replied, ReplyHandle};
use crate::select::{AllClosed, select, when};
use crate::usage;
use crate::user_list::AnyUser;

/// A port whose users' sends of `T` return as soon as the bounded buffer has room, and whose
/// owner asks the buffer for the oldest message with a `send(())`, getting `None` when the
/// buffer is empty (the Appendix's `TASK_NUM=-1`).
pub type BoundedBufferPort<T, L = AnyUser, const N: usize = 1> =
    FilteredPort<T, (), usage::Receive, (), Option<T>, usage::Send, L, N>;

/// The bounded-buffer filter task, holding up to `CAP` messages.
///
/// A full buffer is back-pressure, never a silent loss: as in the Appendix's
/// `WHEN (HEAD+1) MOD 20 <> TAIL ==> RECEIVE`, the filter stops taking users' messages
/// while it is full, so a user's send waits for room — and if the user's end has a
/// timeout, the send fails with [`SendError::Timeout`](crate::SendError::Timeout), which
/// hands the message back.
///
/// # Served in place
///
/// While the filter runs, the port serves both sides itself, in the sender's own poll,
/// with no rendezvous: a user's send is one write into the buffer while it has room to
/// spare, and the owner's request one read. The filter task's rendezvous takes what the
/// buffer cannot take in place: the message that fills its last place, the owner's request
/// while the buffer is full, every message while another user's waits in the rendezvous
/// (so that users are served in the order they came), and every post before the filter
/// runs or once it has stopped. What a sender
/// and the owner see is the same either way, with one difference for an observing cell:
/// a message served in place is logged as the user's send and the owner's, not as a
/// receive of the filter task.
#[derive(Debug)]
pub struct BoundedBuffer<T, const CAP: usize> {
    queue: VecDeque<T>,
}

/// The buffer of a running filter, shared by the filter task and the two sides of the
/// port, which serve posts from it in place.
///
/// Only the filter task's rendezvous fills the last place and empties a full buffer, so
/// its guard (`has_room`, judged before it waits) stays true while it waits: a user's
/// message written in place never takes the place the filter judged it had, and a request
/// read in place never makes room that the waiting filter would not see.
struct Buffer<T> {
    held: Mutex<Held<T>>,
}

struct Held<T> {
    /// Whether a filter runs: only then is anything served in place.
    live: bool,
    capacity: usize,
    queue: VecDeque<T>,
}

impl<T: Send + 'static> Buffer<T> {
    fn held(&self) -> MutexGuard<'_, Held<T>> {
        // Every critical section is one push, pop or look: a panic cannot leave it half-done.
        self.held.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The buffer of the filter of `ends`, installed in both sides of the port the first time
    /// a filter runs there and found again by a filter started later (a restarted task).
    fn of(ends: &FilterEnds<T, (), usage::Receive, (), Option<T>, usage::Send>) -> Arc<Self> {
        let fresh = || {
            let buffer: Arc<dyn ServeInline<T, ()>> = Arc::new(Self {
                held: Mutex::new(Held {
                    live: false,
                    capacity: 0,
                    queue: VecDeque::new(),
                }),
            });
            buffer
        };
        let users = ends
            .port
            .attachment
            .core
            .hooks_to_set()
            .inline
            .get_or_init(fresh);
        let buffer = Arc::clone(users)
            .into_any()
            .downcast::<Self>()
            .expect("only a bounded buffer serves a bounded buffer's port in place");
        let owner = ends
            .filter
            .attachment
            .core
            .hooks_to_set()
            .inline
            .get_or_init(|| Arc::clone(&buffer) as Arc<dyn ServeInline<(), Option<T>>>);
        let same = Arc::clone(owner)
            .into_any()
            .downcast::<Self>()
            .is_ok_and(|owner| Arc::ptr_eq(&owner, &buffer));
        assert!(same, "both sides of a bounded buffer serve from one buffer");
        buffer
    }
}

/// A user's send: written into the buffer while it has a place to spare.
impl<T: Send + 'static> ServeInline<T, ()> for Buffer<T> {
    fn serve(&self, message: T, another_waits: bool) -> Result<(), T> {
        let mut held = self.held();
        // The last place is the filter task's: it may have judged that it has room and be
        // taking a message from the rendezvous right now.
        let spare = held.live && held.queue.len() + 1 < held.capacity;
        // With several users, one whose message waits in the rendezvous came first.
        if !spare || another_waits {
            return Err(message);
        }
        held.queue.push_back(message);
        Ok(())
    }

    fn into_any(self: Arc<Self>) -> Arc<dyn Any + Send + Sync> {
        self
    }
}

/// The owner's request: the oldest message, or `None` when the buffer is empty.
impl<T: Send + 'static> ServeInline<(), Option<T>> for Buffer<T> {
    fn serve(&self, request: (), _: bool) -> Result<Option<T>, ()> {
        let mut held = self.held();
        // A full buffer's filter task has stopped taking users' messages and waits for
        // this very request: it is served there, so that the filter takes a waiting
        // user's message as soon as the place is made. Only the filter fills the last
        // place, so only its rendezvous ever serves a full buffer.
        if !held.live || held.queue.len() >= held.capacity {
            return Err(request);
        }
        Ok(held.queue.pop_front())
    }

    fn into_any(self: Arc<Self>) -> Arc<dyn Any + Send + Sync> {
        self
    }
}

/// Marks the buffer's filter as stopped when the filter task's future is dropped: its
/// messages go with it, as they did with a filter that held them itself.
struct Running<T: Send + 'static>(Arc<Buffer<T>>);

impl<T: Send + 'static> Drop for Running<T> {
    fn drop(&mut self) {
        let mut held = self.0.held();
        held.live = false;
        held.queue.clear();
    }
}

impl<T: Send + 'static, const CAP: usize> BoundedBuffer<T, CAP> {
    /// An empty buffer, its storage allocated once, here.
    pub fn new() -> Self {
        const { assert!(CAP > 0, "a bounded buffer needs room for one message") };
        Self {
            queue: VecDeque::with_capacity(CAP),
        }
    }

    /// How many messages wait for the owner.
    pub fn len(&self) -> usize {
        self.queue.len()
    }

    /// Whether no message waits.
    pub fn is_empty(&self) -> bool {
        self.queue.is_empty()
    }

    /// Runs the filter: takes users' messages while there is room, and answers the owner's
    /// requests with the oldest message, in place where it can (see [served in
    /// place](BoundedBuffer#served-in-place)). Runs until the task running it is dropped.
    pub async fn run(
        self,
        mut ends: FilterEnds<T, (), usage::Receive, (), Option<T>, usage::Send>,
    ) {
        enum Event<T> {
            FromUser(T, ReplyHandle<()>),
            FromOwner(ReplyHandle<Option<T>>),
        }
        let buffer = Buffer::of(&ends);
        {
            let mut held = buffer.held();
            held.live = true;
            held.capacity = CAP;
            held.queue = self.queue;
        }
        let _running = Running(Arc::clone(&buffer));
        loop {
            let has_room = buffer.held().queue.len() < CAP;
            let event = select()
                .or(when(has_room, &mut ends.port), |(message, reply)| {
                    Event::FromUser(message, reply)
                })
                .or(&mut ends.filter, |((), reply)| Event::FromOwner(reply))
                .await;
            match event {
                Ok(Event::FromUser(message, reply)) => {
                    // Kept even if the user gave up meanwhile: a sender that gives up after
                    // its message was taken is told so (`SendError::ReplyTimeout`), and the
                    // message goes on to the owner.
                    buffer.held().queue.push_back(message);
                    let _taken = reply.reply(());
                }
                Ok(Event::FromOwner(reply)) => {
                    let oldest = buffer.held().queue.pop_front();
                    // An owner that gave up never reads the message: it stays first in line.
                    if let Replied::Late(Some(message)) = reply.reply(oldest) {
                        buffer.held().queue.push_front(message);
                    }
                }
                Err(AllClosed) => unreachable!("the FILTER alternative has no guard"),
            }
        }
    }
}

impl<T: Send + 'static, const CAP: usize> Default for BoundedBuffer<T, CAP> {
    fn default() -> Self {
        Self::new()
    }
}
