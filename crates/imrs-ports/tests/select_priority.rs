//! select: the ready port of highest priority first, FIFO within a port, never at random.

mod common;

use std::collections::VecDeque;

use common::on_both_runtimes;
use imrs_ports::{AllClosed, AnyUser, End, Port, PortSpec, select, usage, when};
use proptest::prelude::*;

type Inbox = Port<u32, (), usage::Receive, AnyUser, 20>;

/// Declares three ports of priorities 1, 2 and default, with room for twenty users each.
fn three_ports() -> [Inbox; 3] {
    [
        Inbox::new(PortSpec::new("URGENT", "OWNER").priority(1)),
        Inbox::new(PortSpec::new("NORMAL", "OWNER").priority(2)),
        Inbox::new(PortSpec::new("DEFAULT", "OWNER")),
    ]
}

/// One select over the three owner ends: which port, which message.
async fn select_once(ends: &mut [End<u32, (), usage::Receive>; 3]) -> (usize, u32) {
    let [urgent, normal, default] = ends;
    let take = |port: usize| {
        move |(message, reply): (u32, imrs_ports::ReplyHandle<()>)| {
            reply.reply(());
            (port, message)
        }
    };
    // Declared in an order unlike the priorities, so that the order of `or` cannot pass for
    // the priority.
    select()
        .or(&mut *default, take(2))
        .or(&mut *normal, take(1))
        .or(&mut *urgent, take(0))
        .await
        .expect("no guard is closed")
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn select_serves_by_priority_then_arrival(arrivals in prop::collection::vec(0usize..3, 1..20)) {
        let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        runtime.block_on(async {
            let ports = three_ports();
            let mut owners = ports.each_ref().map(|port| port.owner().unwrap());
            let mut expected: [VecDeque<u32>; 3] = Default::default();
            let mut senders = Vec::new();
            // Each arrival is a user of its port sending a sequence number; each send is
            // posted before the next one starts.
            for (sequence, &port) in arrivals.iter().enumerate() {
                let mut user = ports[port].user_named(format!("USER{sequence}")).unwrap();
                let sequence = sequence as u32;
                let mut send = Box::pin(async move { user.send(sequence).await.unwrap() });
                let mut cx = std::task::Context::from_waker(std::task::Waker::noop());
                assert!(send.as_mut().poll(&mut cx).is_pending());
                senders.push(send);
                expected[port].push_back(sequence);
            }
            for _ in 0..arrivals.len() {
                let (port, message) = select_once(&mut owners).await;
                // The most urgent port that has anything must be the one served...
                let most_urgent = (0..3).find(|&p| !expected[p].is_empty()).unwrap();
                prop_assert_eq!(port, most_urgent);
                // ...and within it, the earliest arrival.
                prop_assert_eq!(Some(message), expected[port].pop_front());
            }
            for sender in senders {
                sender.await;
            }
            Ok(())
        })?;
    }
}

#[test]
fn a_closed_guard_is_not_served_even_when_ready() {
    on_both_runtimes(|| async {
        let ports = three_ports();
        let [urgent, normal, _] = &ports;
        let (mut urgent_owner, mut normal_owner) =
            (urgent.owner().unwrap(), normal.owner().unwrap());
        let mut to_urgent = urgent.user_named("A").unwrap();
        let mut to_normal = normal.user_named("B").unwrap();
        let a = tokio::spawn(async move { to_urgent.send(1).await.unwrap() });
        let b = tokio::spawn(async move { to_normal.send(2).await.unwrap() });
        common::until(|| urgent_owner.waiting() == 1 && normal_owner.waiting() == 1).await;
        let served = select()
            .or(when(false, &mut urgent_owner), |(m, r): (u32, _)| (m, r))
            .or(&mut normal_owner, |(m, r)| (m, r))
            .await
            .unwrap();
        assert_eq!(served.0, 2);
        served.1.reply(());
        let (m, r) = urgent_owner.receive().await.unwrap();
        assert_eq!(m, 1);
        r.reply(());
        a.await.unwrap();
        b.await.unwrap();
    });
}

#[test]
fn a_select_with_every_guard_closed_says_so() {
    on_both_runtimes(|| async {
        let ports = three_ports();
        let mut owner = ports[0].owner().unwrap();
        let result = select().or(when(false, &mut owner), |_| ()).await;
        assert_eq!(result, Err(AllClosed));
    });
}

#[test]
fn select_waits_until_a_message_arrives() {
    on_both_runtimes(|| async {
        let ports = three_ports();
        let mut owners = ports.each_ref().map(|port| port.owner().unwrap());
        let mut user = ports[2].user_named("LATE").unwrap();
        let late = tokio::spawn(async move {
            tokio::task::yield_now().await;
            user.send(42).await.unwrap()
        });
        assert_eq!(select_once(&mut owners).await, (2, 42));
        late.await.unwrap();
    });
}

#[test]
fn a_select_over_ports_closed_for_good_ends_as_receive_does() {
    on_both_runtimes(|| async {
        let [urgent, normal, _] = three_ports();
        let mut urgent_owner = urgent.owner().unwrap();
        let mut normal_owner = normal.owner().unwrap();
        let late_sender = normal.user_named("LATE").unwrap();
        // Both declarations go, and then the last user: nobody can ever send on either.
        drop((urgent, normal));
        let selecting = tokio::spawn(async move {
            let result = select()
                .or(&mut urgent_owner, |_| "urgent")
                .or(&mut normal_owner, |_| "normal")
                .await;
            let receive = urgent_owner.receive().await.map(|_| ());
            (result, receive.is_err())
        });
        tokio::task::yield_now().await;
        drop(late_sender);
        let (result, receive_closed) = selecting.await.unwrap();
        assert!(receive_closed, "receive on the same port says Closed");
        assert_eq!(result, Err(AllClosed));
    });
}

#[test]
fn a_message_sent_before_the_port_closed_is_still_selected() {
    on_both_runtimes(|| async {
        let [urgent, _, _] = three_ports();
        let mut owner = urgent.owner().unwrap();
        let mut sender = urgent.user_named("LAST").unwrap();
        drop(urgent);
        let sending = tokio::spawn(async move { sender.send(7).await });
        let chosen = select()
            .or(
                &mut owner,
                |(message, reply): (u32, imrs_ports::ReplyHandle<()>)| {
                    reply.reply(());
                    message
                },
            )
            .await;
        assert_eq!(chosen, Ok(7));
        sending.await.unwrap().unwrap();
        assert_eq!(select().or(&mut owner, |_| 0).await, Err(AllClosed));
    });
}
