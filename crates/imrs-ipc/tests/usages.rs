//! The usages beside `SEND`/`RECEIVE` across processes, with numbers: a query to the
//! owner's response handler (`RESPONSE`), a broadcast to users in other processes
//! (`SENDALL`), a callall to response handlers there and here (`CALLALL`), and an owner's
//! query to its user in another process, which fails once that user is gone (`QUERY`).

mod common;

use std::io::{BufRead, BufReader};

use common::{Number, Peer, answers, finished, peer, until_users, within};
use imrs_ipc::{Imported, IpcError, Remote};
use imrs_ports::{WireError, usage};
use imrs_testkit::unique_name;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_query_crosses_and_the_owners_response_handler_answers_it() {
    let cell = unique_name("query");
    let mut responder = peer(&["responder", &cell, "TRIPLE"]);
    let stdout = responder.0.stdout.take().expect("piped");
    let mut line = String::new();
    BufReader::new(stdout)
        .read_line(&mut line)
        .expect("the responder speaks");
    assert_eq!(line.trim(), "ready", "the responder failed: {line}");
    let remote = Remote::new(&cell).unwrap();
    let imported = imrs_ipc::import::<Imported<Number, Number, usage::Response>, _>(
        &remote, "TRIPLE", "TRIPLER", "ASKER",
    )
    .unwrap();
    // The module queries, as it would a port of its own process.
    let mut asker = imported.port().user_named("ASKER").unwrap();
    for value in 1..=50 {
        let answer = within(5, asker.query(Number { value })).await.unwrap();
        assert_eq!(answer.value, 3 * value);
    }
    // And the owner's list holds: a module it does not know is refused by name.
    let error = imrs_ipc::import::<Imported<Number, Number, usage::Response>, _>(
        &remote, "TRIPLE", "TRIPLER", "OTHER",
    )
    .err()
    .expect("refused");
    assert_eq!(
        error,
        IpcError::Refused(WireError::NotOnUserList {
            port: "TRIPLE".into(),
            module: "OTHER".into(),
        })
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_broadcast_reaches_users_in_other_processes_and_their_replies_come_back() {
    use imrs_ports::{AnyUser, Port, PortSpec, usage};

    let cell = unique_name("send-all");
    let port: Port<Number, Number, usage::SendAll, AnyUser, 2> =
        Port::new(PortSpec::new("NEWS", "BROADCASTER").user_list(["ASKER", "ASKER_2"]));
    let _exported = imrs_ipc::export(&Remote::new(&cell).unwrap(), &port).unwrap();
    let mut broadcaster = port.owner().unwrap();
    let listeners: Vec<Peer> = ["ASKER", "ASKER_2"]
        .iter()
        .map(|module| peer(&["listener", &cell, "NEWS", module, "20"]))
        .collect();
    // Both listeners' ends are attached when their processes connect.
    until_users(&broadcaster, 2).await;
    for value in 1..=20 {
        let mut broadcast = within(5, broadcaster.send_all(Number { value }))
            .await
            .unwrap();
        assert_eq!(broadcast.first.value, 2 * value);
        let (second, reply) = within(5, broadcast.next_reply()).await.unwrap();
        assert_ne!(second, broadcast.from, "each listener answers once");
        assert_eq!(reply.value, 2 * value);
        assert!(within(5, broadcast.next_reply()).await.is_none());
    }
    for listener in listeners {
        assert_eq!(answers(listener).await, (1..=20).collect::<Vec<_>>());
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_callall_query_reaches_response_handlers_in_other_processes_and_in_this_one() {
    use imrs_ports::{AnyUser, Port, PortSpec, usage};

    let cell = unique_name("call-all");
    let port: Port<Number, Number, usage::CallAll, AnyUser, 3> =
        Port::new(PortSpec::new("POLL", "CALLER").user_list(["REMOTE_1", "REMOTE_2", "LOCAL"]));
    let _exported = imrs_ipc::export(&Remote::new(&cell).unwrap(), &port).unwrap();
    let mut caller = port.owner().unwrap();
    // A response handler in this process, beside two in others (which answer with 4 n).
    let mut local = port
        .answer("LOCAL", |_: &(), n: Number| Number { value: 3 * n.value })
        .unwrap();
    let answerers: Vec<Peer> = ["REMOTE_1", "REMOTE_2"]
        .iter()
        .map(|module| peer(&["answerer", &cell, "POLL", module, "10"]))
        .collect();
    until_users(&caller, 3).await;
    // The local handler answers only when served, so each query is answered first by a
    // remote one, then by the other, then by the local one.
    for value in 1..=10 {
        let mut poll = within(5, caller.call_all(Number { value })).await.unwrap();
        let mut answers = vec![(poll.from.clone(), poll.first.value)];
        let (from, second) = within(5, poll.next_reply()).await.unwrap();
        answers.push((from, second.value));
        within(5, local.serve(&())).await.unwrap();
        let (from, third) = within(5, poll.next_reply()).await.unwrap();
        answers.push((from, third.value));
        assert!(
            within(5, poll.next_reply()).await.is_none(),
            "three answers"
        );
        answers.sort();
        assert_eq!(
            answers,
            [
                ("LOCAL".into(), 3 * value),
                ("REMOTE_1".into(), 4 * value),
                ("REMOTE_2".into(), 4 * value)
            ]
        );
    }
    for answerer in answerers {
        let text = finished(answerer).await;
        assert_eq!(text.lines().filter(|line| *line == "answered").count(), 10);
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_owners_query_reaches_its_user_in_another_process_and_a_gone_user_fails_it() {
    use imrs_ports::{AnyUser, Port, PortSpec, QueryError, usage};

    let cell = unique_name("query");
    // ASK_STATUS(N): USAGE=QUERY, USERLIST=(CHILD): the parent asks its child.
    let port: Port<Number, Number, usage::Query, AnyUser, 1> =
        Port::new(PortSpec::new("ASK_STATUS", "PARENT").user_list(["CHILD"]));
    let _exported = imrs_ipc::export(&Remote::new(&cell).unwrap(), &port).unwrap();
    let mut parent = port.owner().unwrap();
    let child = peer(&["child", &cell, "ASK_STATUS", "CHILD", "10"]);
    until_users(&parent, 1).await;
    for value in 1..=10 {
        let status = within(5, parent.query(Number { value })).await.unwrap();
        assert_eq!(status.value, 5 * value);
    }
    // The child answered ten and ended: the next query fails, typed, and nothing hangs.
    let text = finished(child).await;
    assert_eq!(text.lines().filter(|line| *line == "answered").count(), 10);
    let late = within(10, parent.query(Number { value: 11 })).await;
    assert!(
        matches!(
            late,
            Err(QueryError::NoResponse { .. } | QueryError::PeerGone { .. })
        ),
        "{late:?}"
    );
}
