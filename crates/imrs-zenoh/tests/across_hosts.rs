//! Ports across hosts on zenoh, over loopback: every test opens its hosts on endpoints of
//! its own, as two hosts of one cell would.

mod common;

use std::time::Duration;

use common::{PROMPTLY, listening, two_hosts, within};
use imrs_ports::{AnyUser, Port, PortSpec, SendError, usage};
use imrs_testkit::free_endpoint;
use imrs_zenoh::{Host, Imported, ZenohError, export, import};

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_send_crosses_hosts_and_its_reply_comes_back() {
    let (owner_host, user_host) = two_hosts("send_cell", &free_endpoint()).await;
    let port: Port<u64, u64, usage::Receive, AnyUser, 4> =
        Port::new(PortSpec::new("DOUBLE", "DOUBLER"));
    let _exported = export(&owner_host, &port).await.unwrap();
    let mut doubler = port.owner().unwrap();
    tokio::spawn(async move {
        while let Ok((n, reply)) = doubler.receive().await {
            reply.reply(2 * n);
        }
    });
    let imported: Imported<u64, u64, usage::Receive> =
        import(&user_host, "DOUBLE", "DOUBLER", "ASKER")
            .await
            .unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    for n in 0..100 {
        assert_eq!(
            within(PROMPTLY, "a round trip", asker.send(n))
                .await
                .unwrap(),
            2 * n
        );
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_query_is_answered_by_the_owners_response_handler() {
    let (owner_host, user_host) = two_hosts("query_cell", &free_endpoint()).await;
    let port: Port<String, String, usage::Response, AnyUser, 2> =
        Port::new(PortSpec::new("STATUS", "ROBOT"));
    let _exported = export(&owner_host, &port).await.unwrap();
    let mut handler = port
        .answer("ROBOT", |joints: &Vec<f64>, asked: String| {
            format!("{asked}: {} joints", joints.len())
        })
        .unwrap();
    tokio::spawn(async move {
        let joints = vec![0.0; 6];
        while handler.serve(&joints).await.is_ok() {}
    });
    let imported: Imported<String, String, usage::Response> =
        import(&user_host, "STATUS", "ROBOT", "PANEL")
            .await
            .unwrap();
    let mut panel = imported.port().user_named("PANEL").unwrap();
    let answer = within(PROMPTLY, "a query", panel.query("status".into())).await;
    assert_eq!(answer.unwrap(), "status: 6 joints");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_module_off_the_user_list_is_refused_naming_the_port_and_the_module() {
    let (owner_host, user_host) = two_hosts("list_cell", &free_endpoint()).await;
    let port: Port<u64, u64, usage::Receive, AnyUser, 4> =
        Port::new(PortSpec::new("GRIP", "GRIPPER").user_list(["ROBOT"]));
    let _exported = export(&owner_host, &port).await.unwrap();
    let refused =
        import::<Imported<u64, u64, usage::Receive>>(&user_host, "GRIP", "GRIPPER", "ROGUE")
            .await
            .unwrap_err();
    let ZenohError::Refused { port, reason } = &refused else {
        panic!("not refused: {refused}");
    };
    assert_eq!(port, "GRIP");
    assert!(
        reason.contains("ROGUE") && reason.contains("GRIP"),
        "{refused}"
    );
    // The module on the list is served.
    let robot: Imported<u64, u64, usage::Receive> = import(&user_host, "GRIP", "GRIPPER", "ROBOT")
        .await
        .unwrap();
    assert_eq!(robot.port().name().as_str(), "GRIP");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_port_full_of_users_refuses_one_more_and_a_wrong_owner_is_named() {
    let (owner_host, user_host) = two_hosts("full_cell", &free_endpoint()).await;
    let port: Port<u64, u64, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("FEED", "FEEDER"));
    let _exported = export(&owner_host, &port).await.unwrap();
    let _first: Imported<u64, u64, usage::Receive> =
        import(&user_host, "FEED", "FEEDER", "FIRST").await.unwrap();
    let second =
        import::<Imported<u64, u64, usage::Receive>>(&user_host, "FEED", "FEEDER", "SECOND")
            .await
            .unwrap_err();
    assert!(
        matches!(&second, ZenohError::Refused { port, reason } if port == "FEED" && reason.contains("SECOND")),
        "{second}"
    );
    let wrong = import::<Imported<u64, u64, usage::Receive>>(&user_host, "FEED", "GATE", "FIRST")
        .await
        .unwrap_err();
    assert_eq!(
        wrong.to_string(),
        "port FEED: its owner's host refused: GATE does not own it; FEEDER does"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_import_nobody_exports_and_a_second_export_are_refused_by_name() {
    let (owner_host, user_host) = two_hosts("none_cell", &free_endpoint()).await;
    let missing = within(
        PROMPTLY,
        "an import of nothing",
        import::<Imported<u64, u64, usage::Receive>>(&user_host, "NOBODY", "NOONE", "ASKER"),
    )
    .await
    .unwrap_err();
    assert_eq!(
        missing,
        ZenohError::NoOwner {
            port: "NOBODY".into()
        }
    );
    let port: Port<u64, u64, usage::Receive> = Port::new(PortSpec::new("ONCE", "OWNER"));
    let _exported = export(&owner_host, &port).await.unwrap();
    // Once the user's host has seen the owner's (an import waits for that)…
    let _seen: Imported<u64, u64, usage::Receive> =
        import(&user_host, "ONCE", "OWNER", "ASKER").await.unwrap();
    // …it cannot export the port too.
    let again: Port<u64, u64, usage::Receive> = Port::new(PortSpec::new("ONCE", "OWNER"));
    let twice = export(&user_host, &again).await.unwrap_err();
    assert_eq!(
        twice.to_string(),
        "port ONCE: its owner's host refused: another host exports it already"
    );
    let bad = Host::builder("a/cell").open().await.err().unwrap();
    assert!(bad.to_string().starts_with("cell name \"a/cell\""), "{bad}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_ports_timeout_holds_across_hosts() {
    let (owner_host, user_host) = two_hosts("timeout_cell", &free_endpoint()).await;
    let port: Port<u64, u64, usage::Receive> =
        Port::new(PortSpec::new("SLOW", "SLUGGARD").user_timeout(Duration::from_millis(300)));
    let _exported = export(&owner_host, &port).await.unwrap();
    // The owner attaches and never receives.
    let _sluggard = port.owner().unwrap();
    let imported: Imported<u64, u64, usage::Receive> =
        import(&user_host, "SLOW", "SLUGGARD", "ASKER")
            .await
            .unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    assert_eq!(asker.timeout(), Some(Duration::from_millis(300)));
    let started = std::time::Instant::now();
    let late = within(PROMPTLY, "a send past its timeout", asker.send(1)).await;
    assert!(
        matches!(late, Err(SendError::ReplyTimeout { ref port }) if port.as_str() == "SLOW"),
        "{late:?}"
    );
    assert!(started.elapsed() >= Duration::from_millis(300));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_closed_owner_host_ends_waits_with_peer_gone_and_its_return_is_served() {
    let endpoint = free_endpoint();
    let (owner_host, user_host) = two_hosts("gone_cell", &endpoint).await;
    let port: Port<u64, u64, usage::Receive> = Port::new(PortSpec::new("HOLD", "HOLDER"));
    let exported = export(&owner_host, &port).await.unwrap();
    let holder = port.owner().unwrap();
    let imported: Imported<u64, u64, usage::Receive> =
        import(&user_host, "HOLD", "HOLDER", "ASKER").await.unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    // A send the owner never takes; then its host goes.
    let waiting = tokio::spawn(async move {
        let lost = asker.send(7).await;
        (asker, lost)
    });
    // Once the send has reached the owner's port (its owner never takes it), the host goes.
    within(PROMPTLY, "the send at the owner", async {
        while holder.waiting() == 0 {
            tokio::task::yield_now().await;
        }
    })
    .await;
    drop(exported);
    owner_host.close().await.unwrap();
    drop(holder);
    let (mut asker, lost) = within(PROMPTLY, "the lost request's end", waiting)
        .await
        .unwrap();
    assert!(matches!(lost, Err(SendError::NoReply { .. })), "{lost:?}");
    // Once the owner's host is seen gone, a send fails at once, naming the owner.
    let gone = within(PROMPTLY, "the owner seen gone", async {
        loop {
            match asker.send(8).await {
                Err(SendError::PeerGone { module, .. }) => break module,
                _ => tokio::task::yield_now().await,
            }
        }
    })
    .await;
    assert_eq!(gone.as_str(), "HOLDER");
    // The owner's host comes back on the same endpoint: the same import is served.
    let back_host = listening("gone_cell", &endpoint).await;
    let back: Port<u64, u64, usage::Receive> = Port::new(PortSpec::new("HOLD", "HOLDER"));
    let _exported = export(&back_host, &back).await.unwrap();
    let mut holder = back.owner().unwrap();
    tokio::spawn(async move {
        while let Ok((n, reply)) = holder.receive().await {
            reply.reply(n + 1);
        }
    });
    let served = within(PROMPTLY, "the returned owner served", async {
        loop {
            match asker.send(41).await {
                Ok(reply) => break reply,
                Err(_) => tokio::task::yield_now().await,
            }
        }
    })
    .await;
    assert_eq!(served, 42);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_user_host_that_goes_ends_its_owners_wait_with_peer_gone() {
    let (owner_host, user_host) = two_hosts("user_gone_cell", &free_endpoint()).await;
    let port: Port<u64, u64, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("WORK", "WORKER"));
    let _exported = export(&owner_host, &port).await.unwrap();
    let imported: Imported<u64, u64, usage::Receive> =
        import(&user_host, "WORK", "WORKER", "FEEDER")
            .await
            .unwrap();
    let mut feeder = imported.port().user_named("FEEDER").unwrap();
    let mut worker = port.owner().unwrap();
    let serving = tokio::spawn(async move {
        let (n, reply) = worker.receive().await.unwrap();
        reply.reply(n);
        // The feeder's host goes before it sends again.
        worker.receive().await.map(|(n, _)| n)
    });
    assert_eq!(
        within(PROMPTLY, "a round trip", feeder.send(5))
            .await
            .unwrap(),
        5
    );
    drop(feeder);
    drop(imported);
    user_host.close().await.unwrap();
    let waited = within(PROMPTLY, "the worker's wait", serving)
        .await
        .unwrap();
    assert!(
        matches!(&waited, Err(imrs_ports::ReceiveError::PeerGone { module, .. }) if module.as_str() == "FEEDER"),
        "{waited:?}"
    );
}

/// A hostile peer, speaking zenoh directly, claims module names without end: each claim
/// refused is answered with the reason, naming the port, and leaves no name behind.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_refused_claim_is_answered_by_name_and_leaves_no_name_behind() {
    let (owner_host, peer_host) = two_hosts("claim_cell", &free_endpoint()).await;
    let port: Port<u64, u64, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("GATE", "GATEKEEPER").user_list(["ROBOT"]));
    let _exported = export(&owner_host, &port).await.unwrap();
    let mut gatekeeper = port.owner().unwrap();
    tokio::spawn(async move {
        while let Ok((n, reply)) = gatekeeper.receive().await {
            reply.reply(n);
        }
    });
    // The owner is seen (an import waits for it), then the claims come raw.
    let _robot: Imported<u64, u64, usage::Receive> =
        import(&peer_host, "GATE", "GATEKEEPER", "ROBOT")
            .await
            .unwrap();
    let claims: Vec<String> = (0..50)
        .map(|i| format!("CLAIM_{}_{i}", std::process::id()))
        .collect();
    for module in &claims {
        let replies = peer_host
            .session()
            .get(format!("imrs/claim_cell/port/GATE/{module}"))
            .payload(vec![0, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0])
            .await
            .unwrap();
        let reply = within(PROMPTLY, "a claim's answer", replies.recv_async())
            .await
            .unwrap();
        let reason = reply.into_result().unwrap_err();
        let reason = String::from_utf8(reason.payload().to_bytes().into_owned()).unwrap();
        assert_eq!(
            reason,
            format!("module {module} is not on the user list of port GATE")
        );
    }
    for module in &claims {
        assert_eq!(imrs_ports::Name::known(module), None, "{module} was kept");
    }
}

/// A host whose own session closes: its modules' waits on imported ports end with
/// `PeerGone`, even on a port with no TIMEOUT, rather than hang.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_closed_session_ends_its_own_modules_waits() {
    let (owner_host, user_host) = two_hosts("closing_cell", &free_endpoint()).await;
    let port: Port<u64, u64, usage::Receive> = Port::new(PortSpec::new("WAIT", "WAITER"));
    let _exported = export(&owner_host, &port).await.unwrap();
    let imported: Imported<u64, u64, usage::Receive> =
        import(&user_host, "WAIT", "WAITER", "ASKER").await.unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    user_host.close().await.unwrap();
    let ended = within(PROMPTLY, "a send on a closed host", async {
        loop {
            match asker.send(1).await {
                Err(SendError::PeerGone { module, .. }) => break module,
                _ => tokio::task::yield_now().await,
            }
        }
    })
    .await;
    assert_eq!(ended.as_str(), "WAITER");
}

/// A peer that floods a port under one module's name holds at most a bounded number of
/// requests waiting on the owner's host: the rest are refused at once, naming the port and
/// the module, and the owner's host keeps no task for them.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_flood_under_one_name_is_refused_past_its_room() {
    let (owner_host, user_host) = two_hosts("flood_cell", &free_endpoint()).await;
    let port: Port<u64, u64, usage::Receive> =
        Port::new(PortSpec::new("SLOW", "SLOWPOKE").user_list(["FLOODER"]));
    let _exported = export(&owner_host, &port).await.unwrap();
    // The owner never receives: every request that is let in waits.
    let _slowpoke = port.owner().unwrap();
    let _seen: Imported<u64, u64, usage::Receive> =
        import(&user_host, "SLOW", "SLOWPOKE", "FLOODER")
            .await
            .unwrap();
    let mut flood = tokio::task::JoinSet::new();
    for n in 0..100_u64 {
        let session = user_host.session().clone();
        flood.spawn(async move {
            let mut payload = vec![0, 1, 0, 0];
            payload.extend_from_slice(&n.to_le_bytes());
            let replies = session
                .get("imrs/flood_cell/port/SLOW/FLOODER")
                .payload(payload)
                .timeout(Duration::from_secs(3))
                .await
                .unwrap();
            let reply = replies.recv_async().await.unwrap();
            let reason = reply.into_result().unwrap_err();
            let reason = String::from_utf8(reason.payload().to_bytes().into_owned()).unwrap();
            // Let in, and never answered: zenoh's own timeout on this side.
            (reason != "Timeout").then_some(reason)
        });
    }
    let (mut refused, mut waited) = (0, 0);
    while let Some(answer) = flood.join_next().await {
        match answer.unwrap() {
            Some(reason) => {
                assert_eq!(
                    reason,
                    "port SLOW: module FLOODER has 16 requests waiting already"
                );
                refused += 1;
            }
            None => waited += 1,
        }
    }
    assert_eq!((refused, waited), (84, 16));
}

/// A supervisor's watch of a module on another host: it stays quiet while the module's
/// host imports the port again at once, and ends when that host is gone.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_watched_module_is_seen_gone_with_its_host() {
    let (owner_host, user_host) = two_hosts("watched_cell", &free_endpoint()).await;
    let port: Port<u64, u64, usage::Receive> =
        Port::new(PortSpec::new("WATCHED", "OWNER").user_list(["USER"]));
    let exported = export(&owner_host, &port).await.unwrap();
    let imported: Imported<u64, u64, usage::Receive> =
        import(&user_host, "WATCHED", "OWNER", "USER")
            .await
            .unwrap();
    // A misspelt module is refused by name, never watched in silence.
    assert_eq!(
        exported.watch_user("USRE").await.unwrap_err(),
        ZenohError::NotAUser {
            port: "WATCHED".into(),
            module: "USRE".into()
        }
    );
    let mut watch = exported.watch_user("USER").await.unwrap();
    assert!(watch.is_there().await);
    assert!(user_host.is_exported("WATCHED").await.unwrap());
    assert!(!user_host.is_exported("UNEXPORTED").await.unwrap());
    // Imported again at once: the first token's end is heard, but the module is there.
    drop(imported);
    let _again: Imported<u64, u64, usage::Receive> = import(&user_host, "WATCHED", "OWNER", "USER")
        .await
        .unwrap();
    let quiet = tokio::time::timeout(Duration::from_millis(500), watch.gone()).await;
    assert!(quiet.is_err(), "a module imported again was seen gone");
    // Its host closes: gone.
    user_host.close().await.unwrap();
    within(PROMPTLY, "the module seen gone", watch.gone()).await;
    assert!(!watch.is_there().await);
}
