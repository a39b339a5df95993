//! A bridge's turn in the thread of a module spinning on a TIGHT port.
//!
//! Raw iceoryx2 between two spinning processes is a round trip of a few microseconds: each
//! side looks at shared memory in a loop, and nobody is woken. A bridge of tokio tasks adds
//! to each crossing a task woken, a thread woken, and an event sent to the other process —
//! ten times the round trip itself. So on a TIGHT port the bridge's work is also done in the
//! spinning module's own thread ([`Pump`]): the user's send takes its request into shared
//! memory itself and reads the reply there; the owner's receive takes the request from
//! shared memory itself and sends the reply. The wake-up of the other process is held back
//! while it may be spinning too, and sent as soon as it may not be: when the message has
//! waited [`QUIET_TURNS`] turns, when the spinning wait parks, or when the bridge's task
//! runs. The tasks stay, woken for every wait that parks: on a TIGHT port the wake-ups
//! are the tasks' to serve, not the waking thread's ([`crate::dispatch`]), since that
//! thread is a spinning module's, whose own turns move the messages.

use std::sync::{Mutex, Weak};

use imrs_ports::transport::Pump;

use crate::carry::lock;

/// How many turns a message waits, unannounced, before the peer is woken: a few
/// microseconds, about a round trip. The owner's side waits for the user to take its reply;
/// the user's side, which cannot see the owner take a request, waits for the reply, so a
/// round trip a little longer than usual wakes the owner all the same. Measured on two cores
/// (see the README), three runs each: with 32 turns the round trip's p99 was 3.6–4.5 µs,
/// with 256 it was 3.5–4.5 µs: no clear difference. With no wake-up until the wait parks,
/// a peer that had parked waited out the whole spin, and the p99 was 14 µs–1.3 ms.
pub(crate) const QUIET_TURNS: u32 = 32;

/// One side of a bridge, as a spinning module's turn sees it.
pub(crate) trait Turns: Send + 'static {
    /// Moves what has arrived, either way, holding back the wake-ups of the other process.
    fn turn(&mut self);
    /// Sends the wake-ups held back.
    fn announce(&mut self);
}

/// The pump of a bridge side: a turn, skipped while the bridge is at work elsewhere. The port
/// holds its pump, and the bridge holds the port's ends: the pump holds the bridge weakly,
/// so that the bridge still goes when its task ends.
pub(crate) struct Turn<S: ?Sized>(pub(crate) Weak<Mutex<S>>);

impl<S: Turns + ?Sized> Pump for Turn<S> {
    fn pump(&self) {
        let Some(side) = self.0.upgrade() else {
            return;
        };
        // Busy: the task is moving the messages now; the next turn looks again.
        if let Ok(mut side) = side.try_lock() {
            side.turn();
        }
    }

    fn parking(&self) {
        if let Some(side) = self.0.upgrade() {
            lock(&side).announce();
        }
    }
}

/// Wake-ups held back from a peer that may be spinning, and the turns since the first.
#[derive(Debug, Default)]
pub(crate) struct Quiet {
    turns: Option<u32>,
}

impl Quiet {
    /// A message went without its wake-up.
    pub(crate) fn hold(&mut self) {
        self.turns.get_or_insert(0);
    }

    /// A turn passed with `waiting` messages not yet taken by the peer: whether to wake it
    /// now, its held-back messages having waited long enough.
    pub(crate) fn turn(&mut self, waiting: bool) -> bool {
        let Some(turns) = &mut self.turns else {
            return false;
        };
        if !waiting {
            self.turns = None;
            return false;
        }
        *turns += 1;
        *turns > QUIET_TURNS
    }

    /// Whether a wake-up is held back; forgets it, as the caller sends it now.
    pub(crate) fn take(&mut self) -> bool {
        self.turns.take().is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_held_wake_up_goes_after_its_quiet_turns_unless_the_peer_took_the_message() {
        let mut quiet = Quiet::default();
        assert!(!quiet.turn(true), "nothing held, nothing to announce");
        quiet.hold();
        for _ in 0..QUIET_TURNS {
            assert!(!quiet.turn(true));
        }
        assert!(quiet.turn(true), "the peer did not take it: wake it");
        assert!(quiet.take());
        assert!(!quiet.take(), "announced once");

        quiet.hold();
        assert!(!quiet.turn(false), "taken: nothing to announce");
        assert!(!quiet.take());
    }
}
