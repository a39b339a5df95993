//! `MoveWrist` and `OrientWrist`: the wrist's position and orientation as vectors.

use imrs_sim::hand::Hand;
use nalgebra::Vector3;

use super::{Joint, once_per_step};
use crate::{
    AnyPort, Behavior, Cx, Declare, Flow, Input, Kind, Output, Ports, Schema, SchemaError, ports,
};

/// The ports of [`MoveWrist`] and [`OrientWrist`].
#[derive(Debug, Clone)]
pub struct WristPorts {
    /// Where the wrist should be: x, y, z (m), or roll, pitch, yaw (rad).
    pub desired: Input<Vector3<f32>>,
    /// Where it is, as its joints measure it.
    pub actual: Output<Vector3<f32>>,
}

impl Ports for WristPorts {
    fn list(&self) -> Vec<(&'static str, &dyn AnyPort)> {
        vec![("desired", &self.desired), ("actual", &self.actual)]
    }
}

/// `MoveWrist`: the assemblage of the `Joint` SIs that place the wrist (joints 1 to 3).
#[derive(Debug)]
pub struct MoveWrist {
    hand: Hand,
}

/// `OrientWrist`: the assemblage of the `Joint` SIs that turn the wrist (joints 4 to 6).
#[derive(Debug)]
pub struct OrientWrist {
    hand: Hand,
}

impl MoveWrist {
    /// The wrist's position, for `hand`.
    pub fn new(hand: &Hand) -> Self {
        Self { hand: hand.clone() }
    }
}

impl OrientWrist {
    /// The wrist's orientation, for `hand`.
    pub fn new(hand: &Hand) -> Self {
        Self { hand: hand.clone() }
    }
}

impl Schema for MoveWrist {
    const NAME: &'static str = "MoveWrist";
    const KIND: Kind = Kind::Assemblage;
    type Ports = WristPorts;

    fn set_up(&mut self, cx: &Cx) -> Result<WristPorts, SchemaError> {
        three_joints(cx, &self.hand, 1)
    }
}

impl Schema for OrientWrist {
    const NAME: &'static str = "OrientWrist";
    const KIND: Kind = Kind::Assemblage;
    type Ports = WristPorts;

    fn set_up(&mut self, cx: &Cx) -> Result<WristPorts, SchemaError> {
        three_joints(cx, &self.hand, 4)
    }
}

/// Joints `first` to `first + 2`, a `Split` that hands each its coordinate and a `Gather`
/// that puts their positions back together.
fn three_joints(cx: &Cx, hand: &Hand, first: u32) -> Result<WristPorts, SchemaError> {
    let split = cx.instantiate(Split)?;
    let gather = cx.instantiate(Gather { hand: hand.clone() })?;
    let outs = [&split.ports().x, &split.ports().y, &split.ports().z];
    let ins = [&gather.ports().x, &gather.ports().y, &gather.ports().z];
    for (k, (out, input)) in outs.into_iter().zip(ins).enumerate() {
        let joint = cx.instantiate_as(first + k as u32, Joint::new(hand))?;
        cx.connect(out, &joint.ports().desired);
        cx.connect(&joint.ports().position, input);
    }
    Ok(WristPorts {
        desired: split.ports().desired.clone(),
        actual: gather.ports().actual.clone(),
    })
}

ports! {
    /// A vector in, its three coordinates out.
    pub struct SplitPorts {
        in desired: Vector3<f32> = "desired",
        out x: f32 = "x",
        out y: f32 = "y",
        out z: f32 = "z",
    }
}

ports! {
    /// Three coordinates in, a vector out.
    pub struct GatherPorts {
        in x: f32 = "x",
        in y: f32 = "y",
        in z: f32 = "z",
        out actual: Vector3<f32> = "actual",
    }
}

/// Hands each coordinate of a vector to its joint.
#[derive(Debug)]
pub struct Split;

impl Schema for Split {
    const NAME: &'static str = "Split";
    type Ports = SplitPorts;

    fn set_up(&mut self, cx: &Cx) -> Result<SplitPorts, SchemaError> {
        Ok(Declare::declare(cx.me()))
    }

    async fn behavior(&mut self, p: &SplitPorts, _: &Cx) -> Behavior {
        let v = p.desired.read().await?;
        p.x.write(v.x).await?;
        p.y.write(v.y).await?;
        p.z.write(v.z).await?;
        Ok(Flow::Continue)
    }
}

/// Puts three joints' positions together as a vector, once per step of the hand.
#[derive(Debug)]
pub struct Gather {
    hand: Hand,
}

impl Schema for Gather {
    const NAME: &'static str = "Gather";
    type Ports = GatherPorts;

    fn set_up(&mut self, cx: &Cx) -> Result<GatherPorts, SchemaError> {
        Ok(Declare::declare(cx.me()))
    }

    async fn behavior(&mut self, p: &GatherPorts, _: &Cx) -> Behavior {
        let v = Vector3::new(p.x.read().await?, p.y.read().await?, p.z.read().await?);
        once_per_step(&self.hand, p.actual.write(v)).await?;
        Ok(Flow::Continue)
    }
}
