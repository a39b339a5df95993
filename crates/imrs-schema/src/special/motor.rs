//! `Jmotor_i`: drives joint `i`.

use imrs_sim::hand::Hand;

use super::{once_per_step, refused};
use crate::race::{Either, race};
use crate::{Behavior, Cx, Declare, Flow, ReadError, Schema, SchemaError, ports};

ports! {
    /// `[Jmotor (desired) (actual)]`
    pub struct JmotorPorts {
        in desired: f32 = "desired",
        out actual: f32 = "actual",
    }
}

/// `Jmotor_i`: each value read on `desired` is its command for joint `i` (metres or
/// radians); the joint receives the mean of the commands of every live `Jmotor_i`, and
/// `actual` reports that mean. It takes at most one command per step of the hand.
/// Deinstantiating it withdraws its command.
#[derive(Debug)]
pub struct Jmotor {
    hand: Hand,
    joint: usize,
    source: u64,
}

impl Jmotor {
    /// A motor schema for `hand`; its instance number picks the joint.
    pub fn new(hand: &Hand) -> Self {
        Self {
            hand: hand.clone(),
            joint: 0,
            source: hand.source(),
        }
    }
}

impl Schema for Jmotor {
    const NAME: &'static str = "Jmotor";
    type Ports = JmotorPorts;

    fn set_up(&mut self, cx: &Cx) -> Result<Self::Ports, SchemaError> {
        self.joint = cx.number() as usize;
        self.hand.target(self.joint).map_err(refused(cx))?;
        Ok(Declare::declare(cx.me()))
    }

    async fn behavior(&mut self, ports: &JmotorPorts, cx: &Cx) -> Behavior {
        let actual = self.hand.target(self.joint).unwrap_or(f32::NAN);
        let reporting = once_per_step(&self.hand, ports.actual.write(actual));
        match race(ports.desired.read(), reporting).await {
            // Its commander is gone: it may be rewired; meanwhile the command stands.
            Either::Left(Err(ReadError::Disconnected { .. })) => self.hand.stepped().await,
            Either::Left(desired) => {
                let desired = desired?;
                self.hand
                    .command(self.joint, self.source, desired)
                    .map_err(refused(cx))?;
                // A command takes effect at the next step: one per step, so that a
                // commander that writes without pause cannot spin the network in place.
                self.hand.stepped().await;
            }
            Either::Right(reported) => reported?,
        }
        Ok(Flow::Continue)
    }
}

impl Drop for Jmotor {
    fn drop(&mut self) {
        // A joint number the hand refused was never commanded.
        let _ = self.hand.release(self.joint, self.source);
    }
}
