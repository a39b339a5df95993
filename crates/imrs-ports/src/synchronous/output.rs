//! The writing end of a synchronous port.

use std::fmt;
use std::future::Future;
use std::pin::Pin;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::task::{Context, Poll};

use super::error::WriteError;
use super::handle::{Close, Handle};
use super::input::{Copy, Input, InputShared};
use super::ticket::{Fate, Ticket};
use crate::meta::Name;

/// An output port of a schema instance: its writes go to every connected
/// [`Input`](super::Input).
///
/// Cheap to clone; every clone is the same port. The port closes when [`Output::close`] is
/// called or the last clone is dropped.
pub struct Output<T> {
    handle: Arc<Handle<OutputShared<T>>>,
}

pub(crate) struct OutputShared<T> {
    port: Name,
    owner: Name,
    state: Mutex<OutputState<T>>,
}

struct OutputState<T> {
    /// The inputs connected and not known to be closed: a closed one is forgotten at the
    /// next write or connection, so that an output whose readers come and go (a sensor
    /// read by one short-lived instance after another) keeps no list of the dead.
    inputs: Vec<Arc<InputShared<T>>>,
    /// Whether any input was ever connected: with all of them closed, a write is unread
    /// for good.
    connected: bool,
    /// The write waiting now, kept so that an input connected meanwhile gets it too.
    pending: Option<Copy<T>>,
    closed: bool,
}

impl<T> OutputState<T> {
    /// Whether a waiting write can never be read: it had inputs, and all are closed.
    fn unread_for_good(&self) -> bool {
        self.connected && self.inputs.iter().all(|input| input.lock().closed)
    }

    fn forget_closed(&mut self) {
        self.inputs.retain(|input| !input.lock().closed);
    }

    fn take_pending(&mut self, ticket: &Arc<Ticket>) -> Option<T> {
        match &self.pending {
            Some(copy) if Arc::ptr_eq(&copy.ticket, ticket) => {
                self.pending.take().map(|copy| copy.value)
            }
            _ => None,
        }
    }
}

// Lock order: an output's state, then an input's, then a ticket.
impl<T> OutputShared<T> {
    fn lock(&self) -> MutexGuard<'_, OutputState<T>> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Takes a withdrawn write's copies back from every input.
    fn withdraw(&self, ticket: &Arc<Ticket>) -> Option<T> {
        let mut state = self.lock();
        for input in &state.inputs {
            input.lock().withdraw(ticket);
        }
        state.take_pending(ticket)
    }
}

impl<T> Close for OutputShared<T> {
    fn close(&self) {
        let mut state = self.lock();
        if std::mem::replace(&mut state.closed, true) {
            return;
        }
        for input in &state.inputs {
            input.lock().writer_closed();
        }
        if let Some(copy) = &state.pending {
            copy.ticket.nudge();
        }
    }
}

impl<T: Clone + Send + 'static> Output<T> {
    /// An output port named `port` of the instance (or module) `owner`.
    pub fn new(port: impl Into<Name>, owner: impl Into<Name>) -> Self {
        let shared = Arc::new(OutputShared {
            port: port.into(),
            owner: owner.into(),
            state: Mutex::new(OutputState {
                inputs: Vec::new(),
                connected: false,
                pending: None,
                closed: false,
            }),
        });
        Self {
            handle: Arc::new(Handle { shared }),
        }
    }

    /// Writes `value` to every connected input and waits until one of them has read it.
    ///
    /// Dropping the future before then withdraws the value from every input.
    pub fn write(&self, value: T) -> Write<'_, T> {
        Write {
            output: &self.handle.shared,
            state: WriteState::Start(value),
        }
    }

    pub(crate) fn connect(&self, input: &Input<T>) {
        let input = input.shared();
        let mut state = self.handle.shared.lock();
        state.forget_closed();
        if state.inputs.iter().any(|known| Arc::ptr_eq(known, input)) {
            return;
        }
        state.connected = true;
        let mut reader = input.lock();
        reader.connected(!state.closed);
        if let Some(copy) = &state.pending
            && matches!(*copy.ticket.lock(), Fate::Pending(_))
        {
            reader.deliver(Copy {
                ticket: Arc::clone(&copy.ticket),
                value: copy.value.clone(),
            });
        }
        drop(reader);
        state.inputs.push(Arc::clone(input));
    }

    /// How many inputs are connected: those not closed, and a closed one until the next
    /// write or connection forgets it.
    pub fn connections(&self) -> usize {
        self.handle.shared.lock().inputs.len()
    }
}

impl<T> Output<T> {
    /// The port's name.
    pub fn port(&self) -> &Name {
        &self.handle.shared.port
    }

    /// The instance (or module) that owns the port.
    pub fn owner(&self) -> &Name {
        &self.handle.shared.owner
    }

    /// Closes the port: a read that has nothing left from any live writer fails with
    /// [`Disconnected`](super::ReadError::Disconnected).
    pub fn close(&self) {
        self.handle.shared.close();
    }
}

impl<T> Clone for Output<T> {
    fn clone(&self) -> Self {
        Self {
            handle: Arc::clone(&self.handle),
        }
    }
}

impl<T> fmt::Debug for Output<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Output({}({}))", self.owner(), self.port())
    }
}

enum WriteState<T> {
    Start(T),
    Waiting(Arc<Ticket>),
    Done,
}

/// The future of [`Output::write`]: ready once a connected input has read the value.
#[must_use = "a write does nothing unless awaited"]
pub struct Write<'a, T> {
    output: &'a OutputShared<T>,
    state: WriteState<T>,
}

impl<T: Clone> Write<'_, T> {
    /// Hands the value to every connected input, and keeps it for inputs connected later.
    fn start(&mut self, value: T) -> Arc<Ticket> {
        let ticket = Arc::new(Ticket::new());
        let mut state = self.output.lock();
        state.forget_closed();
        for input in &state.inputs {
            input.lock().deliver(Copy {
                ticket: Arc::clone(&ticket),
                value: value.clone(),
            });
        }
        state.pending = Some(Copy {
            ticket: Arc::clone(&ticket),
            value,
        });
        ticket
    }

    fn fail(&mut self, ticket: &Arc<Ticket>, closed: bool) -> Poll<Result<(), WriteError<T>>> {
        self.state = WriteState::Done;
        let Some(value) = self.output.withdraw(ticket) else {
            return Poll::Ready(Ok(())); // read meanwhile
        };
        let (owner, port) = (self.output.owner.clone(), self.output.port.clone());
        Poll::Ready(Err(if closed {
            WriteError::Closed { owner, port, value }
        } else {
            WriteError::Disconnected { owner, port, value }
        }))
    }
}

// The value is moved in and out, never pinned in place.
impl<T> Unpin for Write<'_, T> {}

impl<T: Clone> Future for Write<'_, T> {
    type Output = Result<(), WriteError<T>>;

    fn poll(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Self::Output> {
        let this = &mut *self;
        let ticket = match std::mem::replace(&mut this.state, WriteState::Done) {
            WriteState::Start(value) => {
                if this.output.lock().closed {
                    let (owner, port) = (this.output.owner.clone(), this.output.port.clone());
                    return Poll::Ready(Err(WriteError::Closed { owner, port, value }));
                }
                this.start(value)
            }
            WriteState::Waiting(ticket) => ticket,
            WriteState::Done => panic!("a write polled after it completed"),
        };
        {
            let mut fate = ticket.lock();
            match &mut *fate {
                Fate::Pending(waker) => *waker = Some(cx.waker().clone()),
                Fate::Read | Fate::Withdrawn => {
                    drop(fate);
                    this.output.lock().take_pending(&ticket);
                    return Poll::Ready(Ok(()));
                }
            }
        }
        // Checked after the waker is set: a close from now on nudges this write.
        let (closed, unread) = {
            let state = this.output.lock();
            (state.closed, state.unread_for_good())
        };
        if closed || unread {
            return this.fail(&ticket, closed);
        }
        this.state = WriteState::Waiting(ticket);
        Poll::Pending
    }
}

impl<T> Drop for Write<'_, T> {
    fn drop(&mut self) {
        if let WriteState::Waiting(ticket) = &self.state {
            if ticket.withdraw() {
                self.output.withdraw(ticket);
            } else {
                self.output.lock().take_pending(ticket);
            }
        }
    }
}
