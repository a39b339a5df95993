//! A module of another host watched from the host that exports a port it uses
//! ([`Exported::watch_user`](crate::Exported::watch_user)): for a supervisor that must act
//! when a host is gone, whether killed or cut off.

use zenoh::handlers::FifoChannelHandler;
use zenoh::sample::{Sample, SampleKind};

use crate::key::{Keys, checked};
use crate::watch::alive;
use crate::{Host, ZenohError};

/// Module `module`'s presence on port `port`, as its host's liveliness token shows it.
pub struct UserWatch {
    subscriber: zenoh::pubsub::Subscriber<FifoChannelHandler<Sample>>,
    session: zenoh::Session,
    key: String,
}

impl std::fmt::Debug for UserWatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("UserWatch").field("key", &self.key).finish()
    }
}

impl UserWatch {
    /// Watches module `module`, which uses port `port` from another host of `host`'s cell.
    pub(crate) async fn new(host: &Host, port: &str, module: &str) -> Result<Self, ZenohError> {
        let key = Keys::new(&host.cell, port)?.user(checked("module", module)?);
        let subscriber = host
            .session
            .liveliness()
            .declare_subscriber(&key)
            .await
            .map_err(ZenohError::session)?;
        Ok(Self {
            subscriber,
            session: host.session.clone(),
            key,
        })
    }

    /// Until the module's host is seen gone: killed, closed, or cut off for longer than its
    /// lease. A token's end is confirmed (a host that imported the port again at once is
    /// not gone). Also ends when this host's session closes.
    pub async fn gone(&mut self) {
        while let Ok(sample) = self.subscriber.recv_async().await {
            if sample.kind() == SampleKind::Delete && !alive(&self.session, &self.key).await {
                return;
            }
        }
    }

    /// Whether the module's host is there now.
    pub async fn is_there(&self) -> bool {
        alive(&self.session, &self.key).await
    }
}
