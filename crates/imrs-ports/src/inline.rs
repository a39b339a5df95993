//! A port served inline: a post that the port itself answers in the poster's own poll,
//! with no rendezvous, while the server it stands for says it can.
//!
//! A filter is a task between two rendezvous. For the bounded buffer, whose answer to a
//! user is always the same empty reply while it has room and whose answer to the owner is
//! the oldest message, that task adds nothing but two trips through a scheduler per
//! message: the buffer serves both sides in place while it has room, and hands a post to
//! the filter task's rendezvous when it has not. See
//! [`BoundedBuffer`](crate::BoundedBuffer).

use std::any::Any;
use std::sync::Arc;

/// What serves a port's posts inline.
pub(crate) trait ServeInline<Req, Rep>: Send + Sync {
    /// Answers `request` at once, or hands it back for the rendezvous. `another_waits`
    /// says whether another poster's request waits in the port's rendezvous now: one that
    /// came first.
    fn serve(&self, request: Req, another_waits: bool) -> Result<Rep, Req>;

    /// The server itself, to be found again by the filter that installed it.
    fn into_any(self: Arc<Self>) -> Arc<dyn Any + Send + Sync>;
}
