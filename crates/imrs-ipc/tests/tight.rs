//! `TIGHT` ports across processes: their round trips, whether the other side spins or has
//! parked; a dead owner still failing the sender; and an export dropped, which closes the port
//! as a port of one process closes.

mod common;

use std::time::Duration;

use common::{Number, send_while_the_owner_is_killed, served_again, started_owner, within};
use imrs_ipc::{Imported, Remote, import};
use imrs_ports::{ProcessType, SendError, usage};
use imrs_testkit::unique_name;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_tight_port_crosses_as_any_other_and_a_dead_owner_still_fails_the_sender() {
    let cell = unique_name("tight");
    let remote = Remote::new(&cell).unwrap();
    let mut owner = started_owner("tight-owner", &cell, "DOUBLE");
    let imported = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "ASKER",
    )
    .unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    // Three deaths, each of a new copy of the owner: whether the spinning sender's own
    // turn or the bridge's task forwarded the last request is a race, and the death must
    // be seen either way.
    for death in 1..=3 {
        // A restarted owner is served once its server is seen.
        assert_eq!(served_again(&mut asker, 1).await.value, 2);
        for value in 2..=200 {
            let reply = within(5, asker.send(Number { value })).await.unwrap();
            assert_eq!(reply.value, 2 * value);
        }
        let result;
        (asker, result) = send_while_the_owner_is_killed(asker, &mut owner).await;
        assert!(
            matches!(result, Err(SendError::NoReply { ref port }) if port == "DOUBLE"),
            "death {death}: {result:?}"
        );
        owner = started_owner("tight-owner", &cell, "DOUBLE");
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_tight_port_is_served_whether_the_other_side_spins_or_has_parked() {
    let cell = unique_name("tight-turns");
    let _owner = started_owner("tight-owner", &cell, "DOUBLE");
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "ASKER",
    )
    .unwrap();
    // The owner declared the port TIGHT: the importing module's waits spin too.
    assert_eq!(imported.port().process_type(), ProcessType::Tight);
    let mut asker = imported.port().user_named("ASKER").unwrap();
    let mut ask = async move |value: u64| {
        let reply = within(5, asker.send(Number { value })).await.unwrap();
        assert_eq!(reply.value, 2 * value);
    };
    // Both spinning: the requests and replies move in the two modules' own turns.
    for value in 1..=500 {
        ask(value).await;
    }
    // The owner has parked between requests: each request's wake-up must reach it.
    for value in 1..=5 {
        tokio::time::sleep(Duration::from_millis(20)).await;
        ask(value).await;
    }
    // The owner answers a second later, long after the sender parked: the reply's wake-up
    // must reach the sender.
    ask(1001).await;
    // And spinning again, as before.
    for value in 1..=100 {
        ask(value).await;
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_tight_port_whose_export_is_dropped_closes_as_a_port_of_one_process_does() {
    use imrs_ports::{AnyUser, Port, PortSpec, ReceiveError, usage};

    // The port keeps the bridge's turns, and the bridge keeps the port: dropping the export
    // must still let the bridge go, with its hold on the port.
    let cell = unique_name("tight-dropped");
    let port: Port<Number, Number, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("DOUBLE", "DOUBLER").process_type(ProcessType::Tight));
    let exported = imrs_ipc::export(&Remote::new(&cell).unwrap(), &port).unwrap();
    let mut owner = port.owner().unwrap();
    drop(exported);
    drop(port);
    let received = within(5, owner.receive()).await;
    assert!(
        matches!(received, Err(ReceiveError::Closed { ref port }) if port == "DOUBLE"),
        "{received:?}"
    );
}
