//! `select` over guarded alternatives (Shin 1985, §4.2): of the open alternatives that are
//! ready, take the one on the port of highest priority, FIFO within a port — never at random.
//!
//! ```
//! # use imrs_ports::{Port, PortSpec, usage, select, when};
//! # async fn run(
//! #     mut urgent: imrs_ports::End<u32, (), usage::Receive>,
//! #     mut routine: imrs_ports::End<&'static str, (), usage::Receive>,
//! # ) -> Result<(), imrs_ports::AllClosed> {
//! enum Event { Urgent(u32), Routine(&'static str) }
//! let room_left = true;
//! let event = select()
//!     .or(when(room_left, &mut urgent), |(n, reply)| { reply.reply(()); Event::Urgent(n) })
//!     .or(&mut routine, |(text, reply)| { reply.reply(()); Event::Routine(text) })
//!     .await?;
//! # let _ = event; Ok(())
//! # }
//! ```

use std::fmt;
use std::future::Future;
use std::pin::Pin;
use std::task::{Context, Poll};

use crate::end::End;
use crate::priority::Priority;
use crate::receive::{ReplyHandle, poll_take};
use crate::usage::Receives;

/// Something a [`select`] can wait on.
pub trait Alternative {
    /// What it yields when chosen.
    type Output;
    /// Its priority; `None` while its guard is closed.
    fn priority(&self) -> Option<Priority>;
    /// Takes its message if one is ready, or registers the task to be woken.
    fn poll_ready(&mut self, cx: &mut Context<'_>) -> Poll<Self::Output>;
    /// Whether nothing can ever be ready again (its port is closed for good). Asked after a
    /// [`poll_ready`](Alternative::poll_ready) that found nothing.
    fn is_closed(&self) -> bool {
        false
    }
}

impl<Req: Send + 'static, Rep: Send + 'static, U: Receives> Alternative for &mut End<Req, Rep, U> {
    type Output = (Req, ReplyHandle<Rep>);

    fn priority(&self) -> Option<Priority> {
        Some(End::priority(self))
    }

    fn poll_ready(&mut self, cx: &mut Context<'_>) -> Poll<Self::Output> {
        poll_take(&self.attachment, cx)
            .map(|(message, from)| (message, ReplyHandle::new(&self.attachment, from)))
    }

    fn is_closed(&self) -> bool {
        self.attachment.peer_gone().is_some() && !self.attachment.has_waiting()
    }
}

/// An alternative behind a guard: `WHEN condition ==> RECEIVE ...`.
#[derive(Debug)]
pub struct Guarded<A> {
    open: bool,
    alternative: A,
}

/// Guards `alternative` with `open`: a closed alternative is not waited on.
pub fn when<A: Alternative>(open: bool, alternative: A) -> Guarded<A> {
    Guarded { open, alternative }
}

impl<A: Alternative> Alternative for Guarded<A> {
    type Output = A::Output;

    fn priority(&self) -> Option<Priority> {
        self.open.then(|| self.alternative.priority()).flatten()
    }

    fn poll_ready(&mut self, cx: &mut Context<'_>) -> Poll<A::Output> {
        self.alternative.poll_ready(cx)
    }

    fn is_closed(&self) -> bool {
        self.alternative.is_closed()
    }
}

/// Every alternative of a `select` was closed, by its guard or because its port is closed
/// for good (no peer can ever come back to it): nothing could ever be chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct AllClosed;

impl fmt::Display for AllClosed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("every alternative of the select is closed, by its guard or for good")
    }
}

impl std::error::Error for AllClosed {}

/// A list of alternatives, each with the function that turns its message into `Out`.
/// Built by [`Select::or`]; the n-th `or` is arm n.
pub trait Arms<Out> {
    /// How many arms.
    const LEN: usize;
    /// The priority of arm `index`; `None` if its guard is closed.
    fn priority(&self, index: usize) -> Option<Priority>;
    /// Polls arm `index`.
    fn poll_arm(&mut self, index: usize, cx: &mut Context<'_>) -> Poll<Out>;
    /// Whether arm `index` can never be ready again.
    fn is_closed(&self, index: usize) -> bool;
}

impl<Out> Arms<Out> for () {
    const LEN: usize = 0;

    fn priority(&self, _: usize) -> Option<Priority> {
        None
    }

    fn poll_arm(&mut self, _: usize, _: &mut Context<'_>) -> Poll<Out> {
        Poll::Pending
    }

    fn is_closed(&self, _: usize) -> bool {
        true
    }
}

/// One arm: an alternative and what to make of its message.
///
/// The alternative's methods are taken as function pointers when the arm is added (where
/// `B: Alternative` is checked), so that the `select`'s own type does not need the bound
/// again: a misused alternative is reported once, at [`Select::or`], not again at `.await`.
pub struct Arm<B, F, Out> {
    alternative: B,
    then: F,
    poll: fn(&mut B, &mut F, &mut Context<'_>) -> Poll<Out>,
    priority: fn(&B) -> Option<Priority>,
    closed: fn(&B) -> bool,
}

impl<B: fmt::Debug, F, Out> fmt::Debug for Arm<B, F, Out> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Arm")
            .field("alternative", &self.alternative)
            .finish_non_exhaustive()
    }
}

fn poll_arm<B, F, Out>(alternative: &mut B, then: &mut F, cx: &mut Context<'_>) -> Poll<Out>
where
    B: Alternative,
    F: FnMut(B::Output) -> Out,
{
    alternative.poll_ready(cx).map(then)
}

impl<Out, Rest, B, F> Arms<Out> for (Rest, Arm<B, F, Out>)
where
    Rest: Arms<Out>,
{
    const LEN: usize = Rest::LEN + 1;

    fn priority(&self, index: usize) -> Option<Priority> {
        if index == Rest::LEN {
            (self.1.priority)(&self.1.alternative)
        } else {
            self.0.priority(index)
        }
    }

    fn poll_arm(&mut self, index: usize, cx: &mut Context<'_>) -> Poll<Out> {
        if index == Rest::LEN {
            let arm = &mut self.1;
            (arm.poll)(&mut arm.alternative, &mut arm.then, cx)
        } else {
            self.0.poll_arm(index, cx)
        }
    }

    fn is_closed(&self, index: usize) -> bool {
        if index == Rest::LEN {
            (self.1.closed)(&self.1.alternative)
        } else {
            self.0.is_closed(index)
        }
    }
}

/// A `select` under construction; await it to wait. See the [module docs](self).
#[must_use = "a select does nothing unless awaited"]
pub struct Select<Out, A> {
    arms: A,
    _out: std::marker::PhantomData<fn() -> Out>,
}

/// Starts a `select`; add alternatives with [`Select::or`], then await it.
pub fn select<Out>() -> Select<Out, ()> {
    Select {
        arms: (),
        _out: std::marker::PhantomData,
    }
}

impl<Out, A: Arms<Out>> Select<Out, A> {
    /// Adds an alternative, and what to make of its message. Among alternatives of equal
    /// priority, the one added first wins.
    pub fn or<B, F>(self, alternative: B, then: F) -> Select<Out, (A, Arm<B, F, Out>)>
    where
        B: Alternative,
        F: FnMut(B::Output) -> Out,
    {
        let arm = Arm {
            alternative,
            then,
            poll: poll_arm::<B, F, Out>,
            priority: B::priority,
            closed: B::is_closed,
        };
        Select {
            arms: (self.arms, arm),
            _out: std::marker::PhantomData,
        }
    }

    /// The open arm that comes next after `after` in the serving order: higher priority
    /// first, then the earlier arm. A handful of arms, so a scan beats sorting into a buffer.
    fn next_in_order(&self, after: Option<(Priority, usize)>) -> Option<(Priority, usize)> {
        let comes_before =
            |a: (Priority, usize), b: (Priority, usize)| a.0 > b.0 || (a.0 == b.0 && a.1 < b.1);
        (0..A::LEN)
            .filter_map(|index| Some((self.arms.priority(index)?, index)))
            .filter(|&arm| after.is_none_or(|after| comes_before(after, arm)))
            .reduce(|best, arm| if comes_before(arm, best) { arm } else { best })
    }
}

impl<Out, A: Arms<Out> + Unpin> Future for Select<Out, A> {
    type Output = Result<Out, AllClosed>;

    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Self::Output> {
        let this = self.get_mut();
        let mut cursor = this.next_in_order(None);
        if cursor.is_none() {
            return Poll::Ready(Err(AllClosed));
        }
        let mut all_closed = true;
        while let Some((priority, index)) = cursor {
            if let Poll::Ready(out) = this.arms.poll_arm(index, cx) {
                return Poll::Ready(Ok(out));
            }
            all_closed &= this.arms.is_closed(index);
            cursor = this.next_in_order(Some((priority, index)));
        }
        if all_closed {
            Poll::Ready(Err(AllClosed))
        } else {
            Poll::Pending
        }
    }
}

impl<Out, A> fmt::Debug for Select<Out, A> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Select").finish_non_exhaustive()
    }
}
