//! A future looked at once, without an executor.

use std::pin::pin;
use std::task::{Context, Poll, Waker};

/// Polls `future` once, with a waker that does nothing, as an executor would before it
/// parks the task. A future pinned already is polled in place through its pin:
/// `poll_once(future.as_mut())`.
pub fn poll_once<F: Future>(future: F) -> Poll<F::Output> {
    let mut future = pin!(future);
    future
        .as_mut()
        .poll(&mut Context::from_waker(Waker::noop()))
}
