//! Messages built in place. A port of [`Shared<T>`] moves a handle to its message, never the
//! message itself: a sender loans the memory from its end ([`End::loan`](crate::End::loan)),
//! writes the message there, and sends the handle; the receiver reads it where it lies.
//!
//! In one process the memory is the heap. A transport across processes lends its own: a
//! sample of shared memory, which crosses to the other process with nothing copied, and is
//! read there in place. The module's code is the same either way — where its port's memory
//! comes from is decided when the cell is wired, by whoever lends it
//! ([`Port::lend_with`](crate::transport::PortTransport::lend_with)).
//!
//! ```
//! use imrs_ports::{Port, PortSpec, Shared, usage};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build()?;
//! # runtime.block_on(async {
//! // An image, too large to copy on every hop.
//! #[derive(Clone)]
//! struct Image {
//!     pixels: [u8; 65536],
//! }
//! impl Default for Image {
//!     fn default() -> Self {
//!         Self { pixels: [0; 65536] }
//!     }
//! }
//! let port = Port::<Shared<Image>, Shared<u64>, usage::Receive>::new(PortSpec::new("IMAGE", "VISION"));
//! let mut vision = port.owner()?;
//! let mut camera = port.user_named("CAMERA")?;
//!
//! let seeing = tokio::spawn(async move {
//!     let (image, reply) = vision.receive().await?;
//!     // Read where the camera wrote it.
//!     // The reply, built where it will cross back: here, the heap.
//!     let mut lit = image.loan_reply();
//!     *lit = image.pixels.iter().filter(|&&byte| byte > 0).count() as u64;
//!     reply.reply(lit);
//!     Ok::<_, imrs_ports::ReceiveError>(())
//! });
//! let mut image = camera.loan()?;
//! image.pixels[..100].fill(255);
//! assert_eq!(*camera.send(image).await?, 100);
//! seeing.await??;
//! # Ok::<_, Box<dyn std::error::Error>>(())
//! # })?;
//! # Ok(())
//! # }
//! ```
//!
//! The receiver builds its reply the same way, in memory its message's transport lends for
//! it ([`Shared::loan_reply`]). A message received from another process lies where its
//! sender wrote it, and is read-only there: changing it ([`DerefMut`]) first copies it to
//! the heap, once. Cloning it (as a `SENDALL` or `CALLALL` port does, once for each user)
//! copies nothing: the clone reads the same memory. A message that may still be written is
//! cloned by copying it to the heap.

use std::any::Any;
use std::fmt;
use std::ops::{Deref, DerefMut};

use crate::Name;

/// Memory a [`Shared`] message lies in: the heap, or a transport's. A transport recognises
/// a buffer of its own by its type ([`Shared::buffer`] is the buffer as `Any`).
pub trait Buffer<T>: Any + Send {
    /// The message.
    fn get(&self) -> &T;
    /// The message, to change in place; `None` where it is read-only (a message received
    /// from another process, which lies where its sender wrote it).
    fn get_mut(&mut self) -> Option<&mut T>;
    /// Memory for the reply to this message, where its transport carries the reply back: a
    /// [`Shared`] of the reply's type, boxed as `Any`. `None` (the default) where the
    /// transport lends none, and the reply is built on the heap.
    fn lend_reply(&self) -> Option<Box<dyn Any + Send>> {
        None
    }

    /// Another handle to this same message, read-only where it lies, for a copy of the
    /// message that needs none ([`Shared`]'s `Clone`): a buffer no one writes (a message
    /// received from another process) can give one, and the memory is let go when the last
    /// handle is dropped. So can a buffer that makes its message read-only from then on (a
    /// broadcast loan, sent to every user when first handed on). `None` (the default)
    /// where the message may be written, and its clone is a copy.
    fn share(&self) -> Option<Box<dyn Buffer<T> + Send>> {
        None
    }
}

impl<T: Send + 'static> Buffer<T> for Box<T> {
    fn get(&self) -> &T {
        self
    }

    fn get_mut(&mut self) -> Option<&mut T> {
        Some(self)
    }
}

/// A message a port moves by handle: it lies in a [`Buffer`] — the heap, or a transport's
/// shared memory — and is read (and, where it is writable, written) in place.
pub struct Shared<T: 'static> {
    buffer: Box<dyn Buffer<T> + Send>,
}

impl<T: Send + 'static> Shared<T> {
    /// `value`, on the heap.
    pub fn new(value: T) -> Self {
        Self::in_buffer(Box::new(value))
    }

    /// The message in `buffer`: how a transport hands over memory of its own.
    pub fn in_buffer(buffer: impl Buffer<T>) -> Self {
        Self {
            buffer: Box::new(buffer),
        }
    }

    /// The buffer the message lies in, for a transport to recognise one of its own.
    pub fn buffer(&self) -> &dyn Any {
        // The buffer itself, not its box.
        let buffer: &dyn Buffer<T> = &*self.buffer;
        buffer
    }

    /// The buffer the message lies in, for a transport to take back and send in place.
    pub fn into_buffer(self) -> Box<dyn Any + Send> {
        self.buffer
    }

    /// Memory for the reply to this message, to build it in place: where the message's
    /// transport carries the reply back — for a message from another process, a sample of
    /// shared memory, all zeros, which the reply then crosses in with nothing copied — or
    /// else the heap, starting as `R::default()`. The heap, too, when the transport has no
    /// memory left or `R` is not the port's reply type; such a reply is copied once when
    /// sent.
    pub fn loan_reply<R: Default + Send + 'static>(&self) -> Shared<R> {
        self.buffer
            .lend_reply()
            .and_then(|reply| reply.downcast::<Shared<R>>().ok())
            .map_or_else(Shared::default, |reply| *reply)
    }

    /// Whether the message can be changed where it lies; if not, [`DerefMut`] copies it to
    /// the heap first.
    pub fn is_writable(&mut self) -> bool {
        self.buffer.get_mut().is_some()
    }
}

impl<T: 'static> Deref for Shared<T> {
    type Target = T;

    fn deref(&self) -> &T {
        self.buffer.get()
    }
}

/// Changing a read-only message (one received from another process) copies it to the heap
/// first, once; a writable one is changed where it lies.
impl<T: Clone + Send + 'static> DerefMut for Shared<T> {
    fn deref_mut(&mut self) -> &mut T {
        if self.buffer.get_mut().is_none() {
            let copy: Box<T> = Box::new(self.buffer.get().clone());
            self.buffer = Box::new(copy);
        }
        self.buffer
            .get_mut()
            .expect("a message just copied to the heap is writable")
    }
}

/// A message that lies where no one writes it (one received from another process, or a
/// broadcast loan, which its transport sends when first handed on) is shared: the clone
/// reads the same memory, as a `SENDALL` or `CALLALL` port needs to hand one message to
/// every user without copying it. A message that may be written (on the heap, or in a loan
/// still being built) is copied to the heap, so that neither handle sees the other's
/// changes.
impl<T: Clone + Send + 'static> Clone for Shared<T> {
    fn clone(&self) -> Self {
        match self.buffer.share() {
            Some(buffer) => Self { buffer },
            None => Self::new(self.buffer.get().clone()),
        }
    }
}

impl<T: fmt::Debug + 'static> fmt::Debug for Shared<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_tuple("Shared").field(self.buffer.get()).finish()
    }
}

impl<T: Default + Send + 'static> Default for Shared<T> {
    fn default() -> Self {
        Self::new(T::default())
    }
}

/// How a port's lender makes a message: a loan of memory to build it in place.
pub(crate) type Lender<Req> = Box<dyn Fn() -> Result<Req, LoanError> + Send + Sync>;

/// A loan its port could not make: the transport's memory is used up (every loan and every
/// request out), or the transport is gone.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LoanError {
    /// The port.
    pub port: Name,
    /// What the transport said.
    pub detail: String,
}

impl fmt::Display for LoanError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "port {}: no message could be loaned: {}",
            self.port, self.detail
        )
    }
}

impl std::error::Error for LoanError {}
