//! A remote module's end of the real port, through which its requests go in; attached at
//! its first request, or refused with the status its process is told.

use std::collections::HashMap;
use std::sync::Arc;

use imrs_ports::{ClaimRefused, End, Name, WireError, usage};

use crate::wire::{NOT_ON_USER_LIST, REFUSED, TOO_MANY_NAMES, TOO_MANY_USERS};

/// A remote module's end of the real port, through which its requests go in.
pub(crate) trait Forward<Req, Rep>: Send + 'static {
    /// The request, as the module's primitive on this port; its reply, or `None`.
    fn forward(&mut self, request: Req) -> impl Future<Output = Option<Rep>> + Send + '_;
}

impl<Req: Send + 'static, Rep: Send + 'static> Forward<Req, Rep> for End<Req, Rep, usage::Send> {
    async fn forward(&mut self, request: Req) -> Option<Rep> {
        self.send(request).await.ok()
    }
}

/// A query: a remote user's to the owner of a `RESPONSE` port, or a remote owner's to the
/// one local user of a `QUERY` port, once that user has attached (the owner counts a remote
/// module attached from its connection; here the module attaches a moment later).
impl<Req: Send + 'static, Rep: Send + 'static> Forward<Req, Rep> for End<Req, Rep, usage::Query> {
    async fn forward(&mut self, request: Req) -> Option<Rep> {
        self.peer_attached().await;
        self.query(request).await.ok()
    }
}

/// Why a remote module could not be attached.
pub(crate) enum Refusal {
    /// The port's own wiring error.
    Wire(WireError),
    /// The module is not on the port's user list (its name, not kept).
    NotOnUserList,
    /// Every user place of the port is taken.
    Full {
        /// The port's number of users.
        capacity: usize,
    },
    /// The module's name would be one more than the process keeps from peers
    /// ([`Name::MOST_FROM_PEERS`]).
    TooManyNames,
    /// Something else failed (a relay back to the module's process).
    Failed,
}

impl From<ClaimRefused> for Refusal {
    fn from(refused: ClaimRefused) -> Self {
        match refused {
            ClaimRefused::NotOnUserList { .. } => Self::NotOnUserList,
            ClaimRefused::Full { capacity, .. } => Self::Full { capacity },
            ClaimRefused::TooManyNames { .. } => Self::TooManyNames,
        }
    }
}

impl From<WireError> for Refusal {
    fn from(error: WireError) -> Self {
        Self::Wire(error)
    }
}

/// The remote modules' ends, by module.
pub(super) type Users<E> = HashMap<String, Arc<tokio::sync::Mutex<E>>>;

/// The end of remote module `module`, attached at its first request; or the status of the
/// port's refusal.
pub(super) fn user<E>(
    attach: &mut impl FnMut(&str) -> Result<E, Refusal>,
    users: &mut Users<E>,
    module: &str,
) -> Result<Arc<tokio::sync::Mutex<E>>, (u32, u32)> {
    if let Some(end) = users.get(module) {
        return Ok(Arc::clone(end));
    }
    match attach(module) {
        Ok(end) => {
            let end = Arc::new(tokio::sync::Mutex::new(end));
            users.insert(module.to_owned(), Arc::clone(&end));
            Ok(end)
        }
        Err(Refusal::Wire(WireError::NotOnUserList { .. }) | Refusal::NotOnUserList) => {
            Err((NOT_ON_USER_LIST, 0))
        }
        Err(
            Refusal::Wire(WireError::TooManyUsers { capacity, .. }) | Refusal::Full { capacity },
        ) => Err((TOO_MANY_USERS, u32::try_from(capacity).unwrap_or(u32::MAX))),
        Err(Refusal::TooManyNames) => Err((
            TOO_MANY_NAMES,
            u32::try_from(Name::MOST_FROM_PEERS).unwrap_or(u32::MAX),
        )),
        Err(_) => Err((REFUSED, 0)),
    }
}
