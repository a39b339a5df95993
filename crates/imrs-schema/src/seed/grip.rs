//! Example I: the guarded move, for n sensors and m limbs.

use imrs_sim::hand::{Hand, finger_of};

use crate::special::{Jmotor, Jposition, Tactile};
use crate::{Behavior, Cx, Declare, Flow, Kind, Schema, SchemaError, ports};

ports! {
    /// `(Tin Pin) (Pout)`
    pub struct TClosejointPorts {
        in tin: bool = "Tin",
        in pin: f32 = "Pin",
        out pout: f32 = "Pout",
    }
}

/// `[TClosejoint (Tin Pin) (Pout) (Del) (IF Tin=0 THEN Pout:=Pin+Del ELSE Pout:=Pin ENDIF)]`:
/// moves a joint on by `del` each pass until the tactile input is set, then holds it.
#[derive(Debug, Clone, Copy)]
pub struct TClosejoint {
    /// `Del`: the step, in radians.
    pub del: f32,
}

impl TClosejoint {
    /// One pass: the seed's IF.
    pub(crate) async fn pass(&self, p: &TClosejointPorts) -> Behavior {
        let touching = p.tin.read().await?;
        let at = p.pin.read().await?;
        p.pout
            .write(if touching { at } else { at + self.del })
            .await?;
        Ok(Flow::Continue)
    }
}

impl Schema for TClosejoint {
    const NAME: &'static str = "TClosejoint";
    type Ports = TClosejointPorts;

    fn set_up(&mut self, cx: &Cx) -> Result<Self::Ports, SchemaError> {
        Ok(Declare::declare(cx.me()))
    }

    async fn behavior(&mut self, p: &TClosejointPorts, _: &Cx) -> Behavior {
        self.pass(p).await
    }
}

/// The `Closejoint_i` task-unit: sensing `Tactile` (the tip of joint `i`'s finger) and
/// `Jposition_i`, motor `Jmotor_i`, linked by [`TClosejoint`]. Its instance number is the
/// joint. As long as it exists, the guarded move goes on.
#[derive(Debug)]
pub struct Closejoint {
    hand: Hand,
    link: TClosejoint,
}

impl Closejoint {
    /// `Closejoint(i, del)`: `i` is the instance number.
    pub fn new(hand: &Hand, del: f32) -> Self {
        Self {
            hand: hand.clone(),
            link: TClosejoint { del },
        }
    }
}

impl Schema for Closejoint {
    const NAME: &'static str = "Closejoint";
    const KIND: Kind = Kind::TaskUnit;
    type Ports = TClosejointPorts;

    fn set_up(&mut self, cx: &Cx) -> Result<TClosejointPorts, SchemaError> {
        let joint = cx.number();
        let finger = finger_of(joint as usize).ok_or_else(|| SchemaError::Failed {
            instance: cx.me().clone(),
            reason: format!("joint {joint} is not a finger joint"),
        })?;
        let ports: TClosejointPorts = Declare::declare(cx.me());
        let tactile = cx.instantiate_as(finger as u32, Tactile::new(&self.hand))?;
        let position = cx.instantiate_as(joint, Jposition::new(&self.hand))?;
        let motor = cx.instantiate_as(joint, Jmotor::new(&self.hand))?;
        cx.connect(&tactile.ports().contact, &ports.tin);
        cx.connect(&position.ports().position, &ports.pin);
        cx.connect(&ports.pout, &motor.ports().desired);
        Ok(ports)
    }

    async fn behavior(&mut self, p: &TClosejointPorts, _: &Cx) -> Behavior {
        self.link.pass(p).await
    }
}

/// `[Grip () () (Closejoint) (FOR i = 1…n DO Closejoint(i, del) ENDFOR) () ()]`: one
/// `Closejoint` per joint, as one assemblage, so that all are scheduled alike.
#[derive(Debug)]
pub struct Grip {
    hand: Hand,
    joints: Vec<u32>,
    del: f32,
}

impl Grip {
    /// A grip of the finger joints `joints`, each closing by `del` per pass.
    pub fn new(hand: &Hand, joints: impl IntoIterator<Item = usize>, del: f32) -> Self {
        Self {
            hand: hand.clone(),
            joints: joints.into_iter().map(|j| j as u32).collect(),
            del,
        }
    }
}

impl Schema for Grip {
    const NAME: &'static str = "Grip";
    const KIND: Kind = Kind::Assemblage;
    type Ports = ();

    fn set_up(&mut self, cx: &Cx) -> Result<(), SchemaError> {
        for &i in &self.joints {
            cx.instantiate_as(i, Closejoint::new(&self.hand, self.del))?;
        }
        Ok(())
    }
}
