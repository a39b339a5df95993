//! Port usages (Shin 1985, restriction 2): which primitive an end may use.
//!
//! Each usage is a zero-sized marker. An end has only the methods of its usage, so a wrong
//! primitive does not compile, and a user end always gets the complement of the owner's
//! usage: send ↔ receive, query ↔ response. `SendAll` and `CallAll` are for owners only;
//! their users receive and respond.

use std::fmt;

mod sealed {
    pub trait Sealed {}
}

/// A port usage. Sealed: the six usages of the seed are all there are.
pub trait Usage: sealed::Sealed + core::marker::Send + Sync + 'static {
    /// The usage as a value, for wiring checks and messages.
    const KIND: UsageKind;
    /// The usage the other end of the port must have.
    type Complement: Usage;
}

/// A usage as a value: what the wiring compares when the types cannot.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum UsageKind {
    /// Blocking send, unblocked by the reply.
    Send,
    /// Blocking receive, answered later by a reply.
    Receive,
    /// Invoke the other end's response handler and wait for it.
    Query,
    /// Serve queries with a response handler.
    Response,
    /// Owner only: send to every user, unblock at the first reply.
    SendAll,
    /// Owner only: query every user, unblock at the first answer.
    CallAll,
}

impl UsageKind {
    /// Whether an owner declared `self` and a user declared `user` fit together.
    pub fn complements(self, user: UsageKind) -> bool {
        use UsageKind::*;
        matches!(
            (self, user),
            (Send | SendAll, Receive)
                | (Receive, Send)
                | (Query | CallAll, Response)
                | (Response, Query)
        )
    }
}

impl fmt::Display for UsageKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            UsageKind::Send => "SEND",
            UsageKind::Receive => "RECEIVE",
            UsageKind::Query => "QUERY",
            UsageKind::Response => "RESPONSE",
            UsageKind::SendAll => "SENDALL",
            UsageKind::CallAll => "CALLALL",
        })
    }
}

macro_rules! usages {
    ($($(#[$doc:meta])* $name:ident => $complement:ident;)*) => {$(
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
        pub struct $name;
        impl sealed::Sealed for $name {}
        impl Usage for $name {
            const KIND: UsageKind = UsageKind::$name;
            type Complement = $complement;
        }
    )*};
}

usages! {
    /// `USAGE=SEND`: the end sends and waits for the reply.
    Send => Receive;
    /// `USAGE=RECEIVE`: the end receives and replies later.
    Receive => Send;
    /// `USAGE=QUERY`: the end queries the other end's response handler.
    Query => Response;
    /// `USAGE=RESPONSE`: the end answers queries with its response handler.
    Response => Query;
    /// `USAGE=SENDALL`: the owner sends to every user at once.
    SendAll => Receive;
    /// `USAGE=CALLALL`: the owner queries every user at once.
    CallAll => Response;
}

/// Usages whose end may [`send`](crate::End::send).
#[diagnostic::on_unimplemented(
    message = "this port end cannot `send`: its usage is `{Self}`",
    label = "`send` needs an end whose usage is `usage::Send`",
    note = "the owner declares the port's usage and every user gets the complement: SEND <-> RECEIVE, QUERY <-> RESPONSE"
)]
pub trait Sends: Usage {}
impl Sends for Send {}

/// Usages whose end may [`receive`](crate::End::receive).
#[diagnostic::on_unimplemented(
    message = "this port end cannot `receive`: its usage is `{Self}`",
    label = "`receive` needs an end whose usage is `usage::Receive`",
    note = "the owner declares the port's usage and every user gets the complement: SEND <-> RECEIVE, QUERY <-> RESPONSE"
)]
pub trait Receives: Usage {}
impl Receives for Receive {}

/// Usages whose end may [`query`](crate::End::query).
#[diagnostic::on_unimplemented(
    message = "this port end cannot `query`: its usage is `{Self}`",
    label = "`query` needs an end whose usage is `usage::Query`",
    note = "`query` reaches the response handler at the other end of a QUERY port; a SEND end uses `send`, a CALLALL owner `call_all`"
)]
pub trait Queries: Usage {}
impl Queries for Query {}

/// Usages whose end may [`send_all`](crate::End::send_all).
#[diagnostic::on_unimplemented(
    message = "this port end cannot `send_all`: its usage is `{Self}`",
    label = "`send_all` needs an owner end whose usage is `usage::SendAll`"
)]
pub trait SendsAll: Usage {}
impl SendsAll for SendAll {}

/// Usages whose end may [`call_all`](crate::End::call_all).
#[diagnostic::on_unimplemented(
    message = "this port end cannot `call_all`: its usage is `{Self}`",
    label = "`call_all` needs an owner end whose usage is `usage::CallAll`"
)]
pub trait CallsAll: Usage {}
impl CallsAll for CallAll {}

/// Usages whose end is a plain end, built without a response handler.
#[diagnostic::on_unimplemented(
    message = "a `{Self}` end answers queries, so it must be built with its response handler",
    label = "this end would answer queries with no handler",
    note = "build it with `Port::answer(module, handler)`"
)]
pub trait Plain: Usage {}
impl Plain for Send {}
impl Plain for Receive {}
impl Plain for Query {}
impl Plain for SendAll {}
impl Plain for CallAll {}

/// Usages of a port whose one side answers queries with a response handler: a `RESPONSE`
/// owner, or the users of a `QUERY` or `CALLALL` port. [`Port::answer`](crate::Port::answer)
/// attaches the answering side, whichever it is.
#[diagnostic::on_unimplemented(
    message = "no end of a `{Self}` port answers queries",
    label = "`answer` needs a port declared `usage::Response`, `usage::Query` or `usage::CallAll`",
    note = "a response handler answers a QUERY or CALLALL port's users, or owns a RESPONSE port"
)]
pub trait Answers: Usage {
    /// Whether the answering side is the owner's.
    const OWNER_ANSWERS: bool;
}
impl Answers for Response {
    const OWNER_ANSWERS: bool = true;
}
impl Answers for Query {
    const OWNER_ANSWERS: bool = false;
}
impl Answers for CallAll {
    const OWNER_ANSWERS: bool = false;
}
