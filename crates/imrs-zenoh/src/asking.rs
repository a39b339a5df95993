//! How a bridge asks the other host: a zenoh `get` whose reply is handed to the waiting
//! module from zenoh's own callback, so that the module wakes once, as it would for a raw
//! `get`, and the bridge is free for the next request at once.

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
    /// logged. The request stays pending until then; dropping what this returns drops its
    /// reply at once.
    pub(crate) async fn ask<Req: Message, Rep: Message>(
        &self,
        request: Req,
        reply: ReplyHandle<Rep>,
    ) -> Pending<Rep> {
        let pending = Pending(Arc::new(Mutex::new(Some(reply))));
        let bytes = match encode(&self.port, &request) {
            Ok(bytes) => bytes,
            Err(error) => {
                self.no_reply(&error.to_string());
                return Pending(Arc::default());
            }
        };
        drop(request);
        let answering = Answering {
            pending: Pending(Arc::clone(&pending.0)),
            port: Arc::clone(&self.port),
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

/// The reply handle of a request asked and not yet answered.
pub(crate) struct Pending<Rep>(Arc<Mutex<Option<ReplyHandle<Rep>>>>);

impl<Rep> Pending<Rep> {
    fn take(&self) -> Option<ReplyHandle<Rep>> {
        self.0.lock().unwrap_or_else(PoisonError::into_inner).take()
    }

    /// Whether the request still waits for its answer.
    pub(crate) fn waits(&self) -> bool {
        self.0
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .is_some()
    }

    /// Drops the reply handle: the sender gets `NoReply` now.
    pub(crate) fn give_up(&self) {
        drop(self.take());
    }
}

/// What zenoh's callback holds while the query is open.
struct Answering<Rep> {
    pending: Pending<Rep>,
    port: Arc<str>,
}

impl<Rep: Message> Answering<Rep> {
    fn answer(&self, reply: Reply) {
        let Some(handle) = self.pending.take() else {
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
        self.pending.give_up();
    }
}
