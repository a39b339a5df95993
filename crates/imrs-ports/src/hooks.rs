//! What transports and filters add to a port: the lender of a sender's memory, the hand a
//! broadcast passes through, the pump of a spinning wait, the server of posts in place.
//!
//! Most ports have none of them, and every idle module carries its ports: kept in one
//! allocation made when the first is set, they cost such a port one word in place of four
//! cells of their own.

use std::sync::{Arc, OnceLock};

use crate::inline::ServeInline;
use crate::pump::Pump;
use crate::shared::Lender;

/// How a port's transport takes a broadcast before it is cloned for each user
/// ([`Port::broadcast_with`](crate::transport::PortTransport::broadcast_with)).
pub(crate) type Handing<Req> = Box<dyn Fn(Req) -> Req + Send + Sync>;

/// A port's hooks, each set once: the first set holds, for every handle of the port.
pub(crate) struct Hooks<Req, Rep> {
    /// Where a sender's messages are built, if a transport lends memory of its own
    /// ([`Port::lend_with`](crate::transport::PortTransport::lend_with)).
    pub(crate) lender: OnceLock<Lender<Req>>,
    /// Where a broadcast is moved before it is cloned for each user, if a transport says
    /// ([`Port::broadcast_with`](crate::transport::PortTransport::broadcast_with)).
    pub(crate) handing: OnceLock<Handing<Req>>,
    /// The transport's turn in a spinning wait, if a transport gives one
    /// ([`Port::pump_with`](crate::transport::PortTransport::pump_with)).
    pub(crate) pump: OnceLock<Box<dyn Pump>>,
    /// What answers posts in the poster's own poll, if anything does (a bounded buffer's
    /// ports).
    pub(crate) inline: OnceLock<Arc<dyn ServeInline<Req, Rep>>>,
}

impl<Req, Rep> Default for Hooks<Req, Rep> {
    fn default() -> Self {
        Self {
            lender: OnceLock::new(),
            handing: OnceLock::new(),
            pump: OnceLock::new(),
            inline: OnceLock::new(),
        }
    }
}
