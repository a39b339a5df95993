//! Example III: a parallel search over every SEF, triggering a task-unit on the match.

use std::sync::Arc;

use imrs_sim::hand::Shape;
use nalgebra::{Point3, UnitQuaternion};

use crate::special::{Sef, SefPorts, Vision};
use crate::{Behavior, Cx, Declare, Flow, Schema, SchemaError, ports};

/// The features `F1 … F4` a SEF gives of its object.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Features {
    /// `F1`: where it is.
    pub position: Point3<f32>,
    /// `F2`: how it is turned.
    pub orientation: UnitQuaternion<f32>,
    /// `F3`: its shape.
    pub shape: Shape,
    /// `F4`: its size.
    pub size: f32,
}

/// `Objtest`'s test of a SEF's features against the object sought (`DF1 … DF4`).
///
/// [`Desired`] is the seed's test. A recognizer of one's own (a model matched against a
/// point cloud) takes its place; it may take long. Each `Objtest` runs its test on a
/// thread of tokio's blocking pool, so the tests of every SEF run at once.
pub trait Judge: Clone + Send + Sync + 'static {
    /// Whether `features` describe the object sought.
    fn judge(&self, features: &Features) -> bool;
}

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

impl Judge for Desired {
    fn judge(&self, features: &Features) -> bool {
        features.shape == self.shape && (features.size - self.size).abs() <= self.tolerance
    }
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
pub struct Objtest<J = Desired> {
    /// `DF1 … DF4`, and the test against them.
    pub desired: J,
}

impl<J: Judge> Schema for Objtest<J> {
    const NAME: &'static str = "Objtest";
    type Ports = ObjtestPorts;

    fn set_up(&mut self, cx: &Cx) -> Result<ObjtestPorts, SchemaError> {
        Ok(Declare::declare(cx.me()))
    }

    async fn behavior(&mut self, p: &ObjtestPorts, cx: &Cx) -> Behavior {
        let matches = judge(&self.desired, p, cx).await?;
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
/// matching SEF and stops. It numbers each `Objtest` after its SEF, so that no two live
/// tests are of one SEF (the judge of a test stopped mid-judge still finishes on its
/// thread).
pub struct ObjectQ<J = Desired> {
    desired: J,
    trigger: Trigger,
}

impl<J: std::fmt::Debug> std::fmt::Debug for ObjectQ<J> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ObjectQ")
            .field("desired", &self.desired)
            .finish_non_exhaustive()
    }
}

impl<J: Judge> ObjectQ<J> {
    /// A search for what `desired` accepts, starting `trigger(cx, k)` when `SEF_k` matches.
    pub fn new(
        desired: J,
        trigger: impl FnMut(&Cx, u32) -> Result<(), SchemaError> + Send + 'static,
    ) -> Self {
        Self {
            desired,
            trigger: Box::new(trigger),
        }
    }
}

impl<J: Judge> Schema for ObjectQ<J> {
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
                    desired: self.desired.clone(),
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
        cx.forall::<Objtest<J>>()
            .iter()
            .for_each(|test| test.stop());
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
        if judge(&self.desired, p, cx).await? {
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

/// Whether the features an `Objtest` reads from its SEF pass `desired`'s test.
///
/// The test runs on tokio's blocking pool, a thread of its own, so that the tests of every
/// SEF run at once however long each takes, while the processor goes on with the other
/// instances. On a paused runtime the clock stands still until it is done; a test stopped
/// meanwhile drops the handle, and the judge still runs to its end.
async fn judge<J: Judge>(desired: &J, p: &ObjtestPorts, cx: &Cx) -> Result<bool, SchemaError> {
    let features = Features {
        position: p.f1.read().await?,
        orientation: p.f2.read().await?,
        shape: p.f3.read().await?,
        size: p.f4.read().await?,
    };
    let desired = desired.clone();
    tokio::task::spawn_blocking(move || desired.judge(&features))
        .await
        .map_err(|error| SchemaError::Failed {
            instance: cx.me().clone(),
            reason: format!(
                "its judge {}",
                if error.is_panic() {
                    "panicked"
                } else {
                    "was cancelled"
                }
            ),
        })
}

/// `Objtest(F1 … F4) ← SEF_i(F1 … F4)`.
fn connect_sef(cx: &Cx, from: &SefPorts, to: &ObjtestPorts) {
    cx.connect(&from.f1, &to.f1);
    cx.connect(&from.f2, &to.f2);
    cx.connect(&from.f3, &to.f3);
    cx.connect(&from.f4, &to.f4);
}
