//! `sendall` and `callall`: the owner posts to every user and unblocks at the first answer.

use std::fmt;
use std::future::{Future, poll_fn};
use std::pin::Pin;
use std::task::{Context, Poll};

use pin_project_lite::pin_project;

use crate::attachment::Attachment;
use crate::clock::{Sleep, deadline_passed};
use crate::core::{SlotId, register_broadcast};
use crate::error::BroadcastError;
use crate::loom::Ordering;
use crate::meta::Name;
use crate::slot::{Answer, Withdrawn};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stage {
    Posting,
    Posted,
    Done,
}

pin_project! {
    /// The future of [`End::send_all`](crate::End::send_all) and
    /// [`End::call_all`](crate::End::call_all).
    #[must_use = "a broadcast does nothing unless awaited"]
    pub struct Broadcasting<'a, Req, Rep> {
        attachment: &'a Attachment<Req, Rep>,
        message: Option<Req>,
        stage: Stage,
        #[pin]
        deadline: Option<Sleep>,
    }

    impl<'a, Req, Rep> PinnedDrop for Broadcasting<'a, Req, Rep> {
        fn drop(this: Pin<&mut Self>) {
            let this = this.project();
            if *this.stage == Stage::Posted {
                withdraw_all(this.attachment);
            }
        }
    }
}

impl<'a, Req, Rep> Broadcasting<'a, Req, Rep> {
    pub(crate) fn new(attachment: &'a Attachment<Req, Rep>, message: Req) -> Self {
        Self {
            attachment,
            message: Some(message),
            stage: Stage::Posting,
            deadline: None,
        }
    }
}

/// The first answer to a broadcast, and the way to read the later ones.
///
/// While it lives the owner end stays borrowed, so no new broadcast can overwrite answers
/// still to be read; dropping it discards the answers not yet read.
pub struct Broadcast<'a, Req, Rep> {
    /// The first reply.
    pub first: Rep,
    /// The module that gave it.
    pub from: Name,
    attachment: &'a Attachment<Req, Rep>,
}

impl<'a, Req: Clone, Rep> Future for Broadcasting<'a, Req, Rep> {
    type Output = Result<Broadcast<'a, Req, Rep>, BroadcastError<Req>>;

    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Self::Output> {
        let mut this = self.project();
        let attachment = *this.attachment;
        let core = &attachment.core;
        let port = attachment.port().clone();
        if this.deadline.is_none()
            && let Some(timeout) = attachment.timeout
        {
            this.deadline.set(Some(core.clock.sleep(timeout)));
        }

        if *this.stage == Stage::Posting {
            let attached = |index: &usize| core.is_user_attached(*index);
            let users = 0..core.capacity();
            if users.clone().filter(attached).count() == 0 {
                *this.stage = Stage::Done;
                let message = this.message.take().expect("the message waits to be posted");
                return Poll::Ready(Err(BroadcastError::NoUsers { port, message }));
            }
            // Post to everyone at once, or to no one: wait for earlier, abandoned requests
            // to be done with.
            let busy = users.clone().filter(attached).find(|&index| {
                let user = &core.users[index];
                user.wakers.poster.register_by_ref(cx.waker());
                !user.slot.is_free()
            });
            if busy.is_some() {
                if deadline_passed(this.deadline.as_mut(), cx) {
                    *this.stage = Stage::Done;
                    let message = this.message.take().expect("the message waits to be posted");
                    return Poll::Ready(Err(BroadcastError::Timeout { port, message }));
                }
                return Poll::Pending;
            }
            if let Some(hand) = core.hooks().and_then(|hooks| hooks.handing.get()) {
                let message = this.message.take().expect("the message waits to be posted");
                *this.message = Some(hand(message));
            }
            let message = this
                .message
                .as_ref()
                .expect("the message waits to be posted");
            for index in users.filter(attached) {
                let user = &core.users[index];
                // SAFETY: on a SENDALL/CALLALL port the owner end is the only poster of
                // every user slot, and it is borrowed mutably by this future.
                if unsafe { user.slot.post(message.clone(), core.ticket(SlotId::Owner)) }.is_ok() {
                    user.in_broadcast.store(true, Ordering::Relaxed);
                    user.wakers.server.wake();
                }
            }
            *this.stage = Stage::Posted;
        }
        if *this.stage != Stage::Posted {
            panic!("a broadcast polled after it completed");
        }

        match poll_answers(attachment, cx) {
            Poll::Ready(Some((from, first))) => {
                *this.stage = Stage::Done;
                return Poll::Ready(Ok(Broadcast {
                    first,
                    from,
                    attachment,
                }));
            }
            Poll::Ready(None) => {
                *this.stage = Stage::Done;
                return Poll::Ready(Err(BroadcastError::NoReply { port }));
            }
            Poll::Pending => {}
        }
        if !deadline_passed(this.deadline.as_mut(), cx) {
            return Poll::Pending;
        }
        *this.stage = Stage::Done;
        withdraw_all(attachment);
        let message = this
            .message
            .take()
            .expect("the message is kept until the first reply");
        Poll::Ready(Err(BroadcastError::Timeout { port, message }))
    }
}

/// The next reply among the users still answering a broadcast; `None` when there are none.
/// Unanswered requests (dropped reply handles) are skipped.
fn poll_answers<Req, Rep>(
    attachment: &Attachment<Req, Rep>,
    cx: &mut Context<'_>,
) -> Poll<Option<(Name, Rep)>> {
    let core = &attachment.core;
    register_broadcast(core, cx.waker());
    let mut waiting = false;
    for (index, user) in core.users.iter().enumerate() {
        if !user.in_broadcast.load(Ordering::Relaxed) {
            continue;
        }
        // SAFETY: the owner end posted this request (`in_broadcast`) and is its only poster.
        match unsafe { user.slot.try_answer() } {
            Some(Answer::Replied(reply)) => {
                user.in_broadcast.store(false, Ordering::Relaxed);
                let from = core.user_module(index).unwrap_or_else(|| "?".into());
                return Poll::Ready(Some((from, reply)));
            }
            Some(Answer::Unreplied) => user.in_broadcast.store(false, Ordering::Relaxed),
            // A user that detached before taking the message, and will not come back (no
            // restart of its module is coming), will never answer it: take the message back
            // (detaching, and a module's end, wake this task). One that took it may still
            // reply through its handle, wherever that went.
            None if !core.is_user_attached(index) && !core.user_may_come_back(index) => {
                // SAFETY: the owner end posted this request (`in_broadcast`) and is its only
                // poster.
                if unsafe { user.slot.withdraw_unsent() }.is_some() {
                    user.in_broadcast.store(false, Ordering::Relaxed);
                } else {
                    waiting = true;
                }
            }
            None => waiting = true,
        }
    }
    if waiting {
        Poll::Pending
    } else {
        Poll::Ready(None)
    }
}

fn withdraw_all<Req, Rep>(attachment: &Attachment<Req, Rep>) {
    for user in attachment.core.users.iter() {
        if user.in_broadcast.swap(false, Ordering::Relaxed) {
            // SAFETY: the owner end posted this request and is its only poster.
            let withdrawn: Withdrawn<Req, Rep> = unsafe { user.slot.withdraw() };
            drop(withdrawn);
        }
    }
}

impl<Req, Rep> Broadcast<'_, Req, Rep> {
    /// The next later reply, with the module that gave it; `None` once every user has
    /// answered or dropped the message.
    pub async fn next_reply(&mut self) -> Option<(Name, Rep)> {
        poll_fn(|cx| self.poll_next_reply(cx)).await
    }

    /// A later reply that has already come, if any, without waiting.
    pub fn try_next_reply(&mut self) -> Option<(Name, Rep)> {
        let waker = std::task::Waker::noop();
        match self.poll_next_reply(&mut Context::from_waker(waker)) {
            Poll::Ready(reply) => reply,
            Poll::Pending => None,
        }
    }

    /// Polls for the next later reply; see [`Broadcast::next_reply`].
    pub fn poll_next_reply(&mut self, cx: &mut Context<'_>) -> Poll<Option<(Name, Rep)>> {
        poll_answers(self.attachment, cx)
    }
}

impl<Req, Rep> Drop for Broadcast<'_, Req, Rep> {
    fn drop(&mut self) {
        withdraw_all(self.attachment);
    }
}

impl<Req, Rep: fmt::Debug> fmt::Debug for Broadcast<'_, Req, Rep> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Broadcast")
            .field("first", &self.first)
            .field("from", &self.from)
            .finish_non_exhaustive()
    }
}
