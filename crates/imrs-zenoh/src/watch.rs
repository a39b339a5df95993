//! A liveliness token watched: zenoh's events of it, checked against what is alive now.
//!
//! A host whose link came back declares its tokens anew, and the end of the old ones may be
//! heard after the new ones: an event that says a token is gone is believed only once a
//! liveliness query finds no token there.

use std::time::Duration;

use zenoh::sample::SampleKind;

use crate::ZenohError;

/// How long a liveliness query may take: it is answered from what this host knows.
const LOOK: Duration = Duration::from_secs(1);

/// Whether a token lives on `key` now, as far as this host knows.
pub(crate) async fn alive(session: &zenoh::Session, key: &str) -> bool {
    match session.liveliness().get(key).timeout(LOOK).await {
        Ok(replies) => replies.recv_async().await.is_ok(),
        Err(_) => false,
    }
}

/// The token on one key, watched.
pub(crate) struct Watch {
    subscriber:
        zenoh::pubsub::Subscriber<zenoh::handlers::FifoChannelHandler<zenoh::sample::Sample>>,
    session: zenoh::Session,
    key: String,
    /// A token's end taken from the subscriber and not yet confirmed: kept, so that a wait
    /// dropped while it confirms loses no event.
    unconfirmed: std::sync::atomic::AtomicBool,
}

impl Watch {
    /// Watches `key`, hearing first of a token already there.
    pub(crate) async fn new(session: &zenoh::Session, key: &str) -> Result<Self, ZenohError> {
        let subscriber = session
            .liveliness()
            .declare_subscriber(key)
            .history(true)
            .await
            .map_err(ZenohError::session)?;
        Ok(Self {
            subscriber,
            session: session.clone(),
            key: key.to_owned(),
            unconfirmed: std::sync::atomic::AtomicBool::new(false),
        })
    }

    /// Completes when the token is gone (true), or when nothing more can be heard of it
    /// (false: the session is closed).
    pub(crate) async fn gone(&self) -> bool {
        use std::sync::atomic::Ordering;
        loop {
            if self.unconfirmed.load(Ordering::SeqCst) {
                let gone = !alive(&self.session, &self.key).await;
                self.unconfirmed.store(false, Ordering::SeqCst);
                if gone {
                    return true;
                }
            }
            match self.subscriber.recv_async().await {
                Ok(sample) if sample.kind() == SampleKind::Delete => {
                    self.unconfirmed.store(true, Ordering::SeqCst);
                }
                Ok(_) => {}
                Err(_) => return false,
            }
        }
    }

    /// Completes when the token is there (true), or when nothing more can be heard of it
    /// (false).
    pub(crate) async fn back(&self) -> bool {
        self.unconfirmed
            .store(false, std::sync::atomic::Ordering::SeqCst);
        loop {
            match self.subscriber.recv_async().await {
                Ok(sample) if sample.kind() == SampleKind::Put => return true,
                Ok(_) => {}
                Err(_) => return false,
            }
        }
    }

    /// Watches port `port`'s owner's token at `key`, and waits at most `bound` until it is
    /// there; refused with [`ZenohError::NoOwner`] if it is not.
    pub(crate) async fn owner(
        session: &zenoh::Session,
        key: &str,
        port: &str,
        bound: Duration,
    ) -> Result<Self, ZenohError> {
        let watch = Self::new(session, key).await?;
        match tokio::time::timeout(bound, watch.back()).await {
            Ok(true) => Ok(watch),
            _ => Err(ZenohError::NoOwner {
                port: port.to_owned(),
            }),
        }
    }
}
