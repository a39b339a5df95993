//! The guarded move with port arrays, as the seed generalizes it (§5, after Grip): "the
//! task-unit generalizes easily to control any number of joints based on one sensor, or one
//! joint on any number of sensors".

use imrs_sim::hand::Hand;

use crate::special::{Joint, Tactile};
use crate::{
    AnyPort, Behavior, Cx, Flow, Input, Kind, Output, PortArray, Ports, Schema, SchemaError,
};

/// `(Tin_1 … Tin_n Pin_1 … Pin_m) (Pout_1 … Pout_m)`: `n` tactile inputs, and each of the
/// `m` joints' position and command.
#[derive(Debug, Clone)]
pub struct GuardedMovePorts {
    /// `Tin_1 … Tin_n`.
    pub tin: PortArray<Input<bool>>,
    /// `Pin_1 … Pin_m`.
    pub pin: PortArray<Input<f32>>,
    /// `Pout_1 … Pout_m`.
    pub pout: PortArray<Output<f32>>,
}

impl Ports for GuardedMovePorts {
    fn list(&self) -> Vec<(&'static str, &dyn AnyPort)> {
        self.tin
            .list()
            .chain(self.pin.list())
            .chain(self.pout.list())
            .collect()
    }
}

/// The guarded move over port arrays: while no fingertip of `sensors` touches, every joint
/// of `joints` moves on by `del` each pass (`Pout_k := Pin_k + Del`); once any touches, each
/// holds where it is (`Pout_k := Pin_k`). A task-unit whose sensing components are a
/// `Tactile` per sensor and whose motor components a `Joint` per joint, as `Closejoint`'s
/// are, but for `n` sensors and `m` joints.
#[derive(Debug)]
pub struct GuardedMove {
    hand: Hand,
    sensors: Vec<usize>,
    joints: Vec<usize>,
    del: f32,
}

impl GuardedMove {
    /// Moves `joints` of `hand` by `del` a pass until a fingertip of `sensors` touches.
    pub fn new(
        hand: &Hand,
        sensors: impl IntoIterator<Item = usize>,
        joints: impl IntoIterator<Item = usize>,
        del: f32,
    ) -> Self {
        Self {
            hand: hand.clone(),
            sensors: sensors.into_iter().collect(),
            joints: joints.into_iter().collect(),
            del,
        }
    }
}

impl Schema for GuardedMove {
    const NAME: &'static str = "GuardedMove";
    const KIND: Kind = Kind::TaskUnit;
    type Ports = GuardedMovePorts;

    fn set_up(&mut self, cx: &Cx) -> Result<GuardedMovePorts, SchemaError> {
        if self.sensors.is_empty() || self.joints.is_empty() {
            return Err(SchemaError::Failed {
                instance: cx.me().clone(),
                reason: format!(
                    "a guarded move needs a sensor and a joint; it has {} and {}",
                    self.sensors.len(),
                    self.joints.len()
                ),
            });
        }
        let me = cx.me();
        let number = |index: usize, what: &str| {
            u32::try_from(index).map_err(|_| SchemaError::Failed {
                instance: me.clone(),
                reason: format!("{what} {index} is no instance number"),
            })
        };
        let ports = GuardedMovePorts {
            tin: PortArray::inputs("Tin", self.sensors.len(), me),
            pin: PortArray::inputs("Pin", self.joints.len(), me),
            pout: PortArray::outputs("Pout", self.joints.len(), me),
        };
        for (k, &finger) in self.sensors.iter().enumerate() {
            let tactile = cx.instantiate_as(number(finger, "sensor")?, Tactile::new(&self.hand))?;
            let tin = ports.tin.get(k + 1).expect("one input per sensor");
            cx.connect(&tactile.ports().contact, tin);
        }
        for (k, &joint) in self.joints.iter().enumerate() {
            let joint = cx.instantiate_as(number(joint, "joint")?, Joint::new(&self.hand))?;
            let (pin, pout) = (ports.pin.get(k + 1), ports.pout.get(k + 1));
            cx.connect(
                &joint.ports().position,
                pin.expect("one position per joint"),
            );
            cx.connect(pout.expect("one command per joint"), &joint.ports().desired);
        }
        Ok(ports)
    }

    async fn behavior(&mut self, p: &GuardedMovePorts, _: &Cx) -> Behavior {
        let mut touching = false;
        for tin in p.tin.iter() {
            touching |= tin.read().await?;
        }
        for (pin, pout) in p.pin.iter().zip(p.pout.iter()) {
            let at = pin.read().await?;
            pout.write(if touching { at } else { at + self.del })
                .await?;
        }
        Ok(Flow::Continue)
    }
}
