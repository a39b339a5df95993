//! sendall: the owner sends to every user and unblocks at the first reply.

mod common;

use std::time::Duration;

use common::{on_both_runtimes, until_sleepers, virtual_clock};
use imrs_ports::{AnyUser, BroadcastError, Port, PortSpec, usage};

type Stop = Port<&'static str, u32, usage::SendAll, AnyUser, 3>;

#[test]
fn send_all_unblocks_at_the_first_reply_and_the_later_ones_stay_readable() {
    on_both_runtimes(|| async {
        let port = Stop::new(PortSpec::new("STOP", "SUPERVISOR"));
        let mut supervisor = port.owner().unwrap();
        let mut first = port.user_named("ROBOT1").unwrap();
        let mut second = port.user_named("ROBOT2").unwrap();
        let mut third = port.user_named("ROBOT3").unwrap();

        let sending = tokio::spawn(async move {
            let mut broadcast = supervisor.send_all("halt").await.unwrap();
            let first = (broadcast.from.to_string(), broadcast.first);
            let mut later = Vec::new();
            while let Some((from, reply)) = broadcast.next_reply().await {
                later.push((from.to_string(), reply));
            }
            (first, later)
        });
        let (message, reply) = second.receive().await.unwrap();
        assert_eq!(message, "halt");
        reply.reply(2);
        let (_, reply) = first.receive().await.unwrap();
        reply.reply(1);
        // ROBOT3 drops its handle: the broadcast still ends, without its answer.
        let (_, reply) = third.receive().await.unwrap();
        drop(reply);
        let (first_reply, mut later) = sending.await.unwrap();
        later.sort();
        let mut all = vec![first_reply];
        all.extend(later);
        all.sort();
        assert_eq!(all, [("ROBOT1".to_string(), 1), ("ROBOT2".to_string(), 2)]);
    });
}

#[test]
fn send_all_with_no_users_hands_the_message_back() {
    on_both_runtimes(|| async {
        let port = Stop::new(PortSpec::new("STOP", "SUPERVISOR"));
        let mut supervisor = port.owner().unwrap();
        match supervisor.send_all("halt").await {
            Err(BroadcastError::NoUsers { port, message }) => {
                assert_eq!(port, "STOP");
                assert_eq!(message, "halt");
            }
            other => panic!("expected NoUsers, got {other:?}"),
        }
    });
}

#[test]
fn send_all_times_out_when_nobody_answers() {
    on_both_runtimes(|| async {
        let (clock, shared) = virtual_clock();
        let port = Stop::new(
            PortSpec::new("STOP", "SUPERVISOR")
                .owner_timeout(Duration::from_secs(1))
                .clock(shared),
        );
        let mut supervisor = port.owner().unwrap();
        let mut robot = port.user_named("ROBOT1").unwrap();
        let sending = tokio::spawn(async move {
            let result = supervisor.send_all("halt").await.map(|b| b.first);
            (result, supervisor)
        });
        until_sleepers(&clock, 1).await;
        clock.advance(Duration::from_secs(1));
        let (result, _supervisor) = sending.await.unwrap();
        assert!(matches!(
            result,
            Err(BroadcastError::Timeout {
                message: "halt",
                ..
            })
        ));
        // The withdrawn message is gone from the robot's port.
        assert!(robot.try_receive().is_none());
    });
}

#[test]
fn send_all_does_not_wait_for_a_user_that_detached_before_taking_the_message() {
    on_both_runtimes(|| async {
        let port = Stop::new(PortSpec::new("STOP", "SUPERVISOR"));
        let mut supervisor = port.owner().unwrap();
        let mut answering = port.user_named("ROBOT1").unwrap();
        let leaving = port.user_named("ROBOT2").unwrap();
        let sending = tokio::spawn(async move {
            let mut broadcast = supervisor.send_all("halt").await.unwrap();
            let later = broadcast.next_reply().await;
            (broadcast.from.to_string(), broadcast.first, later)
        });
        let (_, reply) = answering.receive().await.unwrap();
        reply.reply(1);
        // ROBOT2 goes without taking "halt": the broadcast must end without its answer.
        drop(leaving);
        let (from, first, later) = sending.await.unwrap();
        assert_eq!((from.as_str(), first), ("ROBOT1", 1));
        assert_eq!(later, None);
    });
}

#[test]
fn an_owner_waiting_for_its_first_user_is_woken_when_one_attaches_from_another_thread() {
    use std::future::Future;
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};
    use std::task::{Context, Poll, Wake, Waker};

    /// A waker that remembers it was woken.
    struct Flag(AtomicBool);
    impl Wake for Flag {
        fn wake(self: Arc<Self>) {
            self.0.store(true, Ordering::SeqCst);
        }
    }

    let port = Stop::new(PortSpec::new("STOP", "SUPERVISOR"));
    let supervisor = port.owner().unwrap();
    let flag = Arc::new(Flag(AtomicBool::new(false)));
    let waker = Waker::from(Arc::clone(&flag));
    let mut cx = Context::from_waker(&waker);
    let mut waiting = std::pin::pin!(supervisor.peer_attached());
    // Nobody has attached yet: the owner waits.
    assert_eq!(waiting.as_mut().poll(&mut cx), Poll::Pending);
    assert!(!flag.0.load(Ordering::SeqCst));
    // A user attaches from another thread, and stays; the port stays declared here, so
    // that nothing but the attaching can wake the owner.
    let declared = port.clone();
    let attaching = std::thread::spawn(move || declared.user_named("ROBOT1"));
    let _robot = attaching.join().unwrap().unwrap();
    assert!(
        flag.0.load(Ordering::SeqCst),
        "the attaching wakes the owner"
    );
    assert_eq!(waiting.as_mut().poll(&mut cx), Poll::Ready(()));
    assert_eq!(supervisor.peers(), ["ROBOT1"]);
}
