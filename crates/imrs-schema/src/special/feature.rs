//! `SEF_i`: a separable environmental facet, an assemblage of one feature SI per feature.

use std::sync::{Arc, Mutex, PoisonError};

use imrs_sim::hand::{Detection, Hand, Shape};
use nalgebra::{Point3, UnitQuaternion};

use super::once_per_step;
use crate::{AnyPort, Behavior, Cx, Declare, Flow, Kind, Name, Output, Ports, Schema, SchemaError};

/// What the vision interface last saw of one object; `None` once it is lost.
pub(crate) type Seen = Arc<Mutex<Option<Detection>>>;

pub(crate) fn last_seen(seen: &Seen) -> Option<Detection> {
    *seen.lock().unwrap_or_else(PoisonError::into_inner)
}

/// A feature SI: measures one feature of one object, once per step.
pub struct Feature<T> {
    hand: Hand,
    seen: Seen,
    measure: fn(&Detection) -> T,
}

impl<T> std::fmt::Debug for Feature<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Feature")
    }
}

/// A feature SI's one port.
#[derive(Debug, Clone)]
pub struct FeaturePorts<T> {
    /// The feature's value.
    pub value: Output<T>,
}

impl<T: Clone + Send + Sync + 'static> Ports for FeaturePorts<T> {
    fn list(&self) -> Vec<(&'static str, &dyn AnyPort)> {
        vec![("value", &self.value)]
    }
}

impl<T: Clone + Send + Sync + 'static> Declare for FeaturePorts<T> {
    fn declare(owner: &Name) -> Self {
        Self {
            value: Output::new("value", owner.clone()),
        }
    }
}

impl<T: Clone + Send + Sync + 'static> Schema for Feature<T> {
    const NAME: &'static str = "Feature";
    type Ports = FeaturePorts<T>;

    fn set_up(&mut self, cx: &Cx) -> Result<Self::Ports, SchemaError> {
        Ok(Declare::declare(cx.me()))
    }

    async fn behavior(&mut self, ports: &FeaturePorts<T>, _: &Cx) -> Behavior {
        let Some(seen) = last_seen(&self.seen) else {
            return Ok(Flow::Stop);
        };
        let value = (self.measure)(&seen);
        once_per_step(&self.hand, ports.value.write(value)).await?;
        Ok(Flow::Continue)
    }
}

/// `[SEF () (F1 F2 F3 F4)]`: position, orientation, shape and size of one separable object.
///
/// Instances are made by the [`Vision`](super::Vision) interface, one per object it tells
/// apart, and `SEF_i` always stands for the same object (visual continuity). `FORALL SEF`
/// finds them from inside any assemblage.
#[derive(Debug)]
pub struct Sef {
    hand: Hand,
    seen: Seen,
}

impl Sef {
    pub(crate) fn new(hand: &Hand, seen: Seen) -> Self {
        Self {
            hand: hand.clone(),
            seen,
        }
    }
}

/// `F1 … F4`: the features' ports, equivalent to the feature SIs' own.
#[derive(Debug, Clone)]
pub struct SefPorts {
    /// `F1`: where the object's centre is.
    pub f1: Output<Point3<f32>>,
    /// `F2`: how it is turned.
    pub f2: Output<UnitQuaternion<f32>>,
    /// `F3`: its shape.
    pub f3: Output<Shape>,
    /// `F4`: its size.
    pub f4: Output<f32>,
}

impl Ports for SefPorts {
    fn list(&self) -> Vec<(&'static str, &dyn AnyPort)> {
        vec![
            ("F1", &self.f1),
            ("F2", &self.f2),
            ("F3", &self.f3),
            ("F4", &self.f4),
        ]
    }
}

impl Schema for Sef {
    const NAME: &'static str = "SEF";
    const KIND: Kind = Kind::Assemblage;
    const EVERYWHERE: bool = true;
    type Ports = SefPorts;

    fn set_up(&mut self, cx: &Cx) -> Result<SefPorts, SchemaError> {
        let feature = |n: u32| (n, self.hand.clone(), Arc::clone(&self.seen));
        let (n, hand, seen) = feature(1);
        let f1 = cx.instantiate_as(
            n,
            Feature {
                hand,
                seen,
                measure: |d| d.position,
            },
        )?;
        let (n, hand, seen) = feature(2);
        let f2 = cx.instantiate_as(
            n,
            Feature {
                hand,
                seen,
                measure: |d| d.orientation,
            },
        )?;
        let (n, hand, seen) = feature(3);
        let f3 = cx.instantiate_as(
            n,
            Feature {
                hand,
                seen,
                measure: |d| d.shape,
            },
        )?;
        let (n, hand, seen) = feature(4);
        let f4 = cx.instantiate_as(
            n,
            Feature {
                hand,
                seen,
                measure: |d| d.size,
            },
        )?;
        Ok(SefPorts {
            f1: f1.ports().value.clone(),
            f2: f2.ports().value.clone(),
            f3: f3.ports().value.clone(),
            f4: f4.ports().value.clone(),
        })
    }
}
