//! `Joint_i = [Jposition_i - Jmotor_i]`: a joint as one unit, sensing and motor.

use imrs_sim::hand::Hand;

use super::{Jmotor, Jposition};
use crate::{AnyPort, Cx, Input, Kind, Output, Ports, Schema, SchemaError};

/// `Joint_i = [Jposition_i - Jmotor_i]` (Lyons & Arbib 1985 (7)): a task-unit whose linking process
/// is left implicit, so an assemblage of `Jposition_i` and `Jmotor_i` whose ports are theirs.
#[derive(Debug)]
pub struct Joint {
    hand: Hand,
}

impl Joint {
    /// Joint `i` of `hand`, `i` its instance number.
    pub fn new(hand: &Hand) -> Self {
        Self { hand: hand.clone() }
    }
}

/// `desired ≡ Jmotor_i(desired)`, `position ≡ Jposition_i(position)`.
#[derive(Debug, Clone)]
pub struct JointPorts {
    /// The joint's command.
    pub desired: Input<f32>,
    /// Where the joint is.
    pub position: Output<f32>,
}

impl Ports for JointPorts {
    fn list(&self) -> Vec<(&'static str, &dyn AnyPort)> {
        vec![("desired", &self.desired), ("position", &self.position)]
    }
}

impl Schema for Joint {
    const NAME: &'static str = "Joint";
    const KIND: Kind = Kind::Assemblage;
    type Ports = JointPorts;

    fn set_up(&mut self, cx: &Cx) -> Result<JointPorts, SchemaError> {
        let i = cx.number();
        let sensing = cx.instantiate_as(i, Jposition::new(&self.hand))?;
        let motor = cx.instantiate_as(i, Jmotor::new(&self.hand))?;
        Ok(JointPorts {
            desired: motor.ports().desired.clone(),
            position: sensing.ports().position.clone(),
        })
    }
}
