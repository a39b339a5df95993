//! How a bridge asks the other host: a zenoh `get` whose reply is handed to the waiting
//! module from zenoh's own callback, so that the module wakes once, as it would for a raw
//! `get`. The bridge takes the module's next request once the query has ended, so that a
//! module has one request at a time on the other host, as in one process.

use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use imrs_ports::ReplyHandle;
use zenoh::key_expr::KeyExpr;
use zenoh::query::Reply;

use crate::message::{Message, decode, encode};

/// What a bridge needs to ask the other host.
pub(crate) struct Asking {
    pub(crate) session: zenoh::Session,
    /// Where its requests go, declared once: zenoh then carries a number, not the key.
    pub(crate) key: KeyExpr<'static>,
    /// The owner's name, the attachment of what it delivers to a module: made once, shared.
    /// A module's own requests are named by their key, and carry none.
    pub(crate) name: Option<zenoh::bytes::ZBytes>,
    pub(crate) port: Arc<str>,
    /// How long a request waits for its reply.
    pub(crate) wait: Duration,
}

impl Asking {
    /// Declares `key` on `session` for the requests of `port`.
    pub(crate) async fn new(
        session: zenoh::Session,
        key: String,
        name: Option<zenoh::bytes::ZBytes>,
        port: Arc<str>,
        wait: Duration,
    ) -> Result<Self, crate::ZenohError> {
        let key = session
            .declare_keyexpr(key)
            .await
            .map_err(crate::ZenohError::session)?;
        Ok(Self {
            session,
            key,
            name,
            port,
            wait,
        })
    }

    /// Asks the other host with `request`: its answer goes to `reply` as it comes. Without
    /// one (an error reply, no reply in time, bytes that are no reply) the handle is
    /// dropped when the query ends, and the local sender gets `NoReply`; the reason is
    /// logged. Dropping what this returns drops the reply at once, if it has not come.
    pub(crate) async fn ask<Req: Message, Rep: Message>(
        &self,
        request: Req,
        reply: ReplyHandle<Rep>,
    ) -> Pending<Rep> {
        let (ended, ends) = tokio::sync::oneshot::channel();
        let pending = Pending {
            handle: Arc::new(Mutex::new(Some(reply))),
            ends,
        };
        let bytes = match encode(&self.port, &request) {
            Ok(bytes) => bytes,
            Err(error) => {
                self.no_reply(&error.to_string());
                pending.give_up();
                return pending;
            }
        };
        drop(request);
        let answering = Answering {
            handle: Arc::clone(&pending.handle),
            port: Arc::clone(&self.port),
            _ended: ended,
        };
        let asked = self
            .session
            .get(&self.key)
            .payload(bytes)
            .attachment(self.name.clone())
            .timeout(self.wait)
            .callback(move |reply| answering.answer(reply))
            .await;
        if let Err(error) = asked {
            self.no_reply(&error.to_string());
            pending.give_up();
        }
        pending
    }

    fn no_reply(&self, reason: &str) {
        tracing::debug!(port = %self.port, %reason, "a request across hosts got no reply");
    }
}

/// The reply handle of a request asked and not yet answered, and the word that its query
/// has ended.
pub(crate) struct Pending<Rep> {
    handle: Arc<Mutex<Option<ReplyHandle<Rep>>>>,
    ends: tokio::sync::oneshot::Receiver<()>,
}

impl<Rep> Pending<Rep> {
    /// Whether the request still waits for its answer.
    pub(crate) fn waits(&self) -> bool {
        lock(&self.handle).is_some()
    }

    /// Drops the reply handle: the sender gets `NoReply` now.
    pub(crate) fn give_up(&self) {
        drop(lock(&self.handle).take());
    }

    /// Until the query has ended: answered, refused, or out of time.
    pub(crate) async fn ended(&mut self) {
        let _ = (&mut self.ends).await;
    }
}

impl<Rep> Drop for Pending<Rep> {
    fn drop(&mut self) {
        self.give_up();
    }
}

fn lock<Rep>(
    handle: &Mutex<Option<ReplyHandle<Rep>>>,
) -> std::sync::MutexGuard<'_, Option<ReplyHandle<Rep>>> {
    handle.lock().unwrap_or_else(PoisonError::into_inner)
}

/// What zenoh's callback holds while the query is open: dropped when it ends.
struct Answering<Rep> {
    handle: Arc<Mutex<Option<ReplyHandle<Rep>>>>,
    port: Arc<str>,
    /// Dropped with the callback: the query has ended.
    _ended: tokio::sync::oneshot::Sender<()>,
}

impl<Rep: Message> Answering<Rep> {
    fn answer(&self, reply: Reply) {
        let Some(handle) = lock(&self.handle).take() else {
            return;
        };
        let answer = match reply.into_result() {
            Ok(sample) => decode::<Rep>(&self.port, &sample.payload().to_bytes())
                .map_err(|error| error.to_string()),
            Err(error) => Err(String::from_utf8_lossy(&error.payload().to_bytes()).into_owned()),
        };
        match answer {
            Ok(answer) => drop(handle.reply(answer)),
            Err(reason) => {
                tracing::debug!(port = %self.port, %reason, "a request across hosts got no reply");
            }
        }
    }
}

impl<Rep> Drop for Answering<Rep> {
    /// The query has ended: a request still unanswered never will be.
    fn drop(&mut self) {
        drop(lock(&self.handle).take());
    }
}
