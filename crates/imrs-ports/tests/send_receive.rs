//! send / receive / reply, on both tokio runtimes.

mod common;

use std::time::Duration;

use common::{on_both_runtimes, until, until_sleepers, virtual_clock};
use imrs_ports::{
    Clock, Instant, Port, PortSpec, ProcessType, ReceiveError, SendError, Shown, usage,
};

#[test]
fn send_waits_for_the_reply_and_returns_it() {
    on_both_runtimes(|| async {
        let port = Port::<u32, u32, usage::Receive>::new(PortSpec::new("P", "OWNER"));
        let mut owner = port.owner().unwrap();
        let mut user = port.user_named("USER").unwrap();
        let sender = tokio::spawn(async move { user.send(20).await.unwrap() });
        let (message, reply) = owner.receive().await.unwrap();
        assert_eq!(message, 20);
        reply.reply(message + 1);
        assert_eq!(sender.await.unwrap(), 21);
    });
}

#[test]
fn the_owner_may_send_and_a_user_receive() {
    on_both_runtimes(|| async {
        // LET_1_GO: GATE sends, RELEASE receives and answers with a return code.
        let port = Port::<(), i32, usage::Send>::new(PortSpec::new("LET_1_GO", "GATE"));
        let mut gate = port.owner().unwrap();
        let mut release = port.user_named("RELEASE").unwrap();
        let releasing = tokio::spawn(async move {
            let ((), reply) = release.receive().await.unwrap();
            reply.reply(0);
        });
        assert_eq!(gate.send(()).await.unwrap(), 0);
        releasing.await.unwrap();
    });
}

#[test]
fn receives_come_in_arrival_order_and_replies_in_any_order() {
    on_both_runtimes(|| async {
        let port = Port::<u32, u32, usage::Receive, imrs_ports::AnyUser, 3>::new(PortSpec::new(
            "P", "OWNER",
        ));
        let mut owner = port.owner().unwrap();
        let mut senders = Vec::new();
        for n in 0..3u32 {
            let mut user = port.user_named(format!("USER{n}")).unwrap();
            senders.push(tokio::spawn(async move { user.send(n).await.unwrap() }));
            // Each sender is waiting before the next starts: a known arrival order.
            until(|| owner.waiting() == n as usize + 1).await;
        }
        let mut pending = Vec::new();
        for expected in 0..3u32 {
            let (message, reply) = owner.receive().await.unwrap();
            assert_eq!(message, expected);
            pending.push((message, reply));
        }
        // Three replies pending at once; answer the last first, one from another task.
        let (last, last_reply) = pending.pop().unwrap();
        last_reply.reply(last * 10);
        let (middle, middle_reply) = pending.pop().unwrap();
        tokio::spawn(async move { middle_reply.reply(middle * 10) })
            .await
            .unwrap();
        let (first, first_reply) = pending.pop().unwrap();
        first_reply.reply(first * 10);
        for (n, sender) in senders.into_iter().enumerate() {
            assert_eq!(sender.await.unwrap(), n as u32 * 10);
        }
    });
}

#[test]
fn a_reply_handle_dropped_unanswered_fails_the_sender_at_once() {
    on_both_runtimes(|| async {
        let port = Port::<&str, (), usage::Receive>::new(PortSpec::new("P", "OWNER"));
        let mut owner = port.owner().unwrap();
        let mut user = port.user_named("USER").unwrap();
        let sender = tokio::spawn(async move { user.send("card").await });
        let (_, reply) = owner.receive().await.unwrap();
        drop(reply);
        match sender.await.unwrap() {
            Err(SendError::NoReply { port }) => assert_eq!(port, "P"),
            other => panic!("expected NoReply, got {other:?}"),
        }
    });
}

#[test]
fn a_send_times_out_on_the_virtual_clock_and_hands_the_message_back() {
    on_both_runtimes(|| async {
        let (clock, shared) = virtual_clock();
        // LET_1_GO with TIMEOUT=2 sec, and nobody receiving.
        let port = Port::<&str, i32, usage::Send>::new(
            PortSpec::new("LET_1_GO", "GATE")
                .owner_timeout(Duration::from_secs(2))
                .clock(shared),
        );
        let mut gate = port.owner().unwrap();
        let _release = port.user_named("RELEASE").unwrap();
        let sending = tokio::spawn(async move { gate.send("pallet").await });
        until_sleepers(&clock, 1).await;
        clock.advance(Duration::from_millis(1999));
        for _ in 0..10 {
            tokio::task::yield_now().await;
        }
        assert!(
            !sending.is_finished(),
            "the send gave up before its timeout"
        );
        assert_eq!(clock.sleepers(), 1);
        clock.advance(Duration::from_millis(1));
        match sending.await.unwrap() {
            Err(SendError::Timeout { port, message }) => {
                assert_eq!(port, "LET_1_GO");
                assert_eq!(message, "pallet");
            }
            other => panic!("expected a timeout, got {other:?}"),
        }
        assert_eq!(clock.now(), Instant::from_start(Duration::from_secs(2)));
    });
}

#[test]
fn a_send_not_replied_in_time_fails_and_the_late_reply_is_dropped() {
    on_both_runtimes(|| async {
        let (clock, shared) = virtual_clock();
        let port = Port::<u8, u8, usage::Receive>::new(PortSpec::new("P", "OWNER").clock(shared));
        let mut owner = port.owner().unwrap();
        let mut user = port
            .user_named("USER")
            .unwrap()
            .with_timeout(Duration::from_secs(3));
        let sending = tokio::spawn(async move {
            let first = user.send(1).await;
            (first, user)
        });
        let (_, late) = owner.receive().await.unwrap();
        until_sleepers(&clock, 1).await;
        clock.advance(Duration::from_secs(3));
        let (first, mut user) = sending.await.unwrap();
        assert!(
            matches!(first, Err(SendError::ReplyTimeout { .. })),
            "{first:?}"
        );
        late.reply(99);
        // The slot is usable again, and the late reply does not leak into the next send.
        let next = tokio::spawn(async move { user.send(2).await });
        let (message, reply) = owner.receive().await.unwrap();
        assert_eq!(message, 2);
        reply.reply(20);
        assert_eq!(next.await.unwrap().unwrap(), 20);
    });
}

#[test]
fn a_receive_times_out() {
    on_both_runtimes(|| async {
        let (clock, shared) = virtual_clock();
        // PALLET_IN_PLACE: TIMEOUT=30 SEC, USAGE=RECEIVE, #USERS=1.
        let port = Port::<(), (), usage::Receive>::new(
            PortSpec::new("PALLET_IN_PLACE", "LOAD_CARD")
                .owner_timeout(Duration::from_secs(30))
                .clock(shared),
        );
        let mut load_card = port.owner().unwrap();
        let _freeze_pallet = port.user_named("FREEZE_PALLET").unwrap();
        let receiving = tokio::spawn(async move { load_card.receive().await.map(|_| ()) });
        until_sleepers(&clock, 1).await;
        clock.advance(Duration::from_secs(30));
        assert_eq!(
            receiving.await.unwrap(),
            Err(ReceiveError::Timeout {
                port: "PALLET_IN_PLACE".into()
            })
        );
    });
}

#[test]
fn a_dropped_send_withdraws_its_message() {
    on_both_runtimes(|| async {
        let port = Port::<u8, u8, usage::Receive>::new(PortSpec::new("P", "OWNER"));
        let mut owner = port.owner().unwrap();
        let mut user = port.user_named("USER").unwrap();
        {
            let send = user.send(1);
            // Polled once (posted), then dropped.
            let mut send = Box::pin(send);
            assert!(futures_poll_once(send.as_mut()).is_pending());
            assert_eq!(owner.waiting(), 1);
        }
        assert_eq!(owner.waiting(), 0);
        assert!(owner.try_receive().is_none());
    });
}

fn futures_poll_once<F: std::future::Future>(
    future: std::pin::Pin<&mut F>,
) -> std::task::Poll<F::Output> {
    let mut cx = std::task::Context::from_waker(std::task::Waker::noop());
    future.poll(&mut cx)
}

#[test]
fn a_port_nobody_can_receive_on_fails_its_senders() {
    on_both_runtimes(|| async {
        let port = Port::<u8, u8, usage::Receive>::new(PortSpec::new("P", "OWNER"));
        let owner = port.owner().unwrap();
        let mut user = port.user_named("USER").unwrap();
        drop(owner);
        drop(port);
        match user.send(5).await {
            Err(SendError::Closed { port, message }) => {
                assert_eq!(port, "P");
                assert_eq!(message, 5);
            }
            other => panic!("expected Closed, got {other:?}"),
        }
    });
}

#[test]
fn a_restarted_owner_serves_what_waits_on_the_port() {
    on_both_runtimes(|| async {
        let port = Port::<u8, u8, usage::Receive>::new(PortSpec::new("P", "OWNER"));
        let first_copy = port.owner().unwrap();
        let mut user = port.user_named("USER").unwrap();
        let sending = tokio::spawn(async move { user.send(5).await });
        drop(first_copy);
        // The port outlives the owner's copy: a new copy attaches and serves.
        let mut second_copy = port.owner().unwrap();
        let (message, reply) = second_copy.receive().await.unwrap();
        reply.reply(message * 2);
        assert_eq!(sending.await.unwrap().unwrap(), 10);
    });
}

#[test]
fn a_tight_port_round_trips_across_threads() {
    on_both_runtimes(|| async {
        let port = Port::<u64, u64, usage::Receive>::new(
            PortSpec::new("SERVO", "ARM").process_type(ProcessType::Tight),
        );
        let mut arm = port.owner().unwrap();
        let mut joint = port.user_named("JOINT").unwrap();
        let serving = tokio::spawn(async move {
            for _ in 0..100 {
                let (n, reply) = arm.receive().await.unwrap();
                reply.reply(n + 1);
            }
        });
        for n in 0..100 {
            assert_eq!(joint.send(n).await.unwrap(), n + 1);
        }
        serving.await.unwrap();
    });
}

#[test]
fn an_endless_timeout_on_the_real_clock_is_no_overflow() {
    on_both_runtimes(|| async {
        let port = Port::<u8, u8, usage::Receive>::new(
            PortSpec::new("P", "OWNER").owner_timeout(Duration::MAX),
        );
        let mut owner = port.owner().unwrap();
        let mut user = port.user_named("USER").unwrap().with_timeout(Duration::MAX);
        let sending = tokio::spawn(async move { user.send(3).await });
        let (message, reply) = owner.receive().await.unwrap();
        reply.reply(message + 1);
        assert_eq!(sending.await.unwrap().unwrap(), 4);
    });
}

#[test]
fn a_port_says_how_its_values_are_shown_and_the_first_way_set_holds() {
    let port = Port::<u32, i32, usage::Send>::new(PortSpec::new("CARD_IN_PLACE", "LOAD_CARD"));
    assert!(port.owner().unwrap().shown().is_none());
    let hex = Shown {
        request: |card: &u32| format!("{card:#x}"),
        reply: |rc: &i32| format!("rc {rc}"),
    };
    let port = port.shown_with(hex).shown();
    let end = port.user_named("SCREW_IN_CARD").unwrap();
    let shown = end.shown().expect("the port shows its values");
    assert_eq!(
        ((shown.request)(&255), (shown.reply)(&-1)),
        ("0xff".into(), "rc -1".into())
    );
}
