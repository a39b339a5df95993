//! The reading end of a synchronous port.

use std::collections::VecDeque;
use std::fmt;
use std::future::Future;
use std::pin::Pin;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::task::{Context, Poll, Waker};

use super::error::ReadError;
use super::handle::{Close, Handle};
use super::ticket::Ticket;
use crate::meta::Name;
use crate::priority::Priority;
use crate::select::Alternative;

/// An input port of a schema instance: reads what connected [`Output`](super::Output)s write.
///
/// Cheap to clone; every clone is the same port (they share one queue). The port closes
/// when [`Input::close`] is called or the last clone is dropped.
pub struct Input<T> {
    handle: Arc<Handle<InputShared<T>>>,
}

/// What outputs connected to this input hold.
pub(crate) struct InputShared<T> {
    pub(crate) port: Name,
    pub(crate) owner: Name,
    priority: Priority,
    state: Mutex<InputState<T>>,
}

/// A value waiting to be read, with the fate of the write it came from.
pub(crate) struct Copy<T> {
    pub(crate) ticket: Arc<Ticket>,
    pub(crate) value: T,
}

pub(crate) struct InputState<T> {
    queue: VecDeque<Copy<T>>,
    pub(crate) closed: bool,
    /// Connected outputs not closed. With `connected` and none live, a read has nobody to
    /// wait for.
    live_writers: usize,
    connected: bool,
    readers: Vec<Waker>,
}

impl<T> InputState<T> {
    /// A connected output wrote `copy` (or was connected while its write waits).
    pub(crate) fn deliver(&mut self, copy: Copy<T>) {
        if self.closed {
            copy.ticket.nudge();
            return;
        }
        self.queue.push_back(copy);
        self.wake_readers();
    }

    pub(crate) fn connected(&mut self, live: bool) {
        self.connected = true;
        self.live_writers += usize::from(live);
    }

    pub(crate) fn writer_closed(&mut self) {
        self.live_writers -= 1;
        self.wake_readers();
    }

    /// Takes back the copies of a withdrawn write.
    pub(crate) fn withdraw(&mut self, ticket: &Arc<Ticket>) {
        self.queue.retain(|copy| !Arc::ptr_eq(&copy.ticket, ticket));
    }

    fn wake_readers(&mut self) {
        self.readers.drain(..).for_each(Waker::wake);
    }
}

impl<T> InputShared<T> {
    pub(crate) fn lock(&self) -> MutexGuard<'_, InputState<T>> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

impl<T> Close for InputShared<T> {
    fn close(&self) {
        let mut state = self.lock();
        state.closed = true;
        // Writers waiting on these copies look again: this input will never read them.
        state.queue.drain(..).for_each(|copy| copy.ticket.nudge());
        state.wake_readers();
    }
}

impl<T: Clone + Send + 'static> Input<T> {
    /// An input port named `port` of the instance (or module) `owner`.
    pub fn new(port: impl Into<Name>, owner: impl Into<Name>) -> Self {
        Self::with_priority(port, owner, Priority::DEFAULT)
    }

    /// An input with a priority: of several ready alternatives of a
    /// [`select`](crate::select()), the one of highest priority is taken.
    pub fn with_priority(
        port: impl Into<Name>,
        owner: impl Into<Name>,
        priority: Priority,
    ) -> Self {
        let shared = Arc::new(InputShared {
            port: port.into(),
            owner: owner.into(),
            priority,
            state: Mutex::new(InputState {
                queue: VecDeque::new(),
                closed: false,
                live_writers: 0,
                connected: false,
                readers: Vec::new(),
            }),
        });
        Self {
            handle: Arc::new(Handle { shared }),
        }
    }

    /// Waits until a connected output writes, and takes the oldest value not yet read here.
    pub fn read(&self) -> Read<'_, T> {
        Read {
            input: &self.handle.shared,
        }
    }

    /// The oldest value written and not yet read here, if there is one; never waits.
    pub fn try_read(&self) -> Option<T> {
        self.handle.shared.lock().take()
    }

    /// How many values wait here to be read.
    pub fn waiting(&self) -> usize {
        self.handle.shared.lock().queue.len()
    }
}

impl<T> InputState<T> {
    fn take(&mut self) -> Option<T> {
        while let Some(copy) = self.queue.pop_front() {
            if copy.ticket.read() {
                return Some(copy.value);
            }
        }
        None
    }
}

impl<T> Input<T> {
    /// The port's name.
    pub fn port(&self) -> &Name {
        &self.handle.shared.port
    }

    /// The instance (or module) that owns the port.
    pub fn owner(&self) -> &Name {
        &self.handle.shared.owner
    }

    /// Closes the port: waiting and later reads fail with [`ReadError::Closed`], and
    /// writers no longer wait for it.
    pub fn close(&self) {
        self.handle.shared.close();
    }

    pub(crate) fn shared(&self) -> &Arc<InputShared<T>> {
        &self.handle.shared
    }
}

impl<T> Clone for Input<T> {
    fn clone(&self) -> Self {
        Self {
            handle: Arc::clone(&self.handle),
        }
    }
}

impl<T> fmt::Debug for Input<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Input({}({}))", self.owner(), self.port())
    }
}

/// The future of [`Input::read`].
#[must_use = "a read does nothing unless awaited"]
pub struct Read<'a, T> {
    input: &'a InputShared<T>,
}

impl<T> Future for Read<'_, T> {
    type Output = Result<T, ReadError>;

    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Self::Output> {
        self.input.poll_read(cx)
    }
}

/// A synchronous input is an alternative of a [`select`](crate::select()): it is ready when
/// a value waits, and chosen by its priority among the ready ones.
impl<T: Clone + Send + 'static> Alternative for &Input<T> {
    type Output = T;

    fn priority(&self) -> Option<Priority> {
        Some(self.handle.shared.priority)
    }

    fn poll_ready(&mut self, cx: &mut Context<'_>) -> Poll<T> {
        match self.handle.shared.poll_read(cx) {
            Poll::Ready(Ok(value)) => Poll::Ready(value),
            // A read that failed is a closed alternative: `is_closed` says so.
            Poll::Ready(Err(_)) | Poll::Pending => Poll::Pending,
        }
    }

    fn is_closed(&self) -> bool {
        let state = self.handle.shared.lock();
        state.queue.is_empty() && (state.closed || (state.connected && state.live_writers == 0))
    }
}

impl<T> InputShared<T> {
    fn poll_read(&self, cx: &mut Context<'_>) -> Poll<Result<T, ReadError>> {
        let input = self;
        let mut state = input.lock();
        if let Some(value) = state.take() {
            return Poll::Ready(Ok(value));
        }
        let error = |kind: fn(Name, Name) -> ReadError| {
            Poll::Ready(Err(kind(input.owner.clone(), input.port.clone())))
        };
        if state.closed {
            return error(|owner, port| ReadError::Closed { owner, port });
        }
        if state.connected && state.live_writers == 0 {
            return error(|owner, port| ReadError::Disconnected { owner, port });
        }
        if !state.readers.iter().any(|w| w.will_wake(cx.waker())) {
            state.readers.push(cx.waker().clone());
        }
        Poll::Pending
    }
}
