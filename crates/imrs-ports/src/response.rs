//! Response ends: the handler side of query/response, and the hook that decides when a
//! handler may run.
//!
//! A response handler is a plain function of `(&State, Query) -> Reply`: it reads its
//! module's state and cannot change it. *When* it runs is the responding module's business:
//! its order scheduler looks at [`ResponseEnd::is_pending`] and calls
//! [`ResponseEnd::respond`] when the handler's rank allows. Without a scheduler,
//! [`respond_while`] runs handlers as soon as the module's background code is suspended.

use std::fmt;
use std::future::{Future, poll_fn};
use std::pin::pin;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError, TryLockError};
use std::task::{Context, Poll};
use std::time::Duration;

use crate::attachment::Attachment;
use crate::clock::deadline_passed;
use crate::error::ReceiveError;
use crate::meta::Name;
use crate::presence::Presence;
use crate::priority::Priority;
use crate::receive::{Replied, ReplyHandle};

type Handler<S, Req, Rep> = Box<dyn Fn(&S, Req) -> Rep + Send + Sync>;

/// The end of a port that answers queries with a response handler (`USAGE=RESPONSE`).
///
/// Built only together with its handler: [`Port::answer`](crate::Port::answer).
pub struct ResponseEnd<Req, Rep, S> {
    attachment: Attachment<Req, Rep>,
    handler: Handler<S, Req, Rep>,
}

impl<Req: Send + 'static, Rep: Send + 'static, S> ResponseEnd<Req, Rep, S> {
    pub(crate) fn new(attachment: Attachment<Req, Rep>, handler: Handler<S, Req, Rep>) -> Self {
        Self {
            attachment,
            handler,
        }
    }

    /// Sets this end's timeout: how long [`ResponseEnd::serve`] waits for a query.
    pub fn with_timeout(mut self, timeout: Duration) -> Self {
        self.attachment.timeout = Some(timeout);
        self
    }

    /// The port's name.
    pub fn port(&self) -> &Name {
        self.attachment.port()
    }

    /// The module holding this end.
    pub fn module(&self) -> &Name {
        &self.attachment.module
    }

    /// The modules that may query this end; see [`End::peers`](crate::End::peers).
    pub fn peers(&self) -> Vec<Name> {
        self.attachment.peers()
    }

    /// The port's priority.
    pub fn priority(&self) -> Priority {
        self.attachment.core.meta.priority
    }

    /// Whether a query waits for this handler.
    pub fn is_pending(&self) -> bool {
        self.attachment.has_waiting()
    }

    /// Ready when a query waits for this handler; otherwise registers the task to be woken
    /// when one arrives. Fails when nobody can ever query this port again.
    pub fn poll_pending(&mut self, cx: &mut Context<'_>) -> Poll<Result<(), ReceiveError>> {
        if self.is_pending() {
            return Poll::Ready(Ok(()));
        }
        self.attachment.register_server(cx);
        if self.is_pending() {
            Poll::Ready(Ok(()))
        } else if let Some(gone) = self.attachment.peer_gone() {
            Poll::Ready(Err(ReceiveError::gone(self.port(), gone)))
        } else {
            Poll::Pending
        }
    }

    /// The hook the order scheduler drives: runs the handler on the oldest waiting query,
    /// reading `state`, and sends its answer. Says whether a query waited, and whether its
    /// querier was still there to read the answer.
    ///
    /// If the handler panics, the querier gets
    /// [`QueryError::NoResponse`](crate::QueryError::NoResponse) instead of hanging.
    pub fn respond(&mut self, state: &S) -> Served {
        let Some((query, from)) = self.attachment.try_take() else {
            return Served::Idle;
        };
        // Built before the handler runs, so that a panic in it drops the handle unanswered.
        let handle = ReplyHandle::new(&self.attachment, from);
        match handle.reply((self.handler)(state, query)) {
            Replied::Delivered => Served::Answered,
            Replied::Late(_) => Served::Late,
        }
    }

    /// Takes the oldest waiting query without running the handler, with the right to answer
    /// it later: for a transport that answers from elsewhere (another process). Dropping the
    /// handle unanswered fails the querier with
    /// [`QueryError::NoResponse`](crate::QueryError::NoResponse), as a panicking handler
    /// does.
    pub fn take(&mut self) -> Option<(Req, ReplyHandle<Rep>)> {
        let (query, from) = self.attachment.try_take()?;
        Some((query, ReplyHandle::new(&self.attachment, from)))
    }

    /// Waits for one query (up to this end's timeout) and answers it: for a module that has
    /// nothing else to do.
    pub async fn serve(&mut self, state: &S) -> Result<(), ReceiveError> {
        let clock = &self.attachment.core.clock;
        let mut deadline = pin!(self.attachment.timeout.map(|timeout| clock.sleep(timeout)));
        poll_fn(|cx| {
            if let Poll::Ready(ready) = self.poll_pending(cx) {
                return Poll::Ready(ready);
            }
            if deadline_passed(deadline.as_mut(), cx) {
                Poll::Ready(Err(ReceiveError::Timeout {
                    port: self.port().clone(),
                }))
            } else {
                Poll::Pending
            }
        })
        .await?;
        self.respond(state);
        Ok(())
    }
}

impl<Req, Rep, S> fmt::Debug for ResponseEnd<Req, Rep, S> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("ResponseEnd")
            .field("port", self.attachment.port())
            .field("module", &self.attachment.module)
            .finish_non_exhaustive()
    }
}

/// What one turn of a response handler did ([`ResponseEnd::respond`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Served {
    /// No query waited.
    Idle,
    /// A query was answered, and its querier has the answer.
    Answered,
    /// A query was answered, but its querier had given up (timed out, or its module died):
    /// nobody reads the answer.
    Late,
}

/// A response end as seen by whatever decides when handlers run.
#[diagnostic::on_unimplemented(
    message = "`{Self}` is not a response end answering from a state `{S}`",
    label = "expected an end built with its response handler",
    note = "build one with `Port::answer`, whose handler takes `&{S}`"
)]
pub trait Respond<S> {
    /// The port this end answers.
    fn port(&self) -> &Name;
    /// Whether a query waits, without registering for a wake; see
    /// [`ResponseEnd::is_pending`].
    fn is_pending(&self) -> bool;
    /// Ready when a query waits; see [`ResponseEnd::poll_pending`].
    fn poll_pending(&mut self, cx: &mut Context<'_>) -> Poll<Result<(), ReceiveError>>;
    /// Answers one waiting query; see [`ResponseEnd::respond`].
    fn respond(&mut self, state: &S) -> Served;
    /// Records that this end is held by the module of `presence`, for an end attached before
    /// its module ran (see [`Presence`](crate::transport::Presence)). By default, nothing.
    fn bind(&mut self, presence: &Arc<Presence>) {
        let _ = presence;
    }
}

impl<Req: Send + 'static, Rep: Send + 'static, S> Respond<S> for ResponseEnd<Req, Rep, S> {
    fn port(&self) -> &Name {
        ResponseEnd::port(self)
    }

    fn is_pending(&self) -> bool {
        ResponseEnd::is_pending(self)
    }

    fn poll_pending(&mut self, cx: &mut Context<'_>) -> Poll<Result<(), ReceiveError>> {
        ResponseEnd::poll_pending(self, cx)
    }

    fn respond(&mut self, state: &S) -> Served {
        ResponseEnd::respond(self, state)
    }

    fn bind(&mut self, presence: &Arc<Presence>) {
        self.attachment.bind(presence);
    }
}

/// A module's state, as the background code and the response handlers share it.
///
/// The background code changes it only inside [`ModuleState::update`], whose closure cannot
/// await; so at every suspension point — where handlers run — the state is whole, and the
/// handlers read it through `&S`. It is `Sync`, so a module holding it runs on any thread;
/// its lock is only ever taken by the module's own task, so it is never contended.
#[derive(Debug, Default)]
pub struct ModuleState<S>(Mutex<S>);

impl<S> ModuleState<S> {
    /// Wraps the initial state.
    pub fn new(state: S) -> Self {
        Self(Mutex::new(state))
    }

    /// Changes the state. The closure is synchronous, so no handler can run in the middle.
    ///
    /// # Panics
    ///
    /// If called from inside another `update` or `read` of the same state.
    pub fn update<R>(&self, change: impl FnOnce(&mut S) -> R) -> R {
        change(&mut self.lock())
    }

    /// Reads the state.
    ///
    /// # Panics
    ///
    /// If called from inside an `update` or `read` of the same state.
    pub fn read<R>(&self, look: impl FnOnce(&S) -> R) -> R {
        look(&self.lock())
    }

    /// Reads the state from outside its module — a test, a report — waiting for an update in
    /// progress on another thread to end. Never call it from the module's own tasks or
    /// handlers: there, use [`ModuleState::read`].
    pub fn inspect<R>(&self, look: impl FnOnce(&S) -> R) -> R {
        look(&self.0.lock().unwrap_or_else(PoisonError::into_inner))
    }

    /// The state, unwrapped.
    pub fn into_inner(self) -> S {
        self.0
            .into_inner()
            .unwrap_or_else(|poisoned| poisoned.into_inner())
    }

    fn lock(&self) -> MutexGuard<'_, S> {
        self.try_lock()
            .expect("a module's state was used from inside its own update or read")
    }

    /// The state, unless it is in the middle of an update. A panic inside an update leaves
    /// the state as the update left it, which is what the module would see next anyway.
    fn try_lock(&self) -> Option<MutexGuard<'_, S>> {
        match self.0.try_lock() {
            Ok(guard) => Some(guard),
            Err(TryLockError::Poisoned(poisoned)) => Some(poisoned.into_inner()),
            Err(TryLockError::WouldBlock) => None,
        }
    }
}

/// Runs a module's `background` code and, whenever it is suspended, runs the response
/// handlers of `ends` on every waiting query: the default moment of the seed's `query`,
/// for modules that have no order scheduler.
pub async fn respond_while<S, F: Future>(
    state: &ModuleState<S>,
    ends: &mut [&mut (dyn Respond<S> + Send)],
    background: F,
) -> F::Output {
    let mut background = pin!(background);
    poll_fn(|cx| {
        if let Poll::Ready(output) = background.as_mut().poll(cx) {
            return Poll::Ready(output);
        }
        // The background is suspended, outside any `update`: the state is whole.
        if let Some(state) = state.try_lock() {
            for end in ends.iter_mut() {
                // Answer every waiting query; a closed port just has none.
                while let Poll::Ready(Ok(())) = end.poll_pending(cx) {
                    end.respond(&state);
                }
            }
        }
        Poll::Pending
    })
    .await
}
