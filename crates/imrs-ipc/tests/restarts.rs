//! Processes killed (`kill -9`) and started again: an owner killed mid-rendezvous fails its
//! sender, a user killed mid-rendezvous harms nobody, and each one's restart is served; the
//! owners of `SENDALL`, `QUERY` and `CALLALL` ports, killed mid-run and started again, reach
//! their users again; a process killed while nobody waited on it is swept by the next to
//! start.

mod common;

use std::time::Duration;

use common::{
    Frame, Number, Peer, answers, owner, send_while_the_owner_is_killed, served_again, started,
    user, within,
};
use imrs_ipc::{Imported, Remote, import};
use imrs_ports::{SendError, Shared, usage};
use imrs_testkit::unique_name;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_owner_killed_mid_rendezvous_fails_the_sender_and_its_restart_is_served() {
    let cell = unique_name("kill");
    let mut first = owner(&cell, "DOUBLE");
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "ASKER",
    )
    .unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    assert_eq!(
        within(5, asker.send(Number { value: 1 }))
            .await
            .unwrap()
            .value,
        2
    );
    let (mut asker, result) = send_while_the_owner_is_killed(asker, &mut first).await;
    assert!(
        matches!(result, Err(SendError::NoReply { ref port }) if port == "DOUBLE"),
        "{result:?}"
    );
    // A new copy of the owner exports the port again; the same importer is served.
    let _second = owner(&cell, "DOUBLE");
    assert_eq!(served_again(&mut asker, 21).await.value, 42);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_user_killed_mid_rendezvous_harms_nobody_and_its_restart_is_served() {
    use imrs_ports::{AnyUser, Port, PortSpec, usage};

    let cell = unique_name("user-killed");
    let port: Port<Number, Number, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("DOUBLE", "DOUBLER").user_list(["ASKER"]));
    let _exported = imrs_ipc::export(&Remote::new(&cell).unwrap(), &port).unwrap();
    let mut owner = port.owner().unwrap();
    // The user's first request is here; kill -9 it before the reply.
    let mut first = user(&cell, "ASKER", "5");
    let (number, reply) = within(10, owner.receive()).await.unwrap();
    assert_eq!(number.value, 1);
    first.0.kill().unwrap();
    first.0.wait().unwrap();
    // The reply goes to nobody; the owner's side goes on.
    reply.reply(Number { value: 2 });
    // A new copy of the user, under the same module name, is served in full.
    let second = user(&cell, "ASKER", "3");
    for value in 1..=3 {
        let (number, reply) = within(10, owner.receive()).await.unwrap();
        assert_eq!(number.value, value);
        reply.reply(Number { value: 2 * value });
    }
    assert_eq!(answers(second).await, [2, 4, 6]);
}

/// The states of the iceoryx2 nodes of process `pid` on this host, "alive" or "dead". (A
/// node whose state iceoryx2 cannot tell has no details, so no process to match.)
fn nodes_of(pid: u32) -> Vec<&'static str> {
    use iceoryx2::node::NodeView;
    use iceoryx2::prelude::*;

    let of = |details: &Option<iceoryx2::node::NodeDetails>| {
        details
            .as_ref()
            .is_some_and(|details| details.process_id().value() as u32 == pid)
    };
    let mut states = Vec::new();
    Node::<ipc_threadsafe::Service>::list(Config::global_config(), |state| {
        match &state {
            NodeState::Alive(node) if of(node.details()) => states.push("alive"),
            NodeState::Dead(node) if of(node.details()) => states.push("dead"),
            _ => {}
        }
        CallbackProgression::Continue
    })
    .unwrap();
    states
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_process_killed_while_nobody_waited_on_it_is_swept_by_the_next_to_start() {
    let mut killed = owner(&unique_name("killed-idle"), "DOUBLE");
    let pid = killed.0.id();
    assert!(nodes_of(pid).contains(&"alive"), "{:?}", nodes_of(pid));
    // Killed with no request waiting on it: no bridge looks for it, and its shared memory
    // stays until another process sweeps.
    killed.0.kill().unwrap();
    killed.0.wait().unwrap();
    // Dead, unless another test's process has already started and swept it.
    assert!(!nodes_of(pid).contains(&"alive"), "{:?}", nodes_of(pid));
    // The next process to wire a port across processes, in any cell, removes it: iceoryx2
    // sweeps the host's dead nodes whenever a node is created, as each crossing port does.
    let _next = owner(&unique_name("next"), "DOUBLE");
    assert_eq!(
        nodes_of(pid),
        Vec::<&str>::new(),
        "the killed process's node is left"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_owner_of_broadcasts_killed_mid_run_and_started_again_reaches_its_user_again() {
    let cell = unique_name("shared-send-all-owner-killed");
    let mut first = started(&["camera", &cell, "FRAMES", "1000000"]);
    let remote = Remote::new(&cell).unwrap();
    let imported = imrs_ipc::import::<Imported<Shared<Frame>, Shared<Frame>, usage::SendAll>, _>(
        &remote, "FRAMES", "CAMERA", "LEFT",
    )
    .unwrap();
    let mut left = imported.port().user_named("LEFT").unwrap();
    // LEFT answers as the camera checks: read in place, three times word 4.
    let (seen, mut heard) = tokio::sync::mpsc::unbounded_channel();
    tokio::spawn(async move {
        while let Ok((mut frame, reply)) = left.receive().await {
            let mut answer: Shared<Frame> = frame.loan_reply();
            answer.words[0] = u64::from(!frame.is_writable());
            answer.words[4] = 3 * frame.words[4];
            reply.reply(answer);
            let _ = seen.send(frame.words[4]);
        }
    });
    for seed in 1..=3 {
        assert_eq!(within(10, heard.recv()).await, Some(seed));
    }
    // kill -9 the camera mid-run.
    first.0.kill().unwrap();
    first.0.wait().unwrap();
    // A new copy of the camera numbers from 1 again, and LEFT hears each of its frames, in
    // order. The frame LEFT was reading when the first died may come first: a later one.
    let mut second = started(&["camera", &cell, "FRAMES", "3"]);
    let mut next = 1;
    while next <= 3 {
        let seed = within(10, heard.recv()).await.unwrap();
        if seed == next {
            next += 1;
        } else {
            assert!(next == 1 && seed > 3, "heard frame {seed}, not {next}");
        }
    }
    // It found every answer as it checks them, read in place.
    assert!(exit_status(&mut second).await.success());
}

/// How `peer` ended, once it has (10 s at most).
async fn exit_status(peer: &mut Peer) -> std::process::ExitStatus {
    within(10, async {
        loop {
            if let Some(status) = peer.0.try_wait().unwrap() {
                return status;
            }
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    })
    .await
}

/// A response handler's answer: five times the question.
fn five_times(_: &(), number: Number) -> Number {
    Number {
        value: 5 * number.value,
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_owner_of_queries_killed_mid_run_and_started_again_reaches_its_user_again() {
    let cell = unique_name("query-owner-killed");
    let first = started(&["parent", &cell, "ASK_STATUS", "1000000"]);
    let remote = Remote::new(&cell).unwrap();
    let imported = imrs_ipc::import::<Imported<Number, Number, usage::Query>, _>(
        &remote,
        "ASK_STATUS",
        "PARENT",
        "CHILD",
    )
    .unwrap();
    let child = imported.port().answer("CHILD", five_times).unwrap();
    let heard = answering(child);
    answers_an_owner_killed_and_started_again(heard, first, &["parent", &cell, "ASK_STATUS", "3"])
        .await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_owner_of_callalls_killed_mid_run_and_started_again_reaches_its_user_again() {
    let cell = unique_name("call-all-owner-killed");
    let first = started(&["caller", &cell, "POLL", "1000000"]);
    let remote = Remote::new(&cell).unwrap();
    let imported = imrs_ipc::import::<Imported<Number, Number, usage::CallAll>, _>(
        &remote, "POLL", "CALLER", "ANSWERER",
    )
    .unwrap();
    let answerer = imported.port().answer("ANSWERER", five_times).unwrap();
    let heard = answering(answerer);
    answers_an_owner_killed_and_started_again(heard, first, &["caller", &cell, "POLL", "3"]).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_owner_of_broadcasts_of_numbers_killed_mid_run_and_started_again_reaches_its_user_again()
{
    let cell = unique_name("send-all-owner-killed");
    let first = started(&["announcer", &cell, "NEWS", "1000000"]);
    let remote = Remote::new(&cell).unwrap();
    let imported = imrs_ipc::import::<Imported<Number, Number, usage::SendAll>, _>(
        &remote,
        "NEWS",
        "ANNOUNCER",
        "HEARER",
    )
    .unwrap();
    let mut hearer = imported.port().user_named("HEARER").unwrap();
    let (answered, heard) = tokio::sync::mpsc::unbounded_channel();
    tokio::spawn(async move {
        let _imported = imported;
        while let Ok((number, reply)) = hearer.receive().await {
            reply.reply(five_times(&(), number));
            let _ = answered.send(());
        }
    });
    answers_an_owner_killed_and_started_again(heard, first, &["announcer", &cell, "NEWS", "3"])
        .await;
}

/// Serves `handler` without end; says each time it has answered.
fn answering(
    mut handler: imrs_ports::ResponseEnd<Number, Number, ()>,
) -> tokio::sync::mpsc::UnboundedReceiver<()> {
    let (answered, heard) = tokio::sync::mpsc::unbounded_channel();
    tokio::spawn(async move {
        while handler.serve(&()).await.is_ok() {
            let _ = answered.send(());
        }
    });
    heard
}

/// A user here answers the owner in `first` (which asks without end) three times, as
/// `heard` tells; then `first` is killed (`kill -9`), and a new copy of the owner, started
/// with `again` to ask three times, must find all three answers right.
async fn answers_an_owner_killed_and_started_again(
    mut heard: tokio::sync::mpsc::UnboundedReceiver<()>,
    mut first: Peer,
    again: &[&str],
) {
    for _ in 0..3 {
        within(10, heard.recv()).await.unwrap();
    }
    first.0.kill().unwrap();
    first.0.wait().unwrap();
    while heard.try_recv().is_ok() {}
    let mut second = started(again);
    for _ in 0..3 {
        within(10, heard.recv()).await.unwrap();
    }
    // The new owner found every answer five times its question.
    assert!(exit_status(&mut second).await.success());
}
