//! Hosts apart: the owner's host in a process of its own (`zenoh_peer`), killed with
//! SIGKILL; and in a network namespace of its own, joined by a veth link that is set down
//! mid-rendezvous and brought back. Where namespaces cannot be made (not root, no `ip`),
//! the namespace test says so loudly and runs over loopback, its cut made by a kill.

mod common;

use std::process::Stdio;
use std::time::Duration;

use common::{PROMPTLY, within};
use imrs_ports::{SendError, usage};
use imrs_testkit::free_endpoint;
use imrs_zenoh::netns::Netns;
use imrs_zenoh::{Host, Imported, import};
use tokio::io::{AsyncBufReadExt, AsyncReadExt, BufReader};
use tokio::process::{Child, Command};

/// The owner's host, `zenoh_peer`, started (inside `netns` if given) and ready.
async fn peer(cell: &str, endpoint: &str, netns: Option<&str>) -> Child {
    let exe = env!("CARGO_BIN_EXE_zenoh_peer");
    let mut command = match netns {
        Some(ns) => {
            let mut c = Command::new("ip");
            c.args(["netns", "exec", ns, exe]);
            c
        }
        None => Command::new(exe),
    };
    let mut child = command
        .args([cell, endpoint])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .kill_on_drop(true)
        .spawn()
        .expect("zenoh_peer starts");
    let stdout = child.stdout.take().expect("its stdout");
    let mut lines = BufReader::new(stdout).lines();
    let line = within(PROMPTLY, "the peer's start", lines.next_line()).await;
    if line.as_ref().ok().and_then(Option::as_deref) != Some("ready") {
        // Why it did not start is on its stderr: the test says it.
        let mut why = String::new();
        if let Some(mut stderr) = child.stderr.take() {
            let _ = within(PROMPTLY, "its stderr", stderr.read_to_string(&mut why)).await;
        }
        panic!("zenoh_peer on {endpoint} did not start: it wrote {line:?}, and on stderr: {why}");
    }
    child
}

/// A send of 0, which the peer holds for ever, ends when the owner's host is cut off: with
/// `NoReply` (its reply is lost).
async fn held_send_ends_with_no_reply(
    asker: &mut imrs_ports::End<u64, u64, usage::Send>,
    cut: impl Future<Output = ()>,
    bound: Duration,
) {
    let held = asker.send(0);
    let (lost, ()) = tokio::join!(within(bound, "the held request's end", held), cut);
    assert!(matches!(lost, Err(SendError::NoReply { .. })), "{lost:?}");
}

/// Sends until one fails with `PeerGone`, naming the owner: the owner's host is seen gone.
async fn seen_gone(asker: &mut imrs_ports::End<u64, u64, usage::Send>, bound: Duration) {
    let gone = within(bound, "the owner seen gone", async {
        loop {
            match asker.send(1).await {
                Err(SendError::PeerGone { module, .. }) => break module,
                _ => tokio::task::yield_now().await,
            }
        }
    })
    .await;
    assert_eq!(gone.as_str(), "DOUBLER");
}

/// Sends until one is served: the owner's host is back, through the same import.
async fn served_again(asker: &mut imrs_ports::End<u64, u64, usage::Send>, bound: Duration) {
    let doubled = within(bound, "the owner served again", async {
        loop {
            match asker.send(21).await {
                Ok(doubled) => break doubled,
                Err(_) => tokio::task::yield_now().await,
            }
        }
    })
    .await;
    assert_eq!(doubled, 42);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_owner_process_killed_ends_waits_and_its_restart_is_served() {
    killed_and_restarted("kill_cell").await;
}

/// The owner's host, a process of its own on loopback, killed with SIGKILL while a send
/// waits for its reply, then started again.
async fn killed_and_restarted(cell: &str) {
    let endpoint = free_endpoint();
    let mut owner = peer(cell, &endpoint, None).await;
    let host = Host::builder(cell).connect(&endpoint).open().await.unwrap();
    let imported: Imported<u64, u64, usage::Receive> =
        import(&host, "DOUBLE", "DOUBLER", "ASKER").await.unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    assert_eq!(
        within(PROMPTLY, "a round trip", asker.send(4))
            .await
            .unwrap(),
        8
    );
    let kill = async {
        tokio::task::yield_now().await;
        owner.start_kill().expect("SIGKILL");
        owner.wait().await.expect("the peer reaped");
    };
    let lease = host.lease();
    held_send_ends_with_no_reply(&mut asker, kill, 2 * lease + PROMPTLY).await;
    seen_gone(&mut asker, 2 * lease + PROMPTLY).await;
    let _restarted = peer(cell, &endpoint, None).await;
    served_again(&mut asker, PROMPTLY).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_link_set_down_mid_rendezvous_ends_waits_and_its_heal_is_served() {
    let netns = match Netns::make(0) {
        Ok(netns) => netns,
        Err(why) => {
            eprintln!(
                "\n!!! NETWORK NAMESPACES UNAVAILABLE ({why}): this test runs over loopback, \
                 its link cut by killing the owner's host !!!\n"
            );
            return killed_and_restarted("loopback_cell").await;
        }
    };
    let endpoint = format!("tcp/{}:7447", netns.inside_address());
    let _owner = peer("netns_cell", &endpoint, Some(netns.name())).await;
    let host = Host::builder("netns_cell")
        .connect(&endpoint)
        .open()
        .await
        .unwrap();
    let imported: Imported<u64, u64, usage::Receive> =
        import(&host, "DOUBLE", "DOUBLER", "ASKER").await.unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    assert_eq!(
        within(PROMPTLY, "a round trip", asker.send(4))
            .await
            .unwrap(),
        8
    );
    let lease = host.lease();
    let cut = async {
        tokio::task::yield_now().await;
        netns.set_link(false).expect("the veth link set down");
    };
    // Nothing tells this host the link is gone: the lease does.
    held_send_ends_with_no_reply(&mut asker, cut, 2 * lease + PROMPTLY).await;
    seen_gone(&mut asker, 2 * lease + PROMPTLY).await;
    netns.set_link(true).expect("the veth link set up");
    served_again(&mut asker, PROMPTLY + 2 * lease).await;
}
