//! GATE's FREQUENCY port: a bounded-buffer filter spliced in between the users and GATE.

mod common;

use std::time::Duration;

use common::{on_both_runtimes, until, until_sleepers, virtual_clock};
use imrs_ports::{
    AnyUser, BoundedBuffer, BoundedBufferPort, Named, PortSpec, SendError, user_list,
};
use imrs_testkit::poll_once;

struct LoadIt;
impl Named for LoadIt {
    const NAME: &'static str = "LOAD_IT";
}
struct ChipIt;
impl Named for ChipIt {
    const NAME: &'static str = "CHIP_IT";
}

user_list! {
    /// `USERLIST=(LOAD_IT,CHIP_IT)`.
    FrequencyUsers = [LoadIt, ChipIt];
}

/// FREQUENCY(TASK_NUM, TIME_FOR_ONE).
type Frequency = BoundedBufferPort<(i32, f64), FrequencyUsers, 2>;

#[test]
fn users_sends_return_at_once_and_gate_reads_them_in_order() {
    on_both_runtimes(|| async {
        let frequency = Frequency::new(PortSpec::new("FREQUENCY", "GATE"), "BOUNDED_BUFFER");
        let mut gate = frequency.owner().unwrap();
        let mut load_it = frequency.user::<LoadIt>().unwrap();
        let mut chip_it = frequency.user::<ChipIt>().unwrap();
        let filter = tokio::spawn(BoundedBuffer::<_, 20>::new().run(frequency.filter().unwrap()));

        // SEND FREQUENCY(TASK_NUM, TEMP_TIME): nothing yet, TASK_NUM = -1 in the seed.
        assert_eq!(gate.send(()).await.unwrap(), None);
        // Neither user waits for GATE: the filter replies as soon as it stores the message.
        load_it.send((0, 20.0)).await.unwrap();
        chip_it.send((1, 40.0)).await.unwrap();
        load_it.send((0, 18.0)).await.unwrap();
        assert_eq!(gate.send(()).await.unwrap(), Some((0, 20.0)));
        assert_eq!(gate.send(()).await.unwrap(), Some((1, 40.0)));
        assert_eq!(gate.send(()).await.unwrap(), Some((0, 18.0)));
        assert_eq!(gate.send(()).await.unwrap(), None);
        filter.abort();
    });
}

/// FREQUENCY on a virtual clock with a buffer of `CAP` running, LOAD_IT's end timed out
/// after 1 s.
struct TimedBuffer {
    clock: imrs_ports::VirtualClock,
    gate: imrs_ports::End<(), Option<(i32, f64)>, imrs_ports::usage::Send>,
    load_it: imrs_ports::End<(i32, f64), (), imrs_ports::usage::Send>,
    filter: tokio::task::JoinHandle<()>,
}

fn timed_buffer<const CAP: usize>() -> TimedBuffer {
    let (clock, shared) = virtual_clock();
    let frequency = Frequency::new(
        PortSpec::new("FREQUENCY", "GATE").clock(shared),
        "BOUNDED_BUFFER",
    );
    TimedBuffer {
        clock,
        gate: frequency.owner().unwrap(),
        load_it: frequency
            .user::<LoadIt>()
            .unwrap()
            .with_timeout(Duration::from_secs(1)),
        filter: tokio::spawn(BoundedBuffer::<_, CAP>::new().run(frequency.filter().unwrap())),
    }
}

#[test]
fn a_full_buffer_holds_the_sender_back_and_loses_nothing() {
    on_both_runtimes(|| async {
        let TimedBuffer {
            clock,
            mut gate,
            mut load_it,
            filter,
        } = timed_buffer::<2>();

        load_it.send((0, 1.0)).await.unwrap();
        load_it.send((0, 2.0)).await.unwrap();
        // Full: the third send waits, and times out with its message handed back.
        let third = tokio::spawn(async move { (load_it.send((0, 3.0)).await, load_it) });
        until_sleepers(&clock, 1).await;
        clock.advance(Duration::from_secs(1));
        let (refused, mut load_it) = third.await.unwrap();
        match refused {
            Err(SendError::Timeout { port, message }) => {
                assert_eq!(port, "FREQUENCY");
                assert_eq!(message, (0, 3.0));
            }
            other => panic!("expected back-pressure to time out, got {other:?}"),
        }
        // Once GATE takes one, there is room again.
        assert_eq!(gate.send(()).await.unwrap(), Some((0, 1.0)));
        let fourth = tokio::spawn(async move { load_it.send((0, 4.0)).await });
        until(|| fourth.is_finished()).await;
        fourth.await.unwrap().unwrap();
        assert_eq!(gate.send(()).await.unwrap(), Some((0, 2.0)));
        assert_eq!(gate.send(()).await.unwrap(), Some((0, 4.0)));
        assert_eq!(gate.send(()).await.unwrap(), None);
        filter.abort();
    });
}

#[test]
fn a_shown_filtered_port_shows_both_sides() {
    let port = BoundedBufferPort::<(i32, f64), AnyUser, 2>::new(
        PortSpec::new("FREQUENCY", "GATE").user_list(["LOAD_IT", "CHIP_IT"]),
        "BOUNDED_BUFFER",
    )
    .shown();
    let user = port.user_named("LOAD_IT").unwrap();
    let shown = user.shown().expect("the users' side shows its values");
    assert_eq!((shown.request)(&(0, 18.5)), "(0, 18.5)");
    let owner = port.owner().unwrap();
    let shown = owner.shown().expect("FILTER shows its values");
    assert_eq!((shown.reply)(&Some((1, 9.0))), "Some((1, 9.0))");
}

#[test]
fn while_the_filter_runs_a_send_with_room_to_spare_completes_in_its_first_poll() {
    // The filter has started and waits: a send is one write into the buffer, and GATE's
    // request one read, each done in its own first poll, with no turn of the filter task.
    let runtime = tokio::runtime::Builder::new_current_thread()
        .build()
        .unwrap();
    runtime.block_on(async {
        let frequency = Frequency::new(PortSpec::new("FREQUENCY", "GATE"), "BOUNDED_BUFFER");
        let mut gate = frequency.owner().unwrap();
        let mut load_it = frequency.user::<LoadIt>().unwrap();
        let filter = tokio::spawn(BoundedBuffer::<_, 4>::new().run(frequency.filter().unwrap()));
        tokio::task::yield_now().await;
        for n in 0..3 {
            let mut send = std::pin::pin!(load_it.send((0, f64::from(n))));
            assert!(poll_once(send.as_mut()).is_ready(), "send {n} waited");
        }
        for n in 0..3 {
            let mut request = std::pin::pin!(gate.send(()));
            match poll_once(request.as_mut()) {
                std::task::Poll::Ready(Ok(Some((0, time)))) => assert_eq!(time, f64::from(n)),
                other => panic!("GATE's request {n} got {other:?}"),
            }
        }
        let mut empty = std::pin::pin!(gate.send(()));
        assert!(matches!(
            poll_once(empty.as_mut()),
            std::task::Poll::Ready(Ok(None))
        ));
        filter.abort();
    });
}

#[test]
fn a_full_buffer_takes_exactly_its_capacity_in_order_then_holds_back() {
    on_both_runtimes(|| async {
        let TimedBuffer {
            clock,
            mut gate,
            mut load_it,
            filter,
        } = timed_buffer::<5>();
        // Four in place and the fifth through the filter: five, and no more.
        for n in 0..5 {
            load_it.send((0, f64::from(n))).await.unwrap();
        }
        let sixth = tokio::spawn(async move { (load_it.send((0, 5.0)).await, load_it) });
        until_sleepers(&clock, 1).await;
        clock.advance(Duration::from_secs(1));
        let (refused, _load_it) = sixth.await.unwrap();
        assert!(
            matches!(
                refused,
                Err(SendError::Timeout {
                    message: (0, 5.0),
                    ..
                })
            ),
            "the sixth send should be held back, got {refused:?}"
        );
        for n in 0..5 {
            assert_eq!(gate.send(()).await.unwrap(), Some((0, f64::from(n))));
        }
        assert_eq!(gate.send(()).await.unwrap(), None);
        filter.abort();
    });
}

#[test]
fn two_users_and_gate_on_four_threads_lose_nothing_and_keep_each_users_order() {
    const EACH: i32 = 2_000;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(4)
        .build()
        .unwrap();
    runtime.block_on(async {
        let frequency = Frequency::new(PortSpec::new("FREQUENCY", "GATE"), "BOUNDED_BUFFER");
        let mut gate = frequency.owner().unwrap();
        let filter = tokio::spawn(BoundedBuffer::<_, 8>::new().run(frequency.filter().unwrap()));
        let mut load_it = frequency.user::<LoadIt>().unwrap();
        let mut chip_it = frequency.user::<ChipIt>().unwrap();
        let users = [
            tokio::spawn(async move {
                for n in 0..EACH {
                    load_it.send((0, f64::from(n))).await.unwrap();
                }
            }),
            tokio::spawn(async move {
                for n in 0..EACH {
                    chip_it.send((1, f64::from(n))).await.unwrap();
                }
            }),
        ];
        let mut next = [0.0, 0.0];
        let mut read = 0;
        while read < 2 * EACH {
            match gate.send(()).await.unwrap() {
                Some((user, time)) => {
                    let user = usize::try_from(user).unwrap();
                    assert_eq!(time, next[user], "user {user} out of order");
                    next[user] += 1.0;
                    read += 1;
                }
                None => tokio::task::yield_now().await,
            }
        }
        for user in users {
            user.await.unwrap();
        }
        assert_eq!(gate.send(()).await.unwrap(), None);
        filter.abort();
    });
}

#[test]
fn a_stopped_filter_serves_nothing_in_place_and_a_new_one_serves_again() {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .build()
        .unwrap();
    runtime.block_on(async {
        let frequency = Frequency::new(PortSpec::new("FREQUENCY", "GATE"), "BOUNDED_BUFFER");
        let mut gate = frequency.owner().unwrap();
        let mut load_it = frequency.user::<LoadIt>().unwrap();
        let first = tokio::spawn(BoundedBuffer::<_, 4>::new().run(frequency.filter().unwrap()));
        tokio::task::yield_now().await;
        load_it.send((0, 1.0)).await.unwrap();
        first.abort();
        assert!(first.await.unwrap_err().is_cancelled());
        // No filter: the send waits for one, and the message held by the stopped filter went
        // with it, as a filter task's own messages do.
        let mut waiting = Box::pin(load_it.send((0, 2.0)));
        assert!(poll_once(waiting.as_mut()).is_pending());
        let second = tokio::spawn(BoundedBuffer::<_, 4>::new().run(frequency.filter().unwrap()));
        waiting.await.unwrap();
        let mut in_place = std::pin::pin!(load_it.send((0, 3.0)));
        assert!(poll_once(in_place.as_mut()).is_ready());
        assert_eq!(gate.send(()).await.unwrap(), Some((0, 2.0)));
        assert_eq!(gate.send(()).await.unwrap(), Some((0, 3.0)));
        assert_eq!(gate.send(()).await.unwrap(), None);
        second.abort();
    });
}
