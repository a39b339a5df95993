//! A port says, for the length of the wake its message causes, which priority it was declared
//! with, so that an executor's waker can lift the woken task (`imrs_ports::transport::waking`).

use std::future::Future;
use std::pin::pin;
use std::sync::{Arc, Mutex};
use std::task::{Context, Poll, Wake, Waker};

use imrs_ports::transport::waking;
use imrs_ports::{Port, PortSpec, Priority, usage};

/// A waker that notes the urgency of each wake it gets.
#[derive(Default)]
struct Noting(Mutex<Vec<Priority>>);

impl Wake for Noting {
    fn wake(self: Arc<Self>) {
        self.wake_by_ref();
    }

    fn wake_by_ref(self: &Arc<Self>) {
        self.0.lock().unwrap().push(waking());
    }
}

/// The urgency of the wakes a receiver and a sender get for one message on a port declared
/// by `spec`: the request wakes the receiver, the reply wakes the sender.
fn wakes_of_one_message(spec: PortSpec) -> (Vec<Priority>, Vec<Priority>) {
    let port = Port::<u8, u8, usage::Receive>::new(spec);
    let mut owner = port.owner().unwrap();
    let mut user = port.user_named("USER").unwrap();
    let (receiver, sender) = (Arc::new(Noting::default()), Arc::new(Noting::default()));
    let (receiver_waker, sender_waker) = (
        Waker::from(Arc::clone(&receiver)),
        Waker::from(Arc::clone(&sender)),
    );

    let mut receiving = pin!(owner.receive());
    assert!(
        receiving
            .as_mut()
            .poll(&mut Context::from_waker(&receiver_waker))
            .is_pending()
    );
    let mut sending = pin!(user.send(7));
    assert!(
        sending
            .as_mut()
            .poll(&mut Context::from_waker(&sender_waker))
            .is_pending()
    );
    let Poll::Ready(Ok((message, reply))) = receiving
        .as_mut()
        .poll(&mut Context::from_waker(&receiver_waker))
    else {
        panic!("the request was posted");
    };
    reply.reply(message + 1);
    let Poll::Ready(Ok(answer)) = sending
        .as_mut()
        .poll(&mut Context::from_waker(&sender_waker))
    else {
        panic!("the reply was given");
    };
    assert_eq!(answer, 8);
    assert_eq!(waking(), Priority::DEFAULT, "no wake runs now");
    let noted = |noting: &Noting| noting.0.lock().unwrap().clone();
    (noted(&receiver), noted(&sender))
}

#[test]
fn a_message_on_a_port_with_a_priority_wakes_at_that_priority_both_ways() {
    let (receiver, sender) = wakes_of_one_message(PortSpec::new("ESTOP", "SAFETY").priority(1));
    assert_eq!(receiver, [Priority::declared(1)], "the request's wake");
    assert_eq!(sender, [Priority::declared(1)], "the reply's wake");
}

#[test]
fn a_port_without_a_priority_wakes_at_the_default() {
    let (receiver, sender) = wakes_of_one_message(PortSpec::new("ROUTINE", "CONVEYOR"));
    assert_eq!(receiver, [Priority::DEFAULT]);
    assert_eq!(sender, [Priority::DEFAULT]);
}
