//! One error type per primitive. Every error names its port; an error on a message that was
//! never delivered hands the message back.

use std::error::Error;
use std::fmt;

use crate::name::Name;
use crate::usage::UsageKind;

/// Why nobody can serve or answer a waiter any more.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Gone {
    /// No end is attached on the other side and no declaration is left to attach one.
    Closed,
    /// The module that held the other side has ended for good.
    Peer(Name),
}

/// Why a [`send`](crate::End::send) failed.
pub enum SendError<T> {
    /// No receiver took the message before the port's timeout; here it is back.
    Timeout {
        /// The port.
        port: Name,
        /// The message, undelivered.
        message: T,
    },
    /// A receiver took the message but did not reply before the port's timeout.
    ReplyTimeout {
        /// The port.
        port: Name,
    },
    /// The receiver dropped its reply handle without replying.
    NoReply {
        /// The port.
        port: Name,
    },
    /// Nobody can ever receive on this port again; here is the message back.
    Closed {
        /// The port.
        port: Name,
        /// The message, undelivered.
        message: T,
    },
    /// The module that received on this port has ended for good (finished, failed beyond
    /// its restart policy, or killed with no restart coming); here is the message back.
    PeerGone {
        /// The port.
        port: Name,
        /// The module that is gone.
        module: Name,
        /// The message, undelivered.
        message: T,
    },
}

/// Why a [`query`](crate::End::query) failed.
pub enum QueryError<T> {
    /// No response handler took the query before the port's timeout; here it is back.
    Timeout {
        /// The port.
        port: Name,
        /// The query, unanswered.
        query: T,
    },
    /// The response handler started but did not finish before the port's timeout.
    ResponseTimeout {
        /// The port.
        port: Name,
    },
    /// The response handler gave no answer (it panicked, or its module died).
    NoResponse {
        /// The port.
        port: Name,
    },
    /// Nobody can ever respond on this port again; here is the query back.
    Closed {
        /// The port.
        port: Name,
        /// The query, unanswered.
        query: T,
    },
    /// The module whose handler answered this port has ended for good; here is the query
    /// back.
    PeerGone {
        /// The port.
        port: Name,
        /// The module that is gone.
        module: Name,
        /// The query, unanswered.
        query: T,
    },
}

/// Why a [`send_all`](crate::End::send_all) or [`call_all`](crate::End::call_all) failed.
pub enum BroadcastError<T> {
    /// No user answered before the port's timeout; here is the message back.
    Timeout {
        /// The port.
        port: Name,
        /// The message.
        message: T,
    },
    /// Every user that took the message dropped it without an answer.
    NoReply {
        /// The port.
        port: Name,
    },
    /// The port has no user to broadcast to; here is the message back.
    NoUsers {
        /// The port.
        port: Name,
        /// The message, undelivered.
        message: T,
    },
}

/// Why a [`receive`](crate::End::receive), or a response end's wait for a query, failed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ReceiveError {
    /// No message arrived before the port's timeout.
    Timeout {
        /// The port.
        port: Name,
    },
    /// Nobody can ever send on this port again.
    Closed {
        /// The port.
        port: Name,
    },
    /// Every module that sent (or queried) on this port has ended for good.
    PeerGone {
        /// The port.
        port: Name,
        /// A module that is gone.
        module: Name,
    },
}

/// A problem found when a port end is attached: the seed's load-time errors.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum WireError {
    /// The port was declared with a typed user list and a named one.
    TwoUserLists {
        /// The port.
        port: Name,
    },
    /// No port of that name was declared.
    UnknownPort {
        /// The port asked for.
        port: Name,
        /// The module that asked.
        module: Name,
    },
    /// A second port was declared under a name already taken.
    DuplicatePort {
        /// The port.
        port: Name,
        /// The module that declared it again.
        module: Name,
    },
    /// The port already has its owner end attached.
    OwnerTaken {
        /// The port.
        port: Name,
        /// The module that tried to own it too.
        module: Name,
    },
    /// The module is not on the port's user list.
    NotOnUserList {
        /// The port.
        port: Name,
        /// The module refused.
        module: Name,
    },
    /// The port already has as many active users as it was declared for.
    TooManyUsers {
        /// The port.
        port: Name,
        /// The module refused.
        module: Name,
        /// The declared number of users.
        capacity: usize,
    },
    /// The user's usage does not complement the owner's.
    UsageMismatch {
        /// The port.
        port: Name,
        /// The user module.
        module: Name,
        /// What the owner declared.
        owner: UsageKind,
        /// What the user declared.
        user: UsageKind,
    },
    /// The user expects other message types than the port carries.
    TypeMismatch {
        /// The port.
        port: Name,
        /// The user module.
        module: Name,
        /// The port's request and reply types.
        declared: String,
        /// The user's request and reply types.
        used: String,
    },
    /// A module attached the owner end of a port that another module owns.
    NotOwner {
        /// The port.
        port: Name,
        /// The module that tried.
        module: Name,
        /// The port's owner.
        owner: Name,
    },
    /// The port runs its timeouts on another clock than the cell it is declared to: on a
    /// virtual clock, its timeouts would never fire (or fire in wall time).
    OtherClock {
        /// The port.
        port: Name,
    },
}

impl<T> SendError<T> {
    /// Whether the peer is gone for good: the port is closed, or its module has ended.
    pub fn is_peer_gone(&self) -> bool {
        matches!(self, Self::Closed { .. } | Self::PeerGone { .. })
    }

    /// The port the send was on.
    pub fn port(&self) -> &Name {
        match self {
            Self::Timeout { port, .. }
            | Self::ReplyTimeout { port }
            | Self::NoReply { port }
            | Self::Closed { port, .. }
            | Self::PeerGone { port, .. } => port,
        }
    }

    /// Whether the port's timeout ran out (the seed's `PORT.TIMEOUT`).
    pub fn is_timeout(&self) -> bool {
        matches!(self, Self::Timeout { .. } | Self::ReplyTimeout { .. })
    }

    /// The undelivered message, if it was never delivered.
    pub fn into_message(self) -> Option<T> {
        match self {
            Self::Timeout { message, .. }
            | Self::Closed { message, .. }
            | Self::PeerGone { message, .. } => Some(message),
            Self::ReplyTimeout { .. } | Self::NoReply { .. } => None,
        }
    }
}

impl<T> QueryError<T> {
    /// Whether the peer is gone for good: the port is closed, or its module has ended.
    pub fn is_peer_gone(&self) -> bool {
        matches!(self, Self::Closed { .. } | Self::PeerGone { .. })
    }

    /// The port the query was on.
    pub fn port(&self) -> &Name {
        match self {
            Self::Timeout { port, .. }
            | Self::ResponseTimeout { port }
            | Self::NoResponse { port }
            | Self::Closed { port, .. }
            | Self::PeerGone { port, .. } => port,
        }
    }

    /// Whether the port's timeout ran out (the seed's `PORT.TIMEOUT`).
    pub fn is_timeout(&self) -> bool {
        matches!(self, Self::Timeout { .. } | Self::ResponseTimeout { .. })
    }

    /// The unanswered query, if no handler ever took it.
    pub fn into_query(self) -> Option<T> {
        match self {
            Self::Timeout { query, .. }
            | Self::Closed { query, .. }
            | Self::PeerGone { query, .. } => Some(query),
            Self::ResponseTimeout { .. } | Self::NoResponse { .. } => None,
        }
    }
}

impl<T> BroadcastError<T> {
    /// The port of the broadcast.
    pub fn port(&self) -> &Name {
        match self {
            Self::Timeout { port, .. } | Self::NoReply { port } | Self::NoUsers { port, .. } => {
                port
            }
        }
    }

    /// Whether the port's timeout ran out.
    pub fn is_timeout(&self) -> bool {
        matches!(self, Self::Timeout { .. })
    }

    /// The message, if no user answered it.
    pub fn into_message(self) -> Option<T> {
        match self {
            Self::Timeout { message, .. } | Self::NoUsers { message, .. } => Some(message),
            Self::NoReply { .. } => None,
        }
    }
}

impl ReceiveError {
    /// The error for a wait whose peers are gone for good, as `gone` says why.
    pub(crate) fn gone(port: &Name, gone: Gone) -> Self {
        let port = port.clone();
        match gone {
            Gone::Closed => Self::Closed { port },
            Gone::Peer(module) => Self::PeerGone { port, module },
        }
    }

    /// Whether the peer is gone for good: the port is closed, or every sender has ended.
    pub fn is_peer_gone(&self) -> bool {
        matches!(self, Self::Closed { .. } | Self::PeerGone { .. })
    }

    /// The port the receive was on.
    pub fn port(&self) -> &Name {
        match self {
            Self::Timeout { port } | Self::Closed { port } | Self::PeerGone { port, .. } => port,
        }
    }

    /// Whether the port's timeout ran out.
    pub fn is_timeout(&self) -> bool {
        matches!(self, Self::Timeout { .. })
    }
}

impl<T> fmt::Display for SendError<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Timeout { port, .. } => {
                write!(
                    f,
                    "send on port {port} timed out before a receiver took the message"
                )
            }
            Self::ReplyTimeout { port } => {
                write!(f, "send on port {port} timed out waiting for the reply")
            }
            Self::NoReply { port } => {
                write!(
                    f,
                    "the receiver on port {port} dropped the message without replying"
                )
            }
            Self::Closed { port, .. } => write!(f, "port {port} has no receiver any more"),
            Self::PeerGone { port, module, .. } => write!(
                f,
                "module {module}, the receiver on port {port}, has ended for good"
            ),
        }
    }
}

impl<T> fmt::Display for QueryError<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Timeout { port, .. } => {
                write!(
                    f,
                    "query on port {port} timed out before a response handler ran"
                )
            }
            Self::ResponseTimeout { port } => {
                write!(
                    f,
                    "query on port {port} timed out waiting for the response handler"
                )
            }
            Self::NoResponse { port } => {
                write!(f, "the response handler of port {port} gave no answer")
            }
            Self::Closed { port, .. } => write!(f, "port {port} has no response handler any more"),
            Self::PeerGone { port, module, .. } => write!(
                f,
                "module {module}, the responder on port {port}, has ended for good"
            ),
        }
    }
}

impl<T> fmt::Display for BroadcastError<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Timeout { port, .. } => write!(f, "no user of port {port} answered in time"),
            Self::NoReply { port } => write!(f, "no user of port {port} answered"),
            Self::NoUsers { port, .. } => write!(f, "port {port} has no users to broadcast to"),
        }
    }
}

impl fmt::Display for ReceiveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Timeout { port } => write!(f, "receive on port {port} timed out"),
            Self::Closed { port } => write!(f, "port {port} has no sender any more"),
            Self::PeerGone { port, module } => write!(
                f,
                "module {module}, the last sender on port {port}, has ended for good"
            ),
        }
    }
}

/// Why a remote module's claim on a port was refused ([`Port::claim`]): the module's name
/// is kept as text, so that a refused name is never made.
///
/// [`Port::claim`]: crate::Port::claim
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ClaimRefused {
    /// The module is not on the port's user list.
    NotOnUserList {
        /// The port.
        port: Name,
        /// The module refused, as claimed.
        module: String,
    },
    /// Every user place of the port is taken.
    Full {
        /// The port.
        port: Name,
        /// The module refused, as claimed.
        module: String,
        /// The declared number of users.
        capacity: usize,
    },
    /// The module's name would be one more than the process keeps from peers
    /// ([`Name::MOST_FROM_PEERS`]): a port without a user list met that many new names.
    TooManyNames {
        /// The port.
        port: Name,
        /// The module refused, as claimed.
        module: String,
    },
}

impl fmt::Display for ClaimRefused {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotOnUserList { port, module } => {
                write!(f, "module {module} is not on the user list of port {port}")
            }
            Self::Full {
                port,
                module,
                capacity,
            } => write!(
                f,
                "module {module} cannot use port {port}: it allows {capacity} active user(s) and all are attached"
            ),
            Self::TooManyNames { port, module } => write!(
                f,
                "module {module} cannot use port {port}: this process already keeps {} module \
                 names its peers made; give port {port} a user list",
                Name::MOST_FROM_PEERS
            ),
        }
    }
}

impl Error for ClaimRefused {}

impl fmt::Display for WireError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TwoUserLists { port } => write!(
                f,
                "port {port} is declared with a typed user list and a named one: keep one"
            ),
            Self::UnknownPort { port, module } => {
                write!(
                    f,
                    "module {module} uses port {port}, which no module declares"
                )
            }
            Self::DuplicatePort { port, module } => {
                write!(
                    f,
                    "module {module} declares port {port}, which is already declared"
                )
            }
            Self::OwnerTaken { port, module } => {
                write!(
                    f,
                    "module {module} cannot own port {port}: its owner end is already attached"
                )
            }
            Self::NotOnUserList { port, module } => {
                write!(f, "module {module} is not on the user list of port {port}")
            }
            Self::TooManyUsers {
                port,
                module,
                capacity,
            } => write!(
                f,
                "module {module} cannot use port {port}: it allows {capacity} active user(s) and all are attached"
            ),
            Self::UsageMismatch {
                port,
                module,
                owner,
                user,
            } => write!(
                f,
                "module {module} uses port {port} with USAGE={user}, which does not complement the owner's USAGE={owner}"
            ),
            Self::TypeMismatch {
                port,
                module,
                declared,
                used,
            } => write!(
                f,
                "module {module} uses port {port} as {used}, but it is declared as {declared}"
            ),
            Self::NotOwner {
                port,
                module,
                owner,
            } => write!(
                f,
                "module {module} attached the owner end of port {port}, which {owner} owns"
            ),
            Self::OtherClock { port } => write!(
                f,
                "port {port} runs on another clock than its cell: make it with `Cell::port`, \
                 which gives it the cell's clock"
            ),
        }
    }
}

macro_rules! debug_without_payload {
    ($($ty:ident { $($variant:ident),* })*) => {$(
        impl<T> fmt::Debug for $ty<T> {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                let variant = match self { $(Self::$variant { .. } => stringify!($variant)),* };
                f.debug_struct(concat!(stringify!($ty), "::"))
                    .field("kind", &variant)
                    .field("port", self.port())
                    .finish_non_exhaustive()
            }
        }
        impl<T> Error for $ty<T> {}
    )*};
}

debug_without_payload! {
    SendError { Timeout, ReplyTimeout, NoReply, Closed, PeerGone }
    QueryError { Timeout, ResponseTimeout, NoResponse, Closed, PeerGone }
    BroadcastError { Timeout, NoReply, NoUsers }
}

impl Error for ReceiveError {}
impl Error for WireError {}
