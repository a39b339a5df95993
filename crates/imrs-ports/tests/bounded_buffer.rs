//! GATE's FREQUENCY port: a bounded-buffer filter spliced in between the users and GATE.

mod common;

use std::time::Duration;

use common::{on_both_runtimes, until, until_sleepers, virtual_clock};
use imrs_ports::{
    AnyUser, BoundedBuffer, BoundedBufferPort, Named, PortSpec, SendError, user_list,
};

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

#[test]
fn a_full_buffer_holds_the_sender_back_and_loses_nothing() {
    on_both_runtimes(|| async {
        let (clock, shared) = virtual_clock();
        let frequency = Frequency::new(
            PortSpec::new("FREQUENCY", "GATE").clock(shared),
            "BOUNDED_BUFFER",
        );
        let mut gate = frequency.owner().unwrap();
        let mut load_it = frequency
            .user::<LoadIt>()
            .unwrap()
            .with_timeout(Duration::from_secs(1));
        let filter = tokio::spawn(BoundedBuffer::<_, 2>::new().run(frequency.filter().unwrap()));

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
