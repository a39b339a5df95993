//! `SEND`/`RECEIVE` ports across processes, wired as a user wires them: sends that cross to
//! the owner's process and replies that come back, to one user process or several; sends
//! polled and replies given outside the runtime; two cells with the same port names; a
//! user's timeout, and a send dropped halfway; a `select` over an exported port and a local
//! one.

mod common;

use std::time::Duration;

use common::{Number, Peer, answers, owner, user, within};
use imrs_ipc::{Imported, Remote, export, import};
use imrs_ports::{AnyUser, Port, PortSpec, ReplyHandle, SendError, usage};
use imrs_testkit::unique_name;

/// Waits for each user process (started by [`user`] to ask the doubles of 1..=`n`) to end,
/// and checks that it got them all, in order.
async fn each_doubled(users: Vec<Peer>, n: u64) {
    for user in users {
        assert_eq!(
            answers(user).await,
            (1..=n).map(|v| 2 * v).collect::<Vec<_>>()
        );
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_send_crosses_to_the_owners_process_and_its_reply_comes_back() {
    let cell = unique_name("send");
    let _owner = owner(&cell, "DOUBLE");
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "ASKER",
    )
    .unwrap();
    // The module's code is what it would be in one process.
    let mut asker = imported.port().user_named("ASKER").unwrap();
    for value in 1..=200 {
        let reply = within(5, asker.send(Number { value })).await.unwrap();
        assert_eq!(reply.value, 2 * value);
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn two_user_processes_are_served_at_once() {
    let cell = unique_name("users");
    let _owner = owner(&cell, "DOUBLE");
    let users: Vec<Peer> = ["ASKER", "ASKER_2"]
        .iter()
        .map(|module| user(&cell, module, "100"))
        .collect();
    each_doubled(users, 100).await;
}

/// The bridge answers a request where the owner's reply is given, when it can: here in a
/// thread of the test's own, outside the runtime, while requests from four processes keep
/// coming, so that the bridge also takes new requests into the port from that thread. None
/// of that may need the runtime, and every reply must cross.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn replies_given_outside_the_runtime_cross_while_requests_keep_coming() {
    let cell = unique_name("outside");
    let remote = Remote::new(&cell).unwrap();
    let modules = ["ASKER", "ASKER_2", "ASKER_3", "ASKER_4"];
    let port: Port<Number, Number, usage::Receive, AnyUser, 4> =
        Port::new(PortSpec::new("DOUBLE", "DOUBLER").user_list(modules));
    let _exported = export(&remote, &port).unwrap();
    let mut owner = port.owner().unwrap();
    let (handles, replier) = std::sync::mpsc::channel::<(Number, ReplyHandle<Number>)>();
    let replier = std::thread::spawn(move || {
        let mut replied = 0;
        for (number, reply) in replier {
            reply.reply(Number {
                value: 2 * number.value,
            });
            replied += 1;
        }
        replied
    });
    let serving = tokio::spawn(async move {
        for _ in 0..800 {
            let taken = owner.receive().await.unwrap();
            handles.send(taken).unwrap();
        }
    });
    let users: Vec<Peer> = modules
        .iter()
        .map(|module| user(&cell, module, "200"))
        .collect();
    each_doubled(users, 200).await;
    within(5, serving).await.unwrap();
    assert_eq!(
        replier.join().expect("the replying thread did not panic"),
        800
    );
}

/// Runs `future` to its end in this thread, with no runtime: parks until woken.
fn block_on<F: Future>(future: F) -> F::Output {
    struct Unpark(std::thread::Thread);
    impl std::task::Wake for Unpark {
        fn wake(self: std::sync::Arc<Self>) {
            self.0.unpark();
        }
    }
    let waker = std::task::Waker::from(std::sync::Arc::new(Unpark(std::thread::current())));
    let mut context = std::task::Context::from_waker(&waker);
    let mut future = std::pin::pin!(future);
    loop {
        if let std::task::Poll::Ready(output) = future.as_mut().poll(&mut context) {
            return output;
        }
        std::thread::park();
    }
}

/// A module's send carries its request into shared memory in the thread it is polled in,
/// and the reply wakes that thread: here one outside the runtime, which only parks. The
/// bridge must need nothing of the runtime there, and the reply must still come.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_send_polled_outside_the_runtime_crosses_and_its_reply_wakes_it() {
    let cell = unique_name("outside-send");
    let _owner = owner(&cell, "DOUBLE");
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "ASKER",
    )
    .unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    let sender = std::thread::spawn(move || {
        (1..=200)
            .map(|value| block_on(asker.send(Number { value })).unwrap().value)
            .collect::<Vec<_>>()
    });
    let replies = within(10, tokio::task::spawn_blocking(move || sender.join()))
        .await
        .unwrap()
        .expect("the sending thread did not panic");
    assert_eq!(replies, (1..=200).map(|v| 2 * v).collect::<Vec<_>>());
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn two_cells_with_the_same_port_names_never_meet() {
    let (a, b) = (unique_name("cell-a"), unique_name("cell-b"));
    // Were their services one, the second owner would be refused: one owner per port.
    let _owner_a = owner(&a, "DOUBLE");
    let _owner_b = owner(&b, "DOUBLE");
    for cell in [&a, &b] {
        let remote = Remote::new(cell).unwrap();
        let imported = import::<Imported<Number, Number, usage::Receive>, _>(
            &remote, "DOUBLE", "DOUBLER", "ASKER",
        )
        .unwrap();
        let mut asker = imported.port().user_named("ASKER").unwrap();
        assert_eq!(
            within(5, asker.send(Number { value: 8 }))
                .await
                .unwrap()
                .value,
            16
        );
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_user_timeout_holds_across_processes_and_the_late_reply_harms_nothing() {
    let cell = unique_name("timeout");
    let _owner = owner(&cell, "DOUBLE");
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "ASKER",
    )
    .unwrap();
    let mut asker = imported
        .port()
        .user_named("ASKER")
        .unwrap()
        .with_timeout(Duration::from_millis(300));
    // The owner takes 1.5 s over 1500: past the user's timeout.
    let late = within(5, asker.send(Number { value: 1500 })).await;
    assert!(
        matches!(late, Err(SendError::ReplyTimeout { ref port }) if port == "DOUBLE"),
        "{late:?}"
    );
    // Until the owner answers 1500, the user's one outstanding request holds its place in
    // the port, as it would in one process: the next sends time out, untaken. Then the late
    // reply goes nowhere, and each later send gets its own reply.
    for value in [3, 4, 5] {
        let reply = within(5, async {
            loop {
                match asker.send(Number { value }).await {
                    Ok(reply) => break reply,
                    // The owner is still busy with 1500: this one times out too.
                    Err(SendError::ReplyTimeout { .. } | SendError::Timeout { .. }) => {}
                    Err(other) => panic!("{other:?}"),
                }
            }
        })
        .await;
        assert_eq!(reply.value, 2 * value);
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn an_owner_selects_over_an_exported_port_and_a_local_one() {
    use imrs_ports::{AnyUser, Port, PortSpec, select, usage};

    let cell = unique_name("select");
    // This process owns both: DOUBLE, used from another process, and LOCAL, from here.
    let remote_port: Port<Number, Number, usage::Receive, AnyUser, 2> = Port::new(
        PortSpec::new("DOUBLE", "DOUBLER")
            .user_list(["ASKER"])
            .priority(2),
    );
    let local_port: Port<Number, Number, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("LOCAL", "DOUBLER").priority(1));
    let _exported = imrs_ipc::export(&Remote::new(&cell).unwrap(), &remote_port).unwrap();
    let asking = user(&cell, "ASKER", "50");
    let mut local = local_port.user_named("HERE").unwrap();
    let local_sends = tokio::spawn(async move {
        for value in 1..=50 {
            assert_eq!(local.send(Number { value }).await.unwrap().value, 2 * value);
        }
    });
    let (mut from_there, mut from_here) =
        (remote_port.owner().unwrap(), local_port.owner().unwrap());
    let mut served = [0, 0];
    within(30, async {
        while served != [50, 50] {
            let (which, number, reply) = select()
                .or(&mut from_there, |(number, reply)| (0, number, reply))
                .or(&mut from_here, |(number, reply)| (1, number, reply))
                .await
                .unwrap();
            served[which] += 1;
            reply.reply(Number {
                value: 2 * number.value,
            });
        }
    })
    .await;
    within(5, local_sends).await.unwrap();
    assert_eq!(answers(asking).await.len(), 50);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_send_dropped_halfway_loses_nothing_and_the_next_gets_its_own_reply() {
    let cell = unique_name("dropped");
    let _owner = owner(&cell, "DOUBLE");
    let remote = Remote::new(&cell).unwrap();
    let imported = import::<Imported<Number, Number, usage::Receive>, _>(
        &remote, "DOUBLE", "DOUBLER", "ASKER",
    )
    .unwrap();
    let mut asker = imported.port().user_named("ASKER").unwrap();
    // The owner takes 1.2 s over 1200; the sender gives up after 200 ms, dropping the send.
    let gave_up = tokio::time::timeout(
        Duration::from_millis(200),
        asker.send(Number { value: 1200 }),
    )
    .await;
    assert!(gave_up.is_err(), "{gave_up:?}");
    // The next send waits for the owner to be done with the dropped one, then gets its own
    // reply, not the late 2400.
    let reply = within(5, asker.send(Number { value: 7 })).await.unwrap();
    assert_eq!(reply.value, 14);
}
