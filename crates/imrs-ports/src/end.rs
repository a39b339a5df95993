//! Port ends: what a module holds to use a port. An end has only the methods of its usage.

use std::fmt;
use std::marker::PhantomData;
use std::time::Duration;

use crate::attachment::Attachment;
use crate::broadcast::Broadcasting;
use crate::meta::Name;
use crate::post::{Posting, QueryOutcome, SendOutcome};
use crate::priority::Priority;
use crate::receive::{Receiving, ReplyHandle};
use crate::shared::{LoanError, Shared};
use crate::shown::Shown;
use crate::usage::{CallsAll, Queries, Receives, Sends, SendsAll, Usage};

/// One end of a port, owner's or user's, with usage `U`.
///
/// Built by [`Port::owner`](crate::Port::owner), [`Port::user`](crate::Port::user) or the
/// [`Wiring`](crate::Wiring). Dropping it detaches it: the port stays, and a new copy of the
/// module can attach in its place.
pub struct End<Req, Rep, U: Usage> {
    pub(crate) attachment: Attachment<Req, Rep>,
    _usage: PhantomData<fn() -> U>,
}

impl<Req: Send + 'static, Rep: Send + 'static, U: Usage> End<Req, Rep, U> {
    pub(crate) fn new(attachment: Attachment<Req, Rep>) -> Self {
        Self {
            attachment,
            _usage: PhantomData,
        }
    }

    /// Sets this end's timeout (the seed's `TIMEOUT=` owner or user option).
    pub fn with_timeout(mut self, timeout: Duration) -> Self {
        self.attachment.timeout = Some(timeout);
        self
    }

    /// The timeout of this end's primitives, if it has one.
    pub fn timeout(&self) -> Option<Duration> {
        self.attachment.timeout
    }

    /// See [`EndTransport::park_waits`](crate::transport::EndTransport::park_waits).
    pub(crate) fn set_parked(&mut self) {
        self.attachment.parked = true;
    }

    /// The port's name.
    pub fn port(&self) -> &Name {
        self.attachment.port()
    }

    /// The module holding this end.
    pub fn module(&self) -> &Name {
        &self.attachment.module
    }

    /// The modules at the other end of the port: the owner, seen from a user; the attached
    /// users, seen from the owner.
    pub fn peers(&self) -> Vec<Name> {
        self.attachment.peers()
    }

    /// Waits until a module is attached at the other end of the port: for the owner, until
    /// the first user attaches (a user's end always has its owner). For a transport that
    /// must not deliver a broadcast before the module it is for has attached.
    pub async fn peer_attached(&self) {
        std::future::poll_fn(|cx| self.attachment.poll_peer(cx)).await;
    }

    /// Calls `visit` with each of [`End::peers`], allocating nothing: for the paths that
    /// run at every message, such as a module's deadlock diagnosis.
    pub fn each_peer(&self, visit: impl FnMut(Name)) {
        self.attachment.each_peer(visit);
    }

    /// How the port's messages and replies are shown, if it says (see
    /// [`Port::shown`](crate::Port::shown)).
    pub fn shown(&self) -> Option<Shown<Req, Rep>> {
        self.attachment.core.shown.get().copied()
    }

    /// The port's priority, used by [`select`](crate::select()).
    pub fn priority(&self) -> Priority {
        self.attachment.core.meta.priority
    }

    /// `SEND`: sends `message` and waits until the receiver replies; returns the reply.
    ///
    /// On a timeout or a closed port an undelivered message comes back in the error.
    pub fn send(&mut self, message: Req) -> Posting<'_, Req, Rep, SendOutcome>
    where
        U: Sends,
    {
        Posting::new(&self.attachment, message)
    }

    /// `RECEIVE`: waits for a sender; returns its message and the handle to reply with.
    ///
    /// Several replies may be pending at once, and a handle may be moved to another task.
    pub fn receive(&mut self) -> Receiving<'_, Req, Rep>
    where
        U: Receives,
    {
        Receiving::new(&self.attachment)
    }

    /// Takes a waiting message without blocking, if there is one.
    pub fn try_receive(&mut self) -> Option<(Req, ReplyHandle<Rep>)>
    where
        U: Receives,
    {
        let (message, from) = self.attachment.try_take()?;
        Some((message, ReplyHandle::new(&self.attachment, from)))
    }

    /// How many senders wait for this end to receive them.
    pub fn waiting(&self) -> usize
    where
        U: Receives,
    {
        self.attachment.waiting()
    }

    /// `QUERY`: runs the response handler at the other end and waits for its answer.
    ///
    /// When the handler runs is up to the responding module's order.
    pub fn query(&mut self, query: Req) -> Posting<'_, Req, Rep, QueryOutcome>
    where
        U: Queries,
    {
        Posting::new(&self.attachment, query)
    }

    /// `SENDALL`: sends `message` to every user; returns at the first reply, and the later
    /// replies stay readable through the returned [`Broadcast`](crate::Broadcast).
    pub fn send_all(&mut self, message: Req) -> Broadcasting<'_, Req, Rep>
    where
        U: SendsAll,
        Req: Clone,
    {
        Broadcasting::new(&self.attachment, message)
    }

    /// `CALLALL`: queries every user's response handler; returns at the first answer, and
    /// the later answers stay readable through the returned [`Broadcast`](crate::Broadcast).
    pub fn call_all(&mut self, query: Req) -> Broadcasting<'_, Req, Rep>
    where
        U: CallsAll,
        Req: Clone,
    {
        Broadcasting::new(&self.attachment, query)
    }
}

impl<Req, Rep, U: Usage> fmt::Debug for End<Req, Rep, U> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("End")
            .field("port", self.attachment.port())
            .field("module", &self.attachment.module)
            .field("usage", &U::KIND)
            .field("owner", &self.attachment.is_owner())
            .finish()
    }
}

impl<T: Default + Send + 'static, Rep: Send + 'static, U: Usage> End<Shared<T>, Rep, U> {
    /// A message to build in place and send: in the memory the port's transport lends
    /// ([`Port::lend_with`](crate::transport::PortTransport::lend_with)) — shared memory, for a port that
    /// crosses processes — or, in one process, on the heap. It starts as `T::default()`
    /// (all zeros, for a message that crosses processes). Refused, naming the port, when the
    /// transport has no memory left: every loan and every request out.
    pub fn loan(&self) -> Result<Shared<T>, LoanError> {
        match self
            .attachment
            .core
            .hooks()
            .and_then(|hooks| hooks.lender.get())
        {
            Some(lender) => lender(),
            None => Ok(Shared::default()),
        }
    }
}
