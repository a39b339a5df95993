//! Example III: a parallel search over every SEF, triggering a task-unit on the match.

use std::sync::Arc;

use imrs_sim::hand::Shape;
use nalgebra::{Point3, UnitQuaternion};

use crate::special::{Sef, SefPorts, Vision};
use crate::{Behavior, Cx, Declare, Flow, Schema, SchemaError, ports};

/// `DF1 … DF4`: the features of the object sought. Position and orientation may be anything;
/// the shape must be the same and the size within `tolerance`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Desired {
    /// `DF3`.
    pub shape: Shape,
    /// `DF4`.
    pub size: f32,
    /// How far the size may be off.
    pub tolerance: f32,
}

ports! {
    /// `(F1 … F4) (judgement)`
    pub struct ObjtestPorts {
        in f1: Point3<f32> = "F1",
        in f2: UnitQuaternion<f32> = "F2",
        in f3: Shape = "F3",
        in f4: f32 = "F4",
        out judgement: u32 = "judgement",
    }
}

/// `Objtest_i`: tests `SEF_i`'s features against the desired ones once, writes its
/// judgement and stops. The judgement is `i` on a match (the seed writes 1; the number
/// tells `Object?` which SEF matched, for the task-unit it triggers) and 0 otherwise.
#[derive(Debug, Clone, Copy)]
pub struct Objtest {
    /// `DF1 … DF4`.
    pub desired: Desired,
}

impl Schema for Objtest {
    const NAME: &'static str = "Objtest";
    type Ports = ObjtestPorts;

    fn set_up(&mut self, cx: &Cx) -> Result<ObjtestPorts, SchemaError> {
        Ok(Declare::declare(cx.me()))
    }

    async fn behavior(&mut self, p: &ObjtestPorts, cx: &Cx) -> Behavior {
        let matches = judge(&self.desired, p).await?;
        p.judgement
            .write(if matches { cx.number() } else { 0 })
            .await?;
        Ok(Flow::Stop)
    }
}

ports! {
    /// `(result) ()`
    pub struct ObjectQPorts {
        in result: u32 = "result",
    }
}

/// What `Object?` starts on a match: `Tj`, given the number of the matching SEF.
type Trigger = Box<dyn FnMut(&Cx, u32) -> Result<(), SchemaError> + Send>;

/// `Object?`: `FORALL SEF_i DO Objtest_i …` — one `Objtest` per SEF, all searching in
/// parallel, their judgements fanned in on `result`; on a match it starts `Tj` for the
/// matching SEF and stops. It numbers each `Objtest` after its SEF, so that it never runs
/// two tests of one SEF at once.
pub struct ObjectQ {
    desired: Desired,
    trigger: Trigger,
}

impl std::fmt::Debug for ObjectQ {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ObjectQ")
            .field("desired", &self.desired)
            .finish_non_exhaustive()
    }
}

impl ObjectQ {
    /// A search for `desired`, starting `trigger(cx, k)` when `SEF_k` matches.
    pub fn new(
        desired: Desired,
        trigger: impl FnMut(&Cx, u32) -> Result<(), SchemaError> + Send + 'static,
    ) -> Self {
        Self {
            desired,
            trigger: Box::new(trigger),
        }
    }
}

impl Schema for ObjectQ {
    const NAME: &'static str = "Object?";
    type Ports = ObjectQPorts;

    fn set_up(&mut self, cx: &Cx) -> Result<ObjectQPorts, SchemaError> {
        Ok(Declare::declare(cx.me()))
    }

    async fn behavior(&mut self, p: &ObjectQPorts, cx: &Cx) -> Behavior {
        let sefs = cx.forall::<Sef>();
        if sefs.is_empty() {
            cx.delay(Vision::FRAME).await;
            return Ok(Flow::Continue);
        }
        for sef in &sefs {
            let test = match cx.instantiate_as(
                sef.number(),
                Objtest {
                    desired: self.desired,
                },
            ) {
                Ok(test) => test,
                Err(SchemaError::InstanceExists { .. }) => continue,
                Err(error) => return Err(error),
            };
            connect_sef(cx, sef.ports(), test.ports());
            cx.connect(&test.ports().judgement, &p.result);
        }
        let matched = match p.result.read().await {
            Ok(matched) => matched,
            // Every test has ended and its judgement was read: test again.
            Err(crate::ReadError::Disconnected { .. }) => return Ok(Flow::Continue),
            Err(error) => return Err(error.into()),
        };
        if matched == 0 {
            return Ok(Flow::Continue);
        }
        cx.forall::<Objtest>().iter().for_each(|test| test.stop());
        (self.trigger)(cx, matched)?;
        Ok(Flow::Stop)
    }
}

/// What an [`ObjtestTrigger`] does on a match: instantiates the task-unit `T` for the SEF
/// numbered, in the test's own context.
pub type Starter = Arc<dyn Fn(&Cx, u32) -> Result<(), SchemaError> + Send + Sync>;

/// The second precondition's `Objtest` (Lyons & Arbib 1985, §5, after Figure 5): tests
/// the SEF it is connected to once; if it fails the test it dies, otherwise it creates the
/// task-unit, connected to that SEF (the starter is given the SEF's number), and dies.
#[derive(Clone)]
pub struct ObjtestTrigger {
    /// The object looked for.
    pub desired: Desired,
    start: Starter,
}

impl std::fmt::Debug for ObjtestTrigger {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ObjtestTrigger")
            .field("desired", &self.desired)
            .finish_non_exhaustive()
    }
}

impl Schema for ObjtestTrigger {
    const NAME: &'static str = "Objtest";
    type Ports = ObjtestPorts;

    fn set_up(&mut self, cx: &Cx) -> Result<ObjtestPorts, SchemaError> {
        Ok(Declare::declare(cx.me()))
    }

    async fn behavior(&mut self, p: &ObjtestPorts, cx: &Cx) -> Behavior {
        if judge(&self.desired, p).await? {
            (self.start)(cx, cx.number())?;
        }
        Ok(Flow::Stop)
    }
}

/// The second precondition (Lyons & Arbib 1985, §5, after Figure 5): waits until some
/// SEF exists, then creates one [`ObjtestTrigger`] for each SEF, connected to it, and
/// dies. The test that matches starts the task-unit, connected to the SEF that triggered
/// it; the others die.
#[derive(Clone)]
pub struct ObjectQOnce {
    desired: Desired,
    start: Starter,
}

impl std::fmt::Debug for ObjectQOnce {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ObjectQOnce")
            .field("desired", &self.desired)
            .finish_non_exhaustive()
    }
}

impl ObjectQOnce {
    /// Looks for `desired`; `start` instantiates the task-unit for the SEF numbered.
    pub fn new(
        desired: Desired,
        start: impl Fn(&Cx, u32) -> Result<(), SchemaError> + Send + Sync + 'static,
    ) -> Self {
        Self {
            desired,
            start: Arc::new(start),
        }
    }
}

impl Schema for ObjectQOnce {
    const NAME: &'static str = "Object?";
    type Ports = ();

    fn set_up(&mut self, _: &Cx) -> Result<(), SchemaError> {
        Ok(())
    }

    async fn behavior(&mut self, _: &(), cx: &Cx) -> Behavior {
        let sefs = cx.forall::<Sef>();
        if sefs.is_empty() {
            cx.delay(Vision::FRAME).await;
            return Ok(Flow::Continue);
        }
        for sef in &sefs {
            let test = match cx.instantiate_as(
                sef.number(),
                ObjtestTrigger {
                    desired: self.desired,
                    start: Arc::clone(&self.start),
                },
            ) {
                Ok(test) => test,
                // A test of this SEF runs already (another precondition's): it judges it.
                Err(SchemaError::InstanceExists { .. }) => continue,
                Err(error) => return Err(error),
            };
            connect_sef(cx, sef.ports(), test.ports());
        }
        Ok(Flow::Stop)
    }
}

/// Whether the features an `Objtest` reads from its SEF describe `desired`.
async fn judge(desired: &Desired, p: &ObjtestPorts) -> Result<bool, SchemaError> {
    let (_, _) = (p.f1.read().await?, p.f2.read().await?);
    let (shape, size) = (p.f3.read().await?, p.f4.read().await?);
    Ok(shape == desired.shape && (size - desired.size).abs() <= desired.tolerance)
}

/// `Objtest(F1 … F4) ← SEF_i(F1 … F4)`.
fn connect_sef(cx: &Cx, from: &SefPorts, to: &ObjtestPorts) {
    cx.connect(&from.f1, &to.f1);
    cx.connect(&from.f2, &to.f2);
    cx.connect(&from.f3, &to.f3);
    cx.connect(&from.f4, &to.f4);
}
