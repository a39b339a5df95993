//! The server's side of send/receive/reply: `receive` and the reply handle.

use std::fmt;
use std::future::Future;
use std::pin::Pin;
use std::sync::Arc;
use std::task::{Context, Poll};

use pin_project_lite::pin_project;

use crate::attachment::Attachment;
use crate::clock::{Sleep, deadline_passed};
use crate::core::{Core, SlotId};
use crate::error::ReceiveError;
use crate::meta::Name;
use crate::urgency::wake_at;

pin_project! {
    /// The future of [`End::receive`](crate::End::receive).
    ///
    /// Dropping it before it completes takes nothing: a message can only be lost by a
    /// receive that returned it.
    #[must_use = "a receive does nothing unless awaited"]
    pub struct Receiving<'a, Req, Rep> {
        attachment: &'a Attachment<Req, Rep>,
        #[pin]
        deadline: Option<Sleep>,
    }
}

impl<'a, Req, Rep> Receiving<'a, Req, Rep> {
    pub(crate) fn new(attachment: &'a Attachment<Req, Rep>) -> Self {
        Self {
            attachment,
            deadline: None,
        }
    }

    /// The port received on.
    #[inline]
    pub fn port(&self) -> &Name {
        self.attachment.port()
    }
}

impl<Req: Send + 'static, Rep: Send + 'static> Future for Receiving<'_, Req, Rep> {
    type Output = Result<(Req, ReplyHandle<Rep>), ReceiveError>;

    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Self::Output> {
        let mut this = self.project();
        let attachment = *this.attachment;
        if this.deadline.is_none()
            && let Some(timeout) = attachment.timeout
        {
            this.deadline
                .set(Some(attachment.core.clock.sleep(timeout)));
        }
        match poll_take(attachment, cx) {
            Poll::Ready((message, from)) => {
                return Poll::Ready(Ok((message, ReplyHandle::new(attachment, from))));
            }
            Poll::Pending => {}
        }
        // The port's name is cloned only for an error: a clone is two atomic operations.
        let port = || attachment.port().clone();
        if let Some(gone) = attachment.peer_gone() {
            return Poll::Ready(Err(ReceiveError::gone(attachment.port(), gone)));
        }
        if deadline_passed(this.deadline, cx) {
            Poll::Ready(Err(ReceiveError::Timeout { port: port() }))
        } else {
            Poll::Pending
        }
    }
}

/// Takes the oldest waiting request for `attachment` to serve, registering the task to be
/// woken if there is none yet. Spins first on a TIGHT port.
pub(crate) fn poll_take<Req, Rep>(
    attachment: &Attachment<Req, Rep>,
    cx: &mut Context<'_>,
) -> Poll<(Req, SlotId)> {
    let spins = attachment.spins();
    for _ in 0..=spins {
        if let Some(taken) = attachment.try_take() {
            return Poll::Ready(taken);
        }
        if spins > 0 {
            attachment.pump();
        }
        std::hint::spin_loop();
    }
    if spins > 0 {
        attachment.parking();
    }
    attachment.register_server(cx);
    // A post between the last look and the registration would have found no waker.
    match attachment.try_take() {
        Some(taken) => Poll::Ready(taken),
        None => Poll::Pending,
    }
}

/// Where a reply goes: the slot of the request it answers. Erases the request type, so that
/// a reply handle is typed by its reply alone.
trait ReplyTarget<Rep>: Send + Sync {
    fn reply(&self, to: SlotId, reply: Rep) -> Result<(), Rep>;
    fn unreplied(&self, to: SlotId);
    fn port(&self) -> &Name;
}

impl<Req: Send, Rep: Send> ReplyTarget<Rep> for Core<Req, Rep> {
    fn reply(&self, to: SlotId, reply: Rep) -> Result<(), Rep> {
        // A reply is a message too: its wake is lifted to the port's priority.
        let mut delivered = Ok(());
        wake_at(self.meta.priority, || {
            // SAFETY: a reply handle exists only for a request taken from slot `to`, and it
            // is consumed by its first answer, so this is the one answer of the server that
            // took it.
            delivered = unsafe { self.slot(to).reply(self.poster(to), reply) };
        });
        delivered
    }

    fn unreplied(&self, to: SlotId) {
        // SAFETY: as in `reply`.
        unsafe { self.slot(to).unreplied(self.poster(to)) }
    }

    fn port(&self) -> &Name {
        &self.meta.name
    }
}

/// What became of a reply ([`ReplyHandle::reply`]).
///
/// Not `must_use`: most replies need no follow-up, and a late one is also in the sender's
/// own error ([`SendError::Timeout`](crate::SendError::Timeout)). A replier whose reply
/// carries something that must not be lost (a granted resource) looks.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Replied<Rep> {
    /// The sender was still waiting, and has the reply.
    Delivered,
    /// The sender had given up (timed out, or its module died): nobody reads this reply,
    /// which is handed back.
    Late(Rep),
}

impl<Rep> Replied<Rep> {
    /// Whether the sender got the reply.
    pub fn is_delivered(&self) -> bool {
        matches!(self, Self::Delivered)
    }
}

/// The seed's runtime task id: the right to reply, once, to one received message.
///
/// It may be kept while other messages are received, and moved to another task. Replying
/// never blocks. Dropping it without a reply fails the sender at once with
/// [`SendError::NoReply`](crate::SendError::NoReply), so nothing hangs.
#[must_use = "reply to the sender, or it receives SendError::NoReply"]
pub struct ReplyHandle<Rep> {
    target: Option<Arc<dyn ReplyTarget<Rep>>>,
    to: SlotId,
}

impl<Rep: Send + 'static> ReplyHandle<Rep> {
    pub(crate) fn new<Req: Send + 'static>(attachment: &Attachment<Req, Rep>, to: SlotId) -> Self {
        let target: Arc<dyn ReplyTarget<Rep>> = attachment.core.clone();
        Self {
            target: Some(target),
            to,
        }
    }

    /// `REPLY`: answers the sender and unblocks it. Never blocks.
    ///
    /// Says whether the sender got the reply: a sender that gave up first (its timeout
    /// fired, or its module died) never reads it, and the reply comes back as
    /// [`Replied::Late`] so that the replier can tell, and keep or undo what it did.
    pub fn reply(mut self, reply: Rep) -> Replied<Rep> {
        let target = self
            .target
            .take()
            .expect("a reply handle holds its target until it is consumed");
        match target.reply(self.to, reply) {
            Ok(()) => Replied::Delivered,
            Err(reply) => Replied::Late(reply),
        }
    }

    /// The port the message came through.
    pub fn port(&self) -> &Name {
        self.target
            .as_ref()
            .expect("a reply handle holds its target until it is consumed")
            .port()
    }
}

impl<Rep> Drop for ReplyHandle<Rep> {
    fn drop(&mut self) {
        if let Some(target) = self.target.take() {
            target.unreplied(self.to);
        }
    }
}

impl<Rep> fmt::Debug for ReplyHandle<Rep> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut debug = f.debug_struct("ReplyHandle");
        if let Some(target) = &self.target {
            debug.field("port", target.port());
        }
        debug.field("to", &self.to).finish()
    }
}
