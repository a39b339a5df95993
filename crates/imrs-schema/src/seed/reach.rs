//! Example II: object parameterization of a motor command — reaching for an object whose
//! pose comes from its SEF.

use std::f32::consts::PI;

use imrs_sim::hand::Hand;
use nalgebra::{Point3, UnitQuaternion, Vector3};

use crate::special::{MoveWrist, OrientWrist, Sef};
use crate::{Behavior, Cx, Declare, Flow, Kind, Schema, SchemaError, ports};

ports! {
    /// `(Pn On) (Pt Ot)`
    pub struct RObjectPorts {
        in pn: Point3<f32> = "Pn",
        in on: UnitQuaternion<f32> = "On",
        out pt: Vector3<f32> = "Pt",
        out ot: Vector3<f32> = "Ot",
    }
}

/// `[RObject (Pn On) (Pt Ot) (handlength grotate) (Pt:=Pn-handlength Ot:=grotate-On)]`: the
/// object model of a reach, filtering an object's pose into the wrist's target.
///
/// The hand comes from above, so of the object's orientation only its yaw matters: `Ot` is
/// `grotate` plus the object's yaw, as (roll, pitch, yaw).
#[derive(Debug, Clone, Copy)]
pub struct RObject {
    /// `handlength`: subtracted from the object's position (a negative z puts the palm
    /// above the object).
    pub handlength: Vector3<f32>,
    /// `grotate`: the grasp's rotation, as (roll, pitch, yaw).
    pub grotate: Vector3<f32>,
}

impl Schema for RObject {
    const NAME: &'static str = "RObject";
    type Ports = RObjectPorts;

    fn set_up(&mut self, cx: &Cx) -> Result<RObjectPorts, SchemaError> {
        Ok(Declare::declare(cx.me()))
    }

    async fn behavior(&mut self, p: &RObjectPorts, _: &Cx) -> Behavior {
        let (position, orientation) = (p.pn.read().await?, p.on.read().await?);
        p.pt.write(position.coords - self.handlength).await?;
        let yaw = orientation.euler_angles().2;
        p.ot.write(self.grotate + Vector3::new(0.0, 0.0, yaw))
            .await?;
        Ok(Flow::Continue)
    }
}

ports! {
    /// `(MP MO OP OO) (Pos Ornt)`
    pub struct ReachPorts {
        in mp: Vector3<f32> = "MP",
        in mo: Vector3<f32> = "MO",
        in op: Vector3<f32> = "OP",
        in oo: Vector3<f32> = "OO",
        out pos: Vector3<f32> = "Pos",
        out ornt: Vector3<f32> = "Ornt",
    }
}

/// `Reach = [RObject - (MoveWrist, OrientWrist)]` (Figure 4): moves the wrist to the object
/// `SEF_k` stands for, by `Del` per pass, and stops once there.
///
/// The seed stops when `Ptemp = OP` and `Otemp = OO`; measured poses are never exactly
/// equal, so here "equal" is within [`Reach::AT`] and [`Reach::TURNED`].
#[derive(Debug)]
pub struct Reach {
    hand: Hand,
    /// `k`: the SEF to reach for.
    sef: u32,
    object: RObject,
    del: (f32, f32),
}

impl Reach {
    /// How close the wrist must come to its target position (m).
    pub const AT: f32 = 0.002;
    /// How close to its target orientation, on each angle (rad).
    pub const TURNED: f32 = 0.01;

    /// A reach for `SEF_sef`, the palm `above` the object's centre, moving at most 2 cm and
    /// 0.05 rad per pass.
    pub fn new(hand: &Hand, sef: u32, above: f32) -> Self {
        Self {
            hand: hand.clone(),
            sef,
            object: RObject {
                handlength: Vector3::new(0.0, 0.0, -above),
                grotate: Vector3::zeros(),
            },
            del: (0.02, 0.05),
        }
    }
}

/// `b - a`, each angle wrapped into (-π, π].
fn turn(a: Vector3<f32>, b: Vector3<f32>) -> Vector3<f32> {
    (b - a).map(|d| (d + PI).rem_euclid(2.0 * PI) - PI)
}

impl Schema for Reach {
    const NAME: &'static str = "Reach";
    const KIND: Kind = Kind::TaskUnit;
    type Ports = ReachPorts;

    fn set_up(&mut self, cx: &Cx) -> Result<ReachPorts, SchemaError> {
        let ports: ReachPorts = Declare::declare(cx.me());
        let sef = cx.get::<Sef>(self.sef).ok_or_else(|| SchemaError::Failed {
            instance: cx.me().clone(),
            reason: format!("there is no SEF_{} to reach for", self.sef),
        })?;
        let object = cx.instantiate(self.object)?;
        cx.connect(&sef.ports().f1, &object.ports().pn);
        cx.connect(&sef.ports().f2, &object.ports().on);
        cx.connect(&object.ports().pt, &ports.op);
        cx.connect(&object.ports().ot, &ports.oo);
        let moving = cx.instantiate(MoveWrist::new(&self.hand))?;
        cx.connect(&moving.ports().actual, &ports.mp);
        cx.connect(&ports.pos, &moving.ports().desired);
        let turning = cx.instantiate(OrientWrist::new(&self.hand))?;
        cx.connect(&turning.ports().actual, &ports.mo);
        cx.connect(&ports.ornt, &turning.ports().desired);
        Ok(ports)
    }

    async fn behavior(&mut self, p: &ReachPorts, _: &Cx) -> Behavior {
        let (ptemp, otemp) = (p.mp.read().await?, p.mo.read().await?);
        let (op, oo) = (p.op.read().await?, p.oo.read().await?);
        let (to_go, to_turn) = (op - ptemp, turn(otemp, oo));
        let there = to_go.norm() <= Self::AT;
        let turned = to_turn.amax() <= Self::TURNED;
        if !there {
            p.pos.write(ptemp + to_go.cap_magnitude(self.del.0)).await?;
        }
        if !turned {
            p.ornt
                .write(otemp + to_turn.map(|d| d.clamp(-self.del.1, self.del.1)))
                .await?;
        }
        Ok(if there && turned {
            Flow::Stop
        } else {
            Flow::Continue
        })
    }
}
