//! What every exported port has, whatever its usage: no other host exporting it, a
//! queryable where modules connect, a watch on the tokens of the hosts that use it, and the
//! owner's token, declared once the port is served.

use tokio::task::JoinHandle;
use zenoh::handlers::FifoChannelHandler;
use zenoh::query::{Query, Queryable};
use zenoh::sample::{Sample, SampleKind};

use crate::key::Keys;
use crate::watch::alive;
use crate::{Host, ZenohError};

/// A port being exported: its keys, the queryable modules connect on, and the tokens of
/// its users' hosts.
pub(crate) struct Opening {
    pub(crate) keys: Keys,
    pub(crate) connects: Queryable<FifoChannelHandler<Query>>,
    pub(crate) leaving: Leaving,
}

/// The tokens of the hosts that use a port, watched.
pub(crate) type Leaving = zenoh::pubsub::Subscriber<FifoChannelHandler<Sample>>;

impl Opening {
    /// Opens `port` on `host`; refused if another host exports it already, as far as this
    /// host has heard.
    pub(crate) async fn new(host: &Host, port: &str) -> Result<Self, ZenohError> {
        let keys = Keys::new(&host.cell, port)?;
        host.carries(port)?;
        let session = &host.session;
        let others = session
            .liveliness()
            .get(&keys.live)
            .await
            .map_err(ZenohError::session)?;
        if others.recv_async().await.is_ok() {
            return Err(ZenohError::Refused {
                port: port.to_owned(),
                reason: "another host exports it already".to_owned(),
            });
        }
        let connects = session
            .declare_queryable(keys.connects())
            .await
            .map_err(ZenohError::session)?;
        let leaving = session
            .liveliness()
            .declare_subscriber(format!("{}/*", keys.user_prefix()))
            .await
            .map_err(ZenohError::session)?;
        Ok(Self {
            keys,
            connects,
            leaving,
        })
    }
}

/// Declares the owner's token at `keys`: to be done once everything that serves the port is
/// declared, since a host that sees the token then sees the rest (zenoh carries one host's
/// declarations to another in order).
pub(crate) async fn live(
    host: &Host,
    keys: &Keys,
) -> Result<zenoh::liveliness::LivelinessToken, ZenohError> {
    host.session
        .liveliness()
        .declare_token(&keys.live)
        .await
        .map_err(ZenohError::session)
}

/// Calls `gone` with each module whose host's token is gone (a liveliness query confirms
/// each end heard), until the session closes.
pub(crate) fn watch_users(
    host: &Host,
    leaving: Leaving,
    gone: impl Fn(&str) + Send + 'static,
) -> JoinHandle<()> {
    let session = host.session.clone();
    tokio::spawn(async move {
        while let Ok(sample) = leaving.recv_async().await {
            let key = sample.key_expr().as_str();
            if sample.kind() == SampleKind::Delete
                && !alive(&session, key).await
                && let Some(module) = key.rsplit('/').next()
            {
                gone(module);
            }
        }
    })
}
