//! Ports whose owner starts each rendezvous, across hosts: a `SENDALL` port's broadcast
//! reaches modules on two other hosts and their replies come back; a `CALLALL` port's
//! query is answered by a remote response handler; a `QUERY` port's owner asks a module on
//! another host. And the dead-peer rule both ways.

mod common;

use std::collections::BTreeSet;

use common::{PROMPTLY, listening, within};
use imrs_ports::{AnyUser, Port, PortSpec, ReceiveError, usage};
use imrs_testkit::free_endpoint;
use imrs_zenoh::{Host, Imported, export, import};

async fn connecting(cell: &str, endpoint: &str) -> Host {
    Host::builder(cell).connect(endpoint).open().await.unwrap()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_broadcast_reaches_modules_on_two_hosts_and_their_replies_come_back() {
    let endpoint = free_endpoint();
    let owner_host = listening("alarm_cell", &endpoint).await;
    let alarm: Port<String, u32, usage::SendAll, AnyUser, 2> =
        Port::new(PortSpec::new("ALARM", "LINE").user_list(["PANEL_A", "PANEL_B"]));
    let _exported = export(&owner_host, &alarm).await.unwrap();
    let mut panels = Vec::new();
    for (module, code) in [("PANEL_A", 1), ("PANEL_B", 2)] {
        let host = connecting("alarm_cell", &endpoint).await;
        let imported: Imported<String, u32, usage::SendAll> =
            import(&host, "ALARM", "LINE", module).await.unwrap();
        let mut panel = imported.port().user_named(module).unwrap();
        let heard = tokio::spawn(async move {
            let (alarm, reply) = panel.receive().await.unwrap();
            reply.reply(code);
            (alarm, host, imported)
        });
        panels.push(heard);
    }
    let mut line = alarm.owner().unwrap();
    let broadcast = within(PROMPTLY, "the broadcast", async {
        // Both remote modules are attached once their hosts have connected.
        while alarm.users_attached() < 2 {
            tokio::task::yield_now().await;
        }
        line.send_all("feeder empty".to_owned()).await
    })
    .await;
    let mut broadcast = broadcast.unwrap();
    let mut codes = BTreeSet::from([broadcast.first]);
    if let Some((_, code)) = within(PROMPTLY, "the later reply", broadcast.next_reply()).await {
        codes.insert(code);
    }
    assert_eq!(codes, BTreeSet::from([1, 2]));
    for panel in panels {
        let (heard, _, _) = within(PROMPTLY, "a panel", panel).await.unwrap();
        assert_eq!(heard, "feeder empty");
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_callall_and_a_query_are_answered_by_response_handlers_on_other_hosts() {
    let endpoint = free_endpoint();
    let owner_host = listening("ask_cell", &endpoint).await;
    let user_host = connecting("ask_cell", &endpoint).await;
    // CALLALL: the cell asks every robot for its joint count.
    let census: Port<u8, u32, usage::CallAll, AnyUser, 1> =
        Port::new(PortSpec::new("CENSUS", "CELL"));
    let _census = export(&owner_host, &census).await.unwrap();
    let robot: Imported<u8, u32, usage::CallAll> =
        import(&user_host, "CENSUS", "CELL", "ROBOT").await.unwrap();
    let mut handler = robot
        .port()
        .answer("ROBOT", |joints: &u32, _: u8| *joints)
        .unwrap();
    tokio::spawn(async move { while handler.serve(&6).await.is_ok() {} });
    // QUERY: a parent asks its child on another host.
    let ask: Port<u64, u64, usage::Query, AnyUser, 1> =
        Port::new(PortSpec::new("ASK", "PARENT").user_list(["CHILD"]));
    let _ask = export(&owner_host, &ask).await.unwrap();
    let child: Imported<u64, u64, usage::Query> =
        import(&user_host, "ASK", "PARENT", "CHILD").await.unwrap();
    let mut child_handler = child
        .port()
        .answer("CHILD", |_: &(), n: u64| n * 5)
        .unwrap();
    tokio::spawn(async move { while child_handler.serve(&()).await.is_ok() {} });

    let mut cell = census.owner().unwrap();
    let answered = within(PROMPTLY, "the census", async {
        while census.users_attached() < 1 {
            tokio::task::yield_now().await;
        }
        cell.call_all(0).await.map(|broadcast| broadcast.first)
    })
    .await;
    assert_eq!(answered.unwrap(), 6);
    let mut parent = ask.owner().unwrap();
    for n in 1..=10 {
        assert_eq!(
            within(PROMPTLY, "a query", parent.query(n)).await.unwrap(),
            5 * n
        );
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_gone_owner_ends_a_listeners_wait_and_its_return_reaches_the_same_import() {
    let endpoint = free_endpoint();
    let owner_host = listening("gone_alarm_cell", &endpoint).await;
    let alarm: Port<u32, u32, usage::SendAll, AnyUser, 1> =
        Port::new(PortSpec::new("ALARM", "LINE"));
    let exported = export(&owner_host, &alarm).await.unwrap();
    let user_host = connecting("gone_alarm_cell", &endpoint).await;
    let imported: Imported<u32, u32, usage::SendAll> =
        import(&user_host, "ALARM", "LINE", "PANEL").await.unwrap();
    let mut panel = imported.port().user_named("PANEL").unwrap();
    // The owner's host goes while the panel waits for a broadcast.
    drop(exported);
    owner_host.close().await.unwrap();
    let waited = within(PROMPTLY, "the panel's wait", panel.receive()).await;
    assert!(
        matches!(&waited, Err(ReceiveError::PeerGone { module, .. }) if module.as_str() == "LINE"),
        "{waited:?}"
    );
    // The owner's host comes back: its broadcasts reach the panel, with no new import.
    owner_back_reaches(&endpoint, "gone_alarm_cell", panel).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_gone_listener_host_leaves_the_owners_broadcasts_to_the_others() {
    let endpoint = free_endpoint();
    let owner_host = listening("left_cell", &endpoint).await;
    let alarm: Port<u32, u32, usage::SendAll, AnyUser, 2> =
        Port::new(PortSpec::new("ALARM", "LINE"));
    let _exported = export(&owner_host, &alarm).await.unwrap();
    let staying_host = connecting("left_cell", &endpoint).await;
    let staying: Imported<u32, u32, usage::SendAll> =
        import(&staying_host, "ALARM", "LINE", "STAYS")
            .await
            .unwrap();
    let mut stays = staying.port().user_named("STAYS").unwrap();
    tokio::spawn(async move {
        while let Ok((n, reply)) = stays.receive().await {
            reply.reply(n);
        }
    });
    let leaving_host = connecting("left_cell", &endpoint).await;
    let leaving: Imported<u32, u32, usage::SendAll> =
        import(&leaving_host, "ALARM", "LINE", "LEAVES")
            .await
            .unwrap();
    let mut line = alarm.owner().unwrap();
    within(PROMPTLY, "both attached", async {
        while alarm.users_attached() < 2 {
            tokio::task::yield_now().await;
        }
    })
    .await;
    // LEAVES never answers; its host goes.
    drop(leaving);
    leaving_host.close().await.unwrap();
    within(PROMPTLY, "the leaver let go", async {
        while alarm.users_attached() > 1 {
            tokio::task::yield_now().await;
        }
    })
    .await;
    let mut broadcast = within(PROMPTLY, "a broadcast", line.send_all(7))
        .await
        .unwrap();
    assert_eq!(broadcast.first, 7);
    assert_eq!(
        within(PROMPTLY, "the rest", broadcast.next_reply()).await,
        None
    );
}

/// The owner's host goes while its broadcast waits for a listener that holds its reply:
/// the listener's next wait still ends with `PeerGone` (the delivery waiting on the reply
/// no longer holds up the word that the owner is gone), and once the listener lets the old
/// reply go, the owner's return reaches it.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_gone_owner_is_seen_while_its_broadcasts_reply_is_held() {
    let endpoint = free_endpoint();
    let owner_host = listening("held_alarm_cell", &endpoint).await;
    let alarm: Port<u32, u32, usage::SendAll, AnyUser, 1> =
        Port::new(PortSpec::new("ALARM", "LINE"));
    let exported = export(&owner_host, &alarm).await.unwrap();
    let user_host = connecting("held_alarm_cell", &endpoint).await;
    let imported: Imported<u32, u32, usage::SendAll> =
        import(&user_host, "ALARM", "LINE", "PANEL").await.unwrap();
    let mut panel = imported.port().user_named("PANEL").unwrap();
    let mut line = alarm.owner().unwrap();
    let broadcasting = tokio::spawn(async move {
        while alarm.users_attached() < 1 {
            tokio::task::yield_now().await;
        }
        let _ = line.send_all(7).await;
    });
    let (n, held) = within(PROMPTLY, "the first broadcast", panel.receive())
        .await
        .unwrap();
    assert_eq!(n, 7);
    // The owner's host goes while the panel holds the broadcast's reply.
    broadcasting.abort();
    drop(exported);
    owner_host.close().await.unwrap();
    let waited = within(PROMPTLY, "the panel's next wait", panel.receive()).await;
    assert!(
        matches!(&waited, Err(ReceiveError::PeerGone { module, .. }) if module.as_str() == "LINE"),
        "{waited:?}"
    );
    // The panel lets the old reply go (one rendezvous at a time, as in one process), and the
    // owner's host comes back: its broadcast reaches the panel, with no new import.
    drop(held);
    owner_back_reaches(&endpoint, "held_alarm_cell", panel).await;
}

/// ALARM's owner's host, back on `endpoint`: its broadcast reaches `panel` on the same
/// import, whose waits find the owner gone until its host has seen it back.
async fn owner_back_reaches(
    endpoint: &str,
    cell: &str,
    mut panel: imrs_ports::End<u32, u32, usage::Receive>,
) {
    let back_host = listening(cell, endpoint).await;
    let back: Port<u32, u32, usage::SendAll, AnyUser, 1> =
        Port::new(PortSpec::new("ALARM", "LINE"));
    let _exported = export(&back_host, &back).await.unwrap();
    let heard = tokio::spawn(async move {
        loop {
            match panel.receive().await {
                Ok((n, reply)) => {
                    reply.reply(n + 1);
                    break n;
                }
                Err(ReceiveError::PeerGone { .. }) => tokio::task::yield_now().await,
                Err(error) => panic!("{error}"),
            }
        }
    });
    let mut line = back.owner().unwrap();
    let answer = within(PROMPTLY, "the returned owner's broadcast", async {
        while back.users_attached() < 1 {
            tokio::task::yield_now().await;
        }
        line.send_all(41).await.map(|broadcast| broadcast.first)
    })
    .await;
    assert_eq!(answer.unwrap(), 42);
    assert_eq!(within(PROMPTLY, "the panel", heard).await.unwrap(), 41);
}
