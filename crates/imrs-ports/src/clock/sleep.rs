use std::fmt;
use std::future::Future;
use std::pin::Pin;
use std::task::{Context, Poll};

use pin_project_lite::pin_project;

use super::virtual_clock::VirtualTimer;

pin_project! {
    /// A timer on a [`Clock`](super::Clock), returned by
    /// [`Clock::sleep_until`](super::Clock::sleep_until).
    ///
    /// The built-in clocks' timers live inline, so waiting with a timeout allocates nothing.
    #[must_use = "a Sleep does nothing unless awaited or polled"]
    pub struct Sleep {
        #[pin]
        inner: Inner,
    }
}

pin_project! {
    #[project = InnerProj]
    enum Inner {
        Real { #[pin] sleep: tokio::time::Sleep },
        Virtual { timer: VirtualTimer },
        Custom { future: Pin<Box<dyn Future<Output = ()> + Send>> },
    }
}

impl Sleep {
    pub(super) fn real(sleep: tokio::time::Sleep) -> Self {
        Self {
            inner: Inner::Real { sleep },
        }
    }

    pub(super) fn virtual_timer(timer: VirtualTimer) -> Self {
        Self {
            inner: Inner::Virtual { timer },
        }
    }

    /// Wraps the timer future of a clock defined outside this crate.
    pub fn from_future(future: impl Future<Output = ()> + Send + 'static) -> Self {
        Self {
            inner: Inner::Custom {
                future: Box::pin(future),
            },
        }
    }
}

impl Future for Sleep {
    type Output = ();

    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<()> {
        match self.project().inner.project() {
            InnerProj::Real { sleep } => sleep.poll(cx),
            InnerProj::Virtual { timer } => timer.poll(cx),
            InnerProj::Custom { future } => future.as_mut().poll(cx),
        }
    }
}

impl fmt::Debug for Sleep {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kind = match &self.inner {
            Inner::Real { .. } => "real",
            Inner::Virtual { .. } => "virtual",
            Inner::Custom { .. } => "custom",
        };
        f.debug_struct("Sleep").field("clock", &kind).finish()
    }
}

/// Whether an optional deadline has passed; registers the task with it if not.
pub(crate) fn deadline_passed(deadline: Pin<&mut Option<Sleep>>, cx: &mut Context<'_>) -> bool {
    deadline
        .as_pin_mut()
        .is_some_and(|sleep| sleep.poll(cx).is_ready())
}
