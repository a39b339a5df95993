//! A host that claims ever new module names on a port without a user list grows its owner
//! only up to `Name::MOST_FROM_PEERS` names; then it is refused by name. Its own test
//! binary, since the bound is the process's.

mod common;

use common::{PROMPTLY, two_hosts, within};
use imrs_ports::{AnyUser, Name, Port, PortSpec, usage};
use imrs_testkit::free_endpoint;
use imrs_zenoh::{Imported, ZenohError, export, import};

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_new_name_past_the_bound_is_refused_by_name_across_hosts() {
    let (owner_host, peer_host) = two_hosts("churn_cell", &free_endpoint()).await;
    let port: Port<u64, u64, usage::Receive, AnyUser, 4> =
        Port::new(PortSpec::new("OPEN_GATE", "GATEKEEPER"));
    let _exported = export(&owner_host, &port).await.unwrap();
    let mut gatekeeper = port.owner().unwrap();
    tokio::spawn(async move {
        while let Ok((n, reply)) = gatekeeper.receive().await {
            reply.reply(n + 1);
        }
    });
    // A module accepted while there is room keeps its place.
    let early: Imported<u64, u64, usage::Receive> =
        import(&peer_host, "OPEN_GATE", "GATEKEEPER", "EARLY_ROBOT")
            .await
            .unwrap();
    // Peers have made the rest of the bound's names, here through another open port.
    let other: Port<u64, u64, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("OTHER_GATE", "GATEKEEPER"));
    let mut made = 0;
    while other.claim(&format!("CHURN_{made}")).is_ok() {
        made += 1;
    }
    assert_eq!(made, Name::MOST_FROM_PEERS - 1);
    let late = format!("LATE_ROBOT_{}", std::process::id());
    let refused = within(
        PROMPTLY,
        "a refused import",
        import::<Imported<u64, u64, usage::Receive>>(&peer_host, "OPEN_GATE", "GATEKEEPER", &late),
    )
    .await
    .unwrap_err();
    assert_eq!(
        refused,
        ZenohError::Refused {
            port: "OPEN_GATE".into(),
            reason: format!(
                "module {late} cannot use port OPEN_GATE: this process already keeps {} module \
                 names its peers made; give port OPEN_GATE a user list",
                Name::MOST_FROM_PEERS
            ),
        }
    );
    assert_eq!(Name::known(&late), None, "{late} was kept");
    // The early module is served still.
    let mut robot = early.port().user_named("EARLY_ROBOT").unwrap();
    assert_eq!(
        within(PROMPTLY, "a rendezvous", robot.send(41))
            .await
            .map_err(|e| e.to_string()),
        Ok(42)
    );
}
