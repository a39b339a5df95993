//! What the tests across hosts share: free endpoints, hosts, and a bounded wait.

#![allow(dead_code)]

pub(crate) mod relay;

use std::net::TcpListener;
use std::time::Duration;

use imrs_zenoh::Host;

/// A TCP endpoint on loopback that nothing listens on now.
pub(crate) fn free_endpoint() -> String {
    let listener = TcpListener::bind("127.0.0.1:0").expect("a free port on loopback");
    let port = listener.local_addr().expect("its address").port();
    format!("tcp/127.0.0.1:{port}")
}

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
