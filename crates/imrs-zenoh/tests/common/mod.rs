//! What the tests across hosts share: hosts, and a bounded wait. Their free endpoints come
//! from `imrs_testkit::free_endpoint`.

#![allow(dead_code)]

pub(crate) mod relay;

use std::time::Duration;

use imrs_zenoh::Host;

/// Two hosts of `cell`: the first listens on `endpoint`, the second connects to it.
pub(crate) async fn two_hosts(cell: &str, endpoint: &str) -> (Host, Host) {
    let owner = listening(cell, endpoint).await;
    let user = Host::builder(cell).connect(endpoint).open().await.unwrap();
    (owner, user)
}

/// A host of `cell` listening on `endpoint`.
pub(crate) async fn listening(cell: &str, endpoint: &str) -> Host {
    Host::builder(cell).listen(endpoint).open().await.unwrap()
}

/// What the network may take for something that happens at once: a bound on a wait for
/// it, never a delay.
pub(crate) const PROMPTLY: Duration = Duration::from_secs(10);

/// `future`, or a failure naming `what` if it takes longer than `bound`.
pub(crate) async fn within<F: Future>(bound: Duration, what: &str, future: F) -> F::Output {
    tokio::time::timeout(bound, future)
        .await
        .unwrap_or_else(|_| panic!("{what} took longer than {bound:?}"))
}
