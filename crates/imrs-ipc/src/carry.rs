//! How a port's messages lie in shared memory: by value, copied into a sample and out of
//! it; or as [`Shared`] handles, built in a loaned sample by the sender and read there by
//! the receiver, so that nothing is copied on the way.

use std::any::Any;
use std::mem::MaybeUninit;
use std::ptr::NonNull;
use std::sync::{Arc, Mutex};

use iceoryx2::active_request::ActiveRequest;
use iceoryx2::pending_response::PendingResponse;
use iceoryx2::port::client::Client;
use iceoryx2::request_mut::RequestMut;
use iceoryx2::request_mut_uninit::RequestMutUninit;
use iceoryx2::response::Response;
use iceoryx2::response_mut::ResponseMut;
use iceoryx2::response_mut_uninit::ResponseMutUninit;
use imrs_ports::shared::Buffer;
use imrs_ports::{LoanError, Name, Shared};

use crate::Wire;
use crate::bridge::Svc;
use crate::wire::{ReplyMeta, RequestMeta};

pub(crate) type Active<Req, Rep> = ActiveRequest<Svc, Req, RequestMeta, Rep, ReplyMeta>;
/// A request the owner's process holds until it has answered it — and, for a request read
/// in place, for as long as the module keeps it.
pub(crate) type Held<Req, Rep> = Arc<Mutex<Active<Req, Rep>>>;
pub(crate) type Pending<Req, Rep> = PendingResponse<Svc, Req, RequestMeta, Rep, ReplyMeta>;
pub(crate) type Asker<Req, Rep> = Client<Svc, Req, RequestMeta, Rep, ReplyMeta>;
pub(crate) type Server<Req, Rep> =
    iceoryx2::port::server::Server<Svc, Req, RequestMeta, Rep, ReplyMeta>;
pub(crate) type Answer<Rep> = Response<Svc, Rep, ReplyMeta>;
pub(crate) type Loan<Req, Rep> = RequestMut<Svc, Req, RequestMeta, Rep, ReplyMeta>;
type LoanUninit<Req, Rep> = RequestMutUninit<Svc, MaybeUninit<Req>, RequestMeta, Rep, ReplyMeta>;
pub(crate) type Reply<Rep> = ResponseMut<Svc, Rep, ReplyMeta>;
pub(crate) type ReplyUninit<Rep> = ResponseMutUninit<Svc, MaybeUninit<Rep>, ReplyMeta>;

/// A port's message type `Self`, carried as wire type `W`.
pub(crate) trait Carry<W: Wire>: Send + Sized + 'static {
    /// A request the owner's process received, as its port carries it.
    fn from_request<Rep: Wire>(request: &Held<W, Rep>) -> Self;
    /// A reply a user's process received, as its port carries it.
    fn from_answer(answer: Answer<W>) -> Self;
    /// The request to send as `client`: in place, if it lies in a loan of `client`'s own;
    /// otherwise copied into a new loan. `None` if there is no room.
    fn into_request<Rep: Wire>(self, client: &Asker<W, Rep>) -> Option<Loan<W, Rep>>;
    /// The reply to `request`: in place, if it lies in a loan made for that very request;
    /// otherwise copied into a new loan. `None` if there is no room.
    fn into_reply<Req: Wire>(self, request: &Held<Req, W>) -> Option<Reply<W>>;
}

/// By value: copied into each sample, and out of it.
impl<W: Wire> Carry<W> for W {
    fn from_request<Rep: Wire>(request: &Held<W, Rep>) -> Self {
        *lock(request).payload()
    }

    fn from_answer(answer: Answer<W>) -> Self {
        *answer.payload()
    }

    fn into_request<Rep: Wire>(self, client: &Asker<W, Rep>) -> Option<Loan<W, Rep>> {
        Some(client.loan_uninit().ok()?.write_payload(self))
    }

    fn into_reply<Req: Wire>(self, request: &Held<Req, W>) -> Option<Reply<W>> {
        Some(lock(request).loan_uninit().ok()?.write_payload(self))
    }
}

/// By handle: a request or a reply built in a loan is sent in place, and read in place.
impl<W: Wire> Carry<W> for Shared<W> {
    fn from_request<Rep: Wire>(request: &Held<W, Rep>) -> Self {
        let payload = NonNull::from(lock(request).payload());
        Shared::in_buffer(Received {
            payload,
            request: Arc::clone(request),
        })
    }

    fn from_answer(answer: Answer<W>) -> Self {
        Shared::in_buffer(Answered(answer))
    }

    fn into_request<Rep: Wire>(self, client: &Asker<W, Rep>) -> Option<Loan<W, Rep>> {
        // A loan of this very client is sent as it lies. A loan of another port (or another
        // process's sample, or the heap) cannot be: it is copied into one of this client's.
        let own = self
            .buffer()
            .downcast_ref::<Loaned<W, Rep>>()
            .is_some_and(|loaned| loaned.0.header().client_id() == client.id());
        if own {
            let loaned: Box<dyn Any + Send> = self.into_buffer();
            return loaned
                .downcast::<Loaned<W, Rep>>()
                .ok()
                .map(|loaned| loaned.0);
        }
        let mut loan = client.loan_uninit().ok()?;
        // SAFETY: `self` is a valid `W`, and the loan is a sample of its own in shared memory,
        // so the two do not overlap; the copy writes the whole payload before it is assumed
        // initialised.
        Some(unsafe {
            loan.payload_mut()
                .as_mut_ptr()
                .copy_from_nonoverlapping(&*self, 1);
            loan.assume_init()
        })
    }

    fn into_reply<Req: Wire>(self, request: &Held<Req, W>) -> Option<Reply<W>> {
        // A loan made for this very request is sent as it lies. One made for another
        // request would answer that request's sender: it is copied, as a heap reply is.
        let own = self
            .buffer()
            .downcast_ref::<Replying<Req, W>>()
            .is_some_and(|replying| Arc::ptr_eq(&replying.request, request));
        if own {
            let replying: Box<dyn Any + Send> = self.into_buffer();
            return replying
                .downcast::<Replying<Req, W>>()
                .ok()
                .map(|replying| replying.reply);
        }
        let mut loan: ReplyUninit<W> = lock(request).loan_uninit().ok()?;
        // SAFETY: as for a request: a valid `W`, copied whole into a sample of its own.
        Some(unsafe {
            loan.payload_mut()
                .as_mut_ptr()
                .copy_from_nonoverlapping(&*self, 1);
            loan.assume_init()
        })
    }
}

/// A loan for a message of `port`, built in place by the sender: shared memory, all zeros.
pub(crate) fn lend<Req: Wire, Rep: Wire>(
    client: &Mutex<Asker<Req, Rep>>,
    port: &Name,
) -> Result<Shared<Req>, LoanError> {
    let mut loan: LoanUninit<Req, Rep> = lock(client).loan_uninit().map_err(|error| LoanError {
        port: port.clone(),
        detail: format!("{error:?}"),
    })?;
    // SAFETY: `Req: FromBytes` (a bound of `Wire`), so all zeros are one of its values; the
    // whole payload is written before it is assumed initialised.
    let loan = unsafe {
        loan.payload_mut().as_mut_ptr().write_bytes(0, 1);
        loan.assume_init()
    };
    Ok(Shared::in_buffer(Loaned(loan)))
}

/// Locks `mutex`: each critical section of the bridges leaves its data whole, so a panic
/// elsewhere does not spoil it.
pub(crate) fn lock<T: ?Sized>(mutex: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    mutex
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
}

/// A request being built by its sender, in a loan from its port's client.
struct Loaned<Req: Wire, Rep: Wire>(Loan<Req, Rep>);

impl<Req: Wire, Rep: Wire> Buffer<Req> for Loaned<Req, Rep> {
    fn get(&self) -> &Req {
        self.0.payload()
    }

    fn get_mut(&mut self) -> Option<&mut Req> {
        Some(self.0.payload_mut())
    }
}

/// A request received from another process, read where its sender wrote it.
struct Received<Req: Wire, Rep: Wire> {
    payload: NonNull<Req>,
    /// Keeps the request's sample, where `payload` lies.
    request: Held<Req, Rep>,
}

// SAFETY: `payload` is only ever read (`Req: Sync`, a bound of `Wire`), and the sample it
// points into is kept by `request`, which may move between threads (`Arc` of a `Mutex` of
// an `ActiveRequest`, which is `Send`).
unsafe impl<Req: Wire, Rep: Wire> Send for Received<Req, Rep> {}

impl<Req: Wire, Rep: Wire> Buffer<Req> for Received<Req, Rep> {
    fn get(&self) -> &Req {
        // SAFETY: `payload` is the payload of the request `request` holds: a sample in
        // shared memory that stays mapped, at the same address, and unwritten (the client
        // gave it up when it sent it) for as long as the request is held — at least as long
        // as `self`. It was a valid `Req` when received, and `Req: FromBytes`, so it is one
        // whatever the sender wrote.
        unsafe { self.payload.as_ref() }
    }

    fn get_mut(&mut self) -> Option<&mut Req> {
        None
    }

    /// No one writes the request: a clone reads it where it lies, and keeps its sample.
    fn share(&self) -> Option<Box<dyn Buffer<Req> + Send>> {
        Some(Box::new(Received {
            payload: self.payload,
            request: Arc::clone(&self.request),
        }))
    }

    fn lend_reply(&self) -> Option<Box<dyn Any + Send>> {
        lend_reply(&self.request)
    }
}

/// A loan for the reply to `request`, in which it crosses back as it lies: a [`Shared`] of
/// the reply's type, all zeros, boxed as `Any` (as [`Buffer::lend_reply`] gives it).
pub(crate) fn lend_reply<Req: Wire, Rep: Wire>(
    request: &Held<Req, Rep>,
) -> Option<Box<dyn Any + Send>> {
    let mut loan: ReplyUninit<Rep> = lock(request).loan_uninit().ok()?;
    // SAFETY: `Rep: FromBytes` (a bound of `Wire`), so all zeros are one of its values; the
    // whole payload is written before it is assumed initialised.
    let reply = unsafe {
        loan.payload_mut().as_mut_ptr().write_bytes(0, 1);
        loan.assume_init()
    };
    let replying = Replying {
        reply,
        request: Arc::clone(request),
    };
    Some(Box::new(Shared::in_buffer(replying)))
}

/// A reply being built by the owner's module, in a loan made for the request it answers.
struct Replying<Req: Wire, Rep: Wire> {
    reply: Reply<Rep>,
    /// The request answered: only its reply is sent as it lies.
    request: Held<Req, Rep>,
}

impl<Req: Wire, Rep: Wire> Buffer<Rep> for Replying<Req, Rep> {
    fn get(&self) -> &Rep {
        self.reply.payload()
    }

    fn get_mut(&mut self) -> Option<&mut Rep> {
        Some(self.reply.payload_mut())
    }
}

/// A reply received from another process, read where its sender wrote it.
struct Answered<Rep: Wire>(Answer<Rep>);

impl<Rep: Wire> Buffer<Rep> for Answered<Rep> {
    fn get(&self) -> &Rep {
        self.0.payload()
    }

    fn get_mut(&mut self) -> Option<&mut Rep> {
        None
    }
}
