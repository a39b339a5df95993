//! The bounded buffer of GATE's FREQUENCY port: a filter that makes a blocking send
//! non-blocking.

use std::collections::VecDeque;

use super::{FilterEnds, FilteredPort};
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
#[derive(Debug)]
pub struct BoundedBuffer<T, const CAP: usize> {
    queue: VecDeque<T>,
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
    /// requests with the oldest message. Runs until the task running it is dropped.
    pub async fn run(
        mut self,
        mut ends: FilterEnds<T, (), usage::Receive, (), Option<T>, usage::Send>,
    ) {
        enum Event<T> {
            FromUser(T, ReplyHandle<()>),
            FromOwner(ReplyHandle<Option<T>>),
        }
        loop {
            let has_room = self.queue.len() < CAP;
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
                    self.queue.push_back(message);
                    let _taken = reply.reply(());
                }
                Ok(Event::FromOwner(reply)) => {
                    // An owner that gave up never reads the message: it stays first in line.
                    if let Replied::Late(Some(message)) = reply.reply(self.queue.pop_front()) {
                        self.queue.push_front(message);
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
