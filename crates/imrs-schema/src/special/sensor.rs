//! `Jposition_i` and `Tactile_i`: the hand's joint positions and fingertip touch.

use imrs_sim::hand::Hand;

use super::{once_per_step, refused};
use crate::{Behavior, Cx, Declare, Flow, Schema, SchemaError, ports};

ports! {
    /// `[Jposition () (position)]`
    pub struct JpositionPorts {
        out position: f32 = "position",
    }
}

ports! {
    /// `[Tactile () (Contact)]`
    pub struct TactilePorts {
        out contact: bool = "Contact",
    }
}

/// `Jposition_i`: where joint `i` is, as the simulation measures it, once per step.
#[derive(Debug)]
pub struct Jposition {
    hand: Hand,
    joint: usize,
}

impl Jposition {
    /// A position sensor of `hand`; its instance number picks the joint.
    pub fn new(hand: &Hand) -> Self {
        Self {
            hand: hand.clone(),
            joint: 0,
        }
    }
}

impl Schema for Jposition {
    const NAME: &'static str = "Jposition";
    type Ports = JpositionPorts;

    fn set_up(&mut self, cx: &Cx) -> Result<Self::Ports, SchemaError> {
        self.joint = cx.number() as usize;
        self.hand.position(self.joint).map_err(refused(cx))?;
        Ok(Declare::declare(cx.me()))
    }

    async fn behavior(&mut self, ports: &JpositionPorts, _: &Cx) -> Behavior {
        let position = self.hand.position(self.joint).unwrap_or(f32::NAN);
        once_per_step(&self.hand, ports.position.write(position)).await?;
        Ok(Flow::Continue)
    }
}

/// `Tactile_i`: whether finger `i`'s tip touches something, from the simulation's
/// contacts, once per step.
#[derive(Debug)]
pub struct Tactile {
    hand: Hand,
    sensor: usize,
}

impl Tactile {
    /// A tactile sensor of `hand`; its instance number picks the fingertip.
    pub fn new(hand: &Hand) -> Self {
        Self {
            hand: hand.clone(),
            sensor: 0,
        }
    }
}

impl Schema for Tactile {
    const NAME: &'static str = "Tactile";
    type Ports = TactilePorts;

    fn set_up(&mut self, cx: &Cx) -> Result<Self::Ports, SchemaError> {
        self.sensor = cx.number() as usize;
        self.hand.touch(self.sensor).map_err(refused(cx))?;
        Ok(Declare::declare(cx.me()))
    }

    async fn behavior(&mut self, ports: &TactilePorts, _: &Cx) -> Behavior {
        let touching = matches!(self.hand.touch(self.sensor), Ok(Some(_)));
        once_per_step(&self.hand, ports.contact.write(touching)).await?;
        Ok(Flow::Continue)
    }
}
