//! The poster's side of a rendezvous: `send` and `query`.

use std::future::Future;
use std::marker::PhantomData;
use std::pin::Pin;
use std::task::{Context, Poll};

use pin_project_lite::pin_project;

use crate::attachment::Attachment;
use crate::clock::{Sleep, deadline_passed};
use crate::error::Gone;
use crate::error::{QueryError, SendError};
use crate::meta::Name;
use crate::slot::{Answer, Withdrawn};

/// How a posted request failed, before it is phrased as the primitive's own error.
#[derive(Debug)]
pub enum Failure<Req> {
    /// Nobody took it in time.
    Timeout(Req),
    /// Taken, but not answered in time.
    AnswerTimeout,
    /// Taken, and dropped without an answer.
    Unanswered,
    /// Nobody can ever take it.
    Closed(Req),
    /// The module that served the port has ended for good.
    PeerGone(Req, Name),
}

impl<Req> Failure<Req> {
    fn gone(request: Req, gone: Gone) -> Self {
        match gone {
            Gone::Closed => Self::Closed(request),
            Gone::Peer(module) => Self::PeerGone(request, module),
        }
    }
}

/// What a posting primitive returns: [`SendOutcome`] or [`QueryOutcome`].
pub trait Outcome<Req, Rep> {
    /// The primitive's result type.
    type Output;
    /// The request was answered.
    fn answered(reply: Rep) -> Self::Output;
    /// The request failed.
    fn failed(failure: Failure<Req>, port: &Name) -> Self::Output;
}

/// The outcome of [`End::send`](crate::End::send).
#[derive(Debug)]
pub struct SendOutcome;

/// The outcome of [`End::query`](crate::End::query).
#[derive(Debug)]
pub struct QueryOutcome;

impl<Req, Rep> Outcome<Req, Rep> for SendOutcome {
    type Output = Result<Rep, SendError<Req>>;

    fn answered(reply: Rep) -> Self::Output {
        Ok(reply)
    }

    fn failed(failure: Failure<Req>, port: &Name) -> Self::Output {
        let port = port.clone();
        Err(match failure {
            Failure::Timeout(message) => SendError::Timeout { port, message },
            Failure::AnswerTimeout => SendError::ReplyTimeout { port },
            Failure::Unanswered => SendError::NoReply { port },
            Failure::Closed(message) => SendError::Closed { port, message },
            Failure::PeerGone(message, module) => SendError::PeerGone {
                port,
                module,
                message,
            },
        })
    }
}

impl<Req, Rep> Outcome<Req, Rep> for QueryOutcome {
    type Output = Result<Rep, QueryError<Req>>;

    fn answered(reply: Rep) -> Self::Output {
        Ok(reply)
    }

    fn failed(failure: Failure<Req>, port: &Name) -> Self::Output {
        let port = port.clone();
        Err(match failure {
            Failure::Timeout(query) => QueryError::Timeout { port, query },
            Failure::AnswerTimeout => QueryError::ResponseTimeout { port },
            Failure::Unanswered => QueryError::NoResponse { port },
            Failure::Closed(query) => QueryError::Closed { port, query },
            Failure::PeerGone(query, module) => QueryError::PeerGone {
                port,
                module,
                query,
            },
        })
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Stage {
    /// Waiting for the slot to be free (an abandoned request may still be served).
    Posting,
    /// The request is in the slot.
    Posted,
    Done,
}

pin_project! {
    /// The future of [`End::send`](crate::End::send) and [`End::query`](crate::End::query).
    ///
    /// Dropping it before it completes withdraws the request: a receiver that already took
    /// it may still reply, and gets its reply back ([`Replied::Late`](crate::Replied::Late)).
    /// A reply that had already come in when the future is dropped is dropped with it.
    #[must_use = "a send or query does nothing unless awaited"]
    pub struct Posting<'a, Req, Rep, O> {
        attachment: &'a Attachment<Req, Rep>,
        request: Option<Req>,
        stage: Stage,
        #[pin]
        deadline: Option<Sleep>,
        _outcome: PhantomData<fn() -> O>,
    }

    impl<'a, Req, Rep, O> PinnedDrop for Posting<'a, Req, Rep, O> {
        fn drop(this: Pin<&mut Self>) {
            let this = this.project();
            if *this.stage == Stage::Posted {
                let slot = this.attachment.core.slot(this.attachment.at);
                // SAFETY: this future is its slot's only poster (it borrows the end mutably),
                // and its request is in the slot.
                drop(unsafe { slot.withdraw() });
            }
        }
    }
}

impl<'a, Req, Rep, O> Posting<'a, Req, Rep, O> {
    pub(crate) fn new(attachment: &'a Attachment<Req, Rep>, request: Req) -> Self {
        Self {
            attachment,
            request: Some(request),
            stage: Stage::Posting,
            deadline: None,
            _outcome: PhantomData,
        }
    }

    /// The port posted to.
    #[inline]
    pub fn port(&self) -> &Name {
        self.attachment.port()
    }

    /// The module this post waits on: the port's owner, for a user's post; `None` for the
    /// owner's own post, which whichever user receives first serves. A copy of a name, for
    /// a record kept while the post waits.
    pub fn waits_on(&self) -> Option<&Name> {
        (!self.attachment.is_owner()).then_some(&self.attachment.core.meta.owner)
    }
}

impl<Req, Rep, O: Outcome<Req, Rep>> Future for Posting<'_, Req, Rep, O> {
    type Output = O::Output;

    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<O::Output> {
        let mut this = self.project();
        let attachment = *this.attachment;
        let core = &attachment.core;
        let slot = core.slot(attachment.at);
        let port = attachment.port();
        if *this.stage == Stage::Posting
            && let Some(server) = core.hooks().and_then(|hooks| hooks.inline.get())
        {
            let request = this.request.take().expect("a request waits to be posted");
            // With several users, one whose request waits in the rendezvous came first.
            let another_waits = core.capacity() > 1 && core.oldest_posted_user().is_some();
            match server.serve(request, another_waits) {
                Ok(reply) => {
                    *this.stage = Stage::Done;
                    return Poll::Ready(O::answered(reply));
                }
                Err(request) => *this.request = Some(request),
            }
        }
        if this.deadline.is_none()
            && let Some(timeout) = attachment.timeout
        {
            this.deadline.set(Some(core.clock.sleep(timeout)));
        }

        if *this.stage == Stage::Posting {
            if slot.poll_free(core.poster(attachment.at), cx).is_ready() {
                let request = this.request.take().expect("a request waits to be posted");
                // SAFETY: the end is its slot's only poster (one end per slot, borrowed
                // mutably by this future).
                match unsafe { slot.post(request, core.ticket(attachment.at)) } {
                    Ok(()) => {
                        *this.stage = Stage::Posted;
                        core.wake_servers_of(attachment.at);
                    }
                    Err(request) => *this.request = Some(request),
                }
            }
            if *this.stage == Stage::Posting {
                let gone = attachment.peer_gone();
                if gone.is_none() && !deadline_passed(this.deadline.as_mut(), cx) {
                    return Poll::Pending;
                }
                *this.stage = Stage::Done;
                let request = this.request.take().expect("an unposted request is kept");
                let failure = match gone {
                    Some(gone) => Failure::gone(request, gone),
                    None => Failure::Timeout(request),
                };
                return Poll::Ready(O::failed(failure, port));
            }
        }
        if *this.stage != Stage::Posted {
            panic!("a send or query polled after it completed");
        }

        let spins = attachment.spins();
        for _ in 0..spins {
            // SAFETY: as above, and the request is in the slot.
            if let Some(answer) = unsafe { slot.try_answer() } {
                *this.stage = Stage::Done;
                return Poll::Ready(finish::<Req, Rep, O>(answer, port));
            }
            attachment.pump();
            std::hint::spin_loop();
        }
        if spins > 0 {
            attachment.parking();
        }
        // SAFETY: as above.
        if let Poll::Ready(answer) = unsafe { slot.poll_answer(core.poster(attachment.at), cx) } {
            *this.stage = Stage::Done;
            return Poll::Ready(finish::<Req, Rep, O>(answer, port));
        }
        // Only a request nobody took is failed for a gone peer: one that was taken is
        // answered, or its dropped reply handle says `NoReply`.
        let gone = slot.posted_ticket().and_then(|_| attachment.peer_gone());
        if gone.is_none() && !deadline_passed(this.deadline.as_mut(), cx) {
            return Poll::Pending;
        }
        *this.stage = Stage::Done;
        // SAFETY: as above.
        let withdrawn = unsafe { slot.withdraw() };
        Poll::Ready(match (withdrawn, gone) {
            (Withdrawn::Unsent(request), Some(gone)) => {
                O::failed(Failure::gone(request, gone), port)
            }
            (Withdrawn::Unsent(request), None) => O::failed(Failure::Timeout(request), port),
            (Withdrawn::Abandoned, Some(_)) => O::failed(Failure::Unanswered, port),
            (Withdrawn::Abandoned, None) => O::failed(Failure::AnswerTimeout, port),
            // The answer beat the timeout: it wins.
            (Withdrawn::Answered(answer), _) => finish::<Req, Rep, O>(answer, port),
        })
    }
}

fn finish<Req, Rep, O: Outcome<Req, Rep>>(answer: Answer<Rep>, port: &Name) -> O::Output {
    match answer {
        Answer::Replied(reply) => O::answered(reply),
        Answer::Unreplied => O::failed(Failure::Unanswered, port),
    }
}
