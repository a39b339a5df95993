//! The special schemas of Lyons & Arbib 1985, §4.3, bound to the simulated hand of
//! [`imrs_sim::hand`]: the mechanism's joints and senses, seen as schemas.
//!
//! | seed | here | ports |
//! |---|---|---|
//! | `Jmotor_i` | [`Jmotor`], instance `i` drives joint `i` | `desired` in, `actual` out (the mean of every live `Jmotor_i`'s command, which is what the joint receives) |
//! | `Jposition_i` | [`Jposition`] | `position` out |
//! | `Tactile_i` | [`Tactile`], sensor `i` at finger `i`'s tip | `Contact` out |
//! | `SEF_i` | [`Sef`], made by [`Vision`] | `F1` position, `F2` orientation, `F3` shape, `F4` size, out |
//! | `Joint_i = [Jposition_i - Jmotor_i]` | [`Joint`] | `desired` in, `position` out |
//! | `MoveWrist`, `OrientWrist` | [`MoveWrist`], [`OrientWrist`] | `desired` in, `actual` out, as vectors |
//!
//! A sensor writes one fresh reading per step of the hand's world: a reading nobody took
//! before the next step is withdrawn and replaced, so a reader never sees a stale one, and
//! a behaviour that reads a sensor runs at most once per step.

mod feature;
mod joint;
mod motor;
mod sensor;
mod vision;
mod wrist;

pub use feature::{Feature, FeaturePorts, Sef, SefPorts};
pub use joint::{Joint, JointPorts};
pub use motor::{Jmotor, JmotorPorts};
pub use sensor::{Jposition, JpositionPorts, Tactile, TactilePorts};
pub use vision::Vision;
pub use wrist::{Gather, GatherPorts, MoveWrist, OrientWrist, Split, SplitPorts, WristPorts};

use imrs_ports::synchronous::Write;
use imrs_sim::hand::{Hand, HandError};

use crate::race::{Either, race};
use crate::{Cx, SchemaError, WriteError};

/// Turns the hand's refusal of a number into the error of the instance `cx` belongs to.
pub(crate) fn refused(cx: &Cx) -> impl FnOnce(HandError) -> SchemaError + '_ {
    |error| SchemaError::Hand {
        instance: cx.me().clone(),
        error,
    }
}

/// Writes one reading, fresh at this step; gives up at the next step if nobody took it,
/// and otherwise waits for the next step, so that a reading is written once per step.
///
/// Readers come and go as the network is rewired: with none connected, or all of them
/// gone, the reading is simply not taken, and the sensor goes on.
pub(crate) async fn once_per_step<T>(hand: &Hand, write: Write<'_, T>) -> Result<(), SchemaError>
where
    T: Clone,
{
    let mut next = std::pin::pin!(hand.stepped());
    next.as_mut().enable();
    match race(next.as_mut(), write).await {
        Either::Left(()) => Ok(()),
        Either::Right(Ok(())) => {
            next.await;
            Ok(())
        }
        Either::Right(Err(WriteError::Disconnected { .. })) => {
            next.await;
            Ok(())
        }
        Either::Right(Err(error)) => Err(error.into()),
    }
}
