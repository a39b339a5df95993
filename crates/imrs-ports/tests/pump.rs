//! A transport's turn in a spinning wait (`Port::pump_with`): a TIGHT port's waits give
//! the transport a turn between their looks, in the waiting module's own thread, and tell it
//! when they park; waits that park at once give none.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::task::Poll;

use imrs_ports::transport::{EndTransport as _, PortTransport as _, Pump};
use imrs_ports::{End, Port, PortSpec, ProcessType, usage};
use imrs_testkit::poll_once;

type Doubler = Port<u64, u64, usage::Receive>;

fn tight() -> Doubler {
    Doubler::new(PortSpec::new("DOUBLE", "DOUBLER").process_type(ProcessType::Tight))
}

/// Counts the turns and the parkings it is given.
#[derive(Default)]
struct Counted {
    turns: AtomicUsize,
    parkings: AtomicUsize,
}

/// The port's pump, counting into what the test reads.
struct Counting(Arc<Counted>);

impl Pump for Counting {
    fn pump(&self) {
        self.0.turns.fetch_add(1, Ordering::Relaxed);
    }

    fn parking(&self) {
        self.0.parkings.fetch_add(1, Ordering::Relaxed);
    }
}

#[test]
fn a_spinning_send_gives_the_transport_turns_then_says_it_parks() {
    let port = tight();
    let counted = Arc::new(Counted::default());
    port.pump_with(Counting(Arc::clone(&counted)));
    let _owner = port.owner().unwrap();
    let mut user = port.user_named("ASKER").unwrap();

    assert!(poll_once(user.send(1)).is_pending());
    assert!(counted.turns.load(Ordering::Relaxed) > 0);
    assert_eq!(counted.parkings.load(Ordering::Relaxed), 1);
}

#[test]
fn a_spinning_receive_gives_the_transport_turns_then_says_it_parks() {
    let port = tight();
    let counted = Arc::new(Counted::default());
    port.pump_with(Counting(Arc::clone(&counted)));
    let mut owner = port.owner().unwrap();

    assert!(poll_once(owner.receive()).is_pending());
    assert!(counted.turns.load(Ordering::Relaxed) > 0);
    assert_eq!(counted.parkings.load(Ordering::Relaxed), 1);
}

#[test]
fn waits_that_park_at_once_give_no_turn() {
    // An end the transport waits on itself parks, on a TIGHT port too.
    let port = tight();
    let counted = Arc::new(Counted::default());
    port.pump_with(Counting(Arc::clone(&counted)));
    let mut owner = port.owner().unwrap();
    owner.park_waits();
    let mut user = port.user_named("ASKER").unwrap();
    user.park_waits();
    assert!(poll_once(owner.receive()).is_pending());
    assert!(poll_once(user.send(1)).is_pending());

    // A port that is not TIGHT never spins.
    let loose = Doubler::new(PortSpec::new("LOOSE", "DOUBLER"));
    loose.pump_with(Counting(Arc::clone(&counted)));
    let mut owner = loose.owner().unwrap();
    assert!(poll_once(owner.receive()).is_pending());

    assert_eq!(counted.turns.load(Ordering::Relaxed), 0);
    assert_eq!(counted.parkings.load(Ordering::Relaxed), 0);
}

/// A transport that serves the port's owner side itself, in its turns: it doubles.
struct Serves(Mutex<End<u64, u64, usage::Receive>>);

impl Pump for Serves {
    fn pump(&self) {
        if let Ok(mut owner) = self.0.try_lock()
            && let Some((n, reply)) = owner.try_receive()
        {
            reply.reply(2 * n);
        }
    }

    fn parking(&self) {}
}

#[test]
fn a_transport_can_serve_a_spinning_send_in_the_senders_own_thread() {
    // Nothing else runs: no task serves the owner's side, only the sender's turns.
    let port = tight();
    let mut owner = port.owner().unwrap();
    owner.park_waits();
    port.pump_with(Serves(Mutex::new(owner)));
    let mut user = port.user_named("ASKER").unwrap();
    for n in 0..100 {
        // Answered within the send's first poll, before it would have parked.
        let doubled = poll_once(user.send(n));
        assert!(
            matches!(doubled, Poll::Ready(Ok(d)) if d == 2 * n),
            "{doubled:?}"
        );
    }
}
