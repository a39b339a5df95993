//! How a bridge takes the requests a port's other side makes: a receiving end's sends, or a
//! response end's queries, each with the right to reply.

use std::future::poll_fn;

use imrs_ports::{End, ReceiveError, ReplyHandle, ResponseEnd, usage};

/// An end a bridge takes requests from: the owner's side of an imported port (what its
/// local user sends), or a remote user's side of an exported one (what its owner
/// broadcasts or asks).
pub(crate) trait Take<Req, Rep>: Send + Sized + 'static {
    /// The next local request, and the right to reply to it.
    fn next(
        &mut self,
    ) -> impl Future<Output = Result<(Req, ReplyHandle<Rep>), ReceiveError>> + Send + '_;
}

impl<Req: Send + 'static, Rep: Send + 'static> Take<Req, Rep> for End<Req, Rep, usage::Receive> {
    async fn next(&mut self) -> Result<(Req, ReplyHandle<Rep>), ReceiveError> {
        self.receive().await
    }
}

impl<Req: Send + 'static, Rep: Send + 'static> Take<Req, Rep> for ResponseEnd<Req, Rep, ()> {
    async fn next(&mut self) -> Result<(Req, ReplyHandle<Rep>), ReceiveError> {
        loop {
            poll_fn(|cx| self.poll_pending(cx)).await?;
            if let Some(taken) = self.take() {
                return Ok(taken);
            }
        }
    }
}
