//! Links that fail, through a relay of our own (`common/relay.rs`): a link that delays and
//! stalls as a lossy one does, and a partition mid-rendezvous that heals. Nothing accepted is
//! lost, nothing is served twice, and timeouts fire as declared. The relay waits for real:
//! it stands for the network, whose time is the wall clock's.

mod common;

use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use common::relay::{Impairment, Relay};
use common::{PROMPTLY, listening, within};
use imrs_ports::{AnyUser, Port, PortSpec, ReceiveError, SendError, usage};
use imrs_testkit::free_endpoint;
use imrs_zenoh::{Host, Imported, export, import};

/// How many times the owner served each request, by its number.
type Served = Arc<Mutex<HashMap<u64, u32>>>;

/// The replies the owner holds back (to requests for 0), until the test lets them go.
type Held = Arc<Mutex<Vec<imrs_ports::ReplyHandle<u64>>>>;

/// Exports DOUBLE on `host`: its owner counts each request and answers twice it, except 0,
/// whose reply it holds back; when its user's host is gone, it waits for the next.
async fn doubler(host: &Host) -> (imrs_zenoh::Exported, Served, Held) {
    let port: Port<u64, u64, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("DOUBLE", "DOUBLER"));
    let exported = export(host, &port).await.unwrap();
    let served = Served::default();
    let mut owner = port.owner().unwrap();
    let counting = Arc::clone(&served);
    let held = Held::default();
    let holding = Arc::clone(&held);
    tokio::spawn(async move {
        loop {
            match owner.receive().await {
                Ok((n, reply)) => {
                    *counting.lock().unwrap().entry(n).or_default() += 1;
                    if n == 0 {
                        holding.lock().unwrap().push(reply);
                    } else {
                        reply.reply(2 * n);
                    }
                }
                // Its user's host is gone; it serves the next one that comes.
                Err(ReceiveError::PeerGone { .. }) => owner.peer_attached().await,
                Err(_) => break,
            }
        }
    });
    (exported, served, held)
}

/// The loopback address an endpoint from [`free_endpoint`] listens on.
fn address(endpoint: &str) -> String {
    endpoint.trim_start_matches("tcp/").to_owned()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn through_delays_and_stalls_each_request_is_served_once_and_timeouts_hold() {
    let endpoint = free_endpoint();
    let owner_host = listening("lossy_cell", &endpoint).await;
    let (_exported, served, _) = doubler(&owner_host).await;
    let slow: Port<u64, u64, usage::Receive> =
        Port::new(PortSpec::new("SLOW", "SLUGGARD").user_timeout(Duration::from_millis(300)));
    let _slow = export(&owner_host, &slow).await.unwrap();
    let _sluggard = slow.owner().unwrap(); // attached, never receiving
    let relay = Relay::start(
        address(&endpoint),
        Impairment {
            delay: Duration::from_millis(2),
            stall_one_in: 10,
            stall: Duration::from_millis(150),
        },
    )
    .await;
    let user_host = Host::builder("lossy_cell")
        .connect(&relay.endpoint)
        .open()
        .await
        .unwrap();
    let imported: Imported<u64, u64, usage::Receive> =
        import(&user_host, "DOUBLE", "DOUBLER", "ASKER")
            .await
            .unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    for n in 1..=100 {
        let doubled = within(PROMPTLY, "a round trip through the relay", asker.send(n)).await;
        assert_eq!(doubled.unwrap(), 2 * n);
    }
    let served = served.lock().unwrap().clone();
    assert_eq!(served.len(), 100);
    assert!(served.values().all(|&times| times == 1), "{served:?}");

    let imported_slow: Imported<u64, u64, usage::Receive> =
        import(&user_host, "SLOW", "SLUGGARD", "ASKER")
            .await
            .unwrap();
    let mut slow_asker = imported_slow.port().user_named("ASKER").unwrap();
    for _ in 0..3 {
        let started = Instant::now();
        let late = within(PROMPTLY, "a send past its timeout", slow_asker.send(1)).await;
        let took = started.elapsed();
        assert!(
            matches!(late, Err(SendError::ReplyTimeout { .. })),
            "{late:?}"
        );
        assert!(took >= Duration::from_millis(300), "{took:?}");
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_partition_mid_rendezvous_ends_waits_and_its_heal_is_served() {
    let endpoint = free_endpoint();
    let owner_host = listening("split_cell", &endpoint).await;
    let (_exported, served, held_back) = doubler(&owner_host).await;
    let relay = Relay::start(
        address(&endpoint),
        Impairment {
            delay: Duration::ZERO,
            stall_one_in: 0,
            stall: Duration::ZERO,
        },
    )
    .await;
    let user_host = Host::builder("split_cell")
        .connect(&relay.endpoint)
        .open()
        .await
        .unwrap();
    let imported: Imported<u64, u64, usage::Receive> =
        import(&user_host, "DOUBLE", "DOUBLER", "ASKER")
            .await
            .unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    assert_eq!(
        within(PROMPTLY, "a round trip", asker.send(4))
            .await
            .unwrap(),
        8
    );
    let lease = user_host.lease();
    // 0 is taken and held by the owner; the link is cut while its sender waits.
    let cut = async {
        while !served.lock().unwrap().contains_key(&0) {
            tokio::task::yield_now().await;
        }
        relay.partition();
    };
    let (held, ()) = tokio::join!(
        within(2 * lease + PROMPTLY, "the held send", asker.send(0)),
        cut
    );
    assert!(matches!(held, Err(SendError::NoReply { .. })), "{held:?}");
    let gone = within(2 * lease + PROMPTLY, "the owner seen gone", async {
        loop {
            match asker.send(1).await {
                Err(SendError::PeerGone { module, .. }) => break module,
                _ => tokio::task::yield_now().await,
            }
        }
    })
    .await;
    assert_eq!(gone.as_str(), "DOUBLER");
    // The owner answers the held request now: too late, its sender has been told
    // `NoReply`, and the answer goes no further than the owner's host.
    for reply in held_back.lock().unwrap().drain(..) {
        let _ = reply.reply(0);
    }
    relay.heal();
    let doubled = within(2 * lease + PROMPTLY, "the healed link served", async {
        loop {
            if let Ok(doubled) = asker.send(21).await {
                break doubled;
            }
            tokio::task::yield_now().await;
        }
    })
    .await;
    assert_eq!(doubled, 42);
    // Nothing was served twice: the held request once, each other at most once.
    let served = served.lock().unwrap().clone();
    assert!(served.values().all(|&times| times == 1), "{served:?}");
    assert_eq!(served.get(&0), Some(&1));
}
