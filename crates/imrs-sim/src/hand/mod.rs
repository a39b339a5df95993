//! A simulated dextrous hand: a palm on a six-degree-of-freedom wrist, four fingers of two
//! phalanges on motorised multibody joints, fingertip touch from rapier's contacts, and
//! objects of different shapes and sizes resting on a table. It steps on the framework
//! clock, as the chip cell does, so a run on virtual time is reproducible.
//!
//! The hand is driven the way Lyons & Arbib 1985 drives its mechanism: each joint is driven to the
//! mean of the commands given to it ([`Hand::command`], one per source), and its sensors
//! report joint positions ([`Hand::position`]), fingertip contact ([`Hand::touch`]) and, as
//! a camera would, the objects' features with no identity attached ([`Hand::see`]).
//!
//! ```
//! use std::sync::Arc;
//! use std::time::Duration;
//! use imrs_ports::{Instant, VirtualClock};
//! use imrs_sim::hand::{Hand, HandConfig, finger_joints};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # let runtime = tokio::runtime::Builder::new_current_thread().enable_all().start_paused(true).build()?;
//! # runtime.block_on(async {
//! let clock = VirtualClock::new();
//! let hand = Hand::new(HandConfig::seeded(1), Arc::new(clock.clone()));
//! hand.spawn();
//! let [proximal, _] = finger_joints(1);
//! hand.command(proximal, 0, 0.5)?; // bend finger 1's first joint to 0.5 rad
//! imrs_core::time::drive(&clock, Instant::from_start(Duration::from_secs(1))).await;
//! assert!((hand.position(proximal)? - 0.5).abs() < 0.02);
//! # Ok::<_, Box<dyn std::error::Error>>(())
//! # })?;
//! # Ok(())
//! # }
//! ```

mod body;
mod layout;
mod object;

use std::fmt;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use imrs_ports::{Instant, SharedClock};
use nalgebra::{Isometry3, Point3};
use tokio::sync::Notify;
use tokio::sync::futures::Notified;

pub use body::Touch;
pub use layout::{
    FINGER_BASES, FINGER_LIMIT, FINGERS, HAND_STEP, JOINTS, PALM_HALF, PALM_HOME, PHALANX_LENGTHS,
    PHALANX_RADIUS, WRIST, WRIST_SPEED, finger_joints, finger_of,
};
pub use object::{Detection, Object, SCENE, Shape};

use crate::rng::Rng;
use crate::step::next_step_after;
use body::HandWorld;

/// How the hand's table is set.
#[derive(Debug, Clone, PartialEq)]
pub struct HandConfig {
    /// Seeds the camera's order of detections.
    pub seed: u64,
    /// The objects on the table.
    pub objects: Vec<Object>,
}

impl HandConfig {
    /// The default table ([`SCENE`]) for `seed`.
    pub fn seeded(seed: u64) -> Self {
        Self {
            seed,
            objects: SCENE.to_vec(),
        }
    }
}

/// A joint or a sensor that the hand does not have.
#[derive(Debug, Clone, PartialEq)]
pub enum HandError {
    /// No joint has this number (joints are 1 to [`JOINTS`]).
    NoJoint(usize),
    /// No finger has this number (fingers are 1 to 4).
    NoFinger(usize),
    /// No object has this index.
    NoObject(usize),
    /// A command or a position that is not a finite number.
    NotFinite {
        /// What it was for: `joint 7`, `object 1`.
        what: String,
        /// The value given.
        value: f32,
    },
}

impl fmt::Display for HandError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NoJoint(j) => write!(f, "the hand has no joint {j} (joints are 1 to {JOINTS})"),
            Self::NoFinger(i) => write!(f, "the hand has no finger {i} (fingers are 1 to 4)"),
            Self::NoObject(i) => write!(f, "the table has no object {i}"),
            Self::NotFinite { what, value } => {
                write!(f, "{value} for {what} is not a finite number")
            }
        }
    }
}

impl std::error::Error for HandError {}

/// The simulated hand. Cheap to clone: every clone drives the same world.
#[derive(Clone)]
pub struct Hand {
    shared: Arc<Shared>,
}

struct Shared {
    world: Mutex<HandWorld>,
    clock: SharedClock,
    stepped: Notify,
    camera: Mutex<Rng>,
    objects: usize,
    sources: AtomicU64,
}

impl Hand {
    /// A hand over the table of `config`, on `clock`. Nothing moves until [`Hand::run`].
    pub fn new(config: HandConfig, clock: SharedClock) -> Self {
        Self {
            shared: Arc::new(Shared {
                world: Mutex::new(HandWorld::new(&config.objects)),
                clock,
                stepped: Notify::new(),
                camera: Mutex::new(Rng::new(config.seed)),
                objects: config.objects.len(),
                sources: AtomicU64::new(1),
            }),
        }
    }

    /// The stepper: steps the world every [`HAND_STEP`] of the clock. Spawn it once.
    pub async fn run(self) {
        let clock = Arc::clone(&self.shared.clock);
        let mut last = Instant::ZERO;
        loop {
            let next = next_step_after(clock.now().max(last), HAND_STEP);
            clock.sleep_until(next).await;
            self.world().step();
            last = next;
            self.shared.stepped.notify_waiters();
        }
    }

    /// Spawns [`Hand::run`] on the current tokio runtime.
    pub fn spawn(&self) -> tokio::task::JoinHandle<()> {
        tokio::spawn(self.clone().run())
    }

    /// A number no other source of commands has: one per motor schema instance.
    pub fn source(&self) -> u64 {
        self.shared.sources.fetch_add(1, Ordering::Relaxed)
    }

    /// Sets `source`'s command for `joint`: metres or radians for the wrist, radians for a
    /// finger joint. The joint is driven to the mean of all live sources' commands.
    pub fn command(&self, joint: usize, source: u64, value: f32) -> Result<(), HandError> {
        check_joint(joint)?;
        if !value.is_finite() {
            return Err(HandError::NotFinite {
                what: format!("joint {joint}"),
                value,
            });
        }
        self.world().command(joint, source, value);
        Ok(())
    }

    /// Withdraws `source`'s command for `joint`; with none left the joint holds where it
    /// was driven last.
    pub fn release(&self, joint: usize, source: u64) -> Result<(), HandError> {
        check_joint(joint)?;
        self.world().release(joint, source);
        Ok(())
    }

    /// The value `joint` is driven to now: the mean of its live commands.
    pub fn target(&self, joint: usize) -> Result<f32, HandError> {
        check_joint(joint)?;
        Ok(self.world().target(joint))
    }

    /// Where `joint` is, as rapier has it: the wrist's coordinate, or a finger joint's angle.
    pub fn position(&self, joint: usize) -> Result<f32, HandError> {
        check_joint(joint)?;
        Ok(self.world().position(joint))
    }

    /// What finger `finger`'s tip touches now, from rapier's contacts.
    pub fn touch(&self, finger: usize) -> Result<Option<Touch>, HandError> {
        check_finger(finger)?;
        Ok(self.world().touch(finger))
    }

    /// Where finger `finger`'s tip is.
    pub fn fingertip(&self, finger: usize) -> Result<Point3<f32>, HandError> {
        check_finger(finger)?;
        Ok(self.world().fingertip(finger))
    }

    /// How fast finger `finger` moves now (its faster link, m/s).
    pub fn finger_speed(&self, finger: usize) -> Result<f32, HandError> {
        check_finger(finger)?;
        Ok(self.world().finger_speed(finger))
    }

    /// The palm's pose.
    pub fn palm(&self) -> Isometry3<f32> {
        self.world().palm()
    }

    /// What the camera sees this frame: one detection per object, in no fixed order and
    /// with no identity — keeping track of which is which is the vision interface's job.
    pub fn see(&self) -> Vec<Detection> {
        let mut seen = self.objects();
        let mut camera = self
            .shared
            .camera
            .lock()
            .unwrap_or_else(PoisonError::into_inner);
        for i in (1..seen.len()).rev() {
            seen.swap(i, camera.range(0, i as u32) as usize);
        }
        seen
    }

    /// Every object as it is now, in the order of [`HandConfig::objects`]: the truth a test
    /// checks the vision against.
    pub fn objects(&self) -> Vec<Detection> {
        self.world().objects()
    }

    /// Moves object `index` to rest at `at` (x, y) on the table, as a hand outside the cell
    /// would.
    pub fn push(&self, index: usize, at: [f32; 2]) -> Result<(), HandError> {
        if index >= self.shared.objects {
            return Err(HandError::NoObject(index));
        }
        if let Some(&value) = at.iter().find(|v| !v.is_finite()) {
            return Err(HandError::NotFinite {
                what: format!("object {index}"),
                value,
            });
        }
        self.world().push(index, at);
        Ok(())
    }

    /// Completes after the world's next step. Create it before looking at the world.
    pub fn stepped(&self) -> Notified<'_> {
        self.shared.stepped.notified()
    }

    /// The time now, on the hand's clock.
    pub fn now(&self) -> Instant {
        self.shared.clock.now()
    }

    /// The hand's clock.
    pub fn clock(&self) -> &SharedClock {
        &self.shared.clock
    }

    fn world(&self) -> MutexGuard<'_, HandWorld> {
        // Every change is a short synchronous block that leaves the world consistent.
        self.shared
            .world
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
    }
}

fn check_joint(joint: usize) -> Result<(), HandError> {
    if (1..=JOINTS).contains(&joint) {
        Ok(())
    } else {
        Err(HandError::NoJoint(joint))
    }
}

fn check_finger(finger: usize) -> Result<(), HandError> {
    if FINGERS.contains(&finger) {
        Ok(())
    } else {
        Err(HandError::NoFinger(finger))
    }
}

impl fmt::Debug for Hand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Hand")
            .field("now", &self.now())
            .finish_non_exhaustive()
    }
}
