//! What a recorder draws of a simulated world, and the trait, [`World`], through which a
//! world gives it.
//!
//! Why a crate of its own, with no dependencies: the recorder (`imrs-record`) must draw any
//! world without compiling one — recording a cell compiles neither rapier nor the chip
//! line's geometry — and a world (`imrs-sim`) must be drawable without compiling the
//! recorder's MCAP writer. Both depend on this small vocabulary instead of on each other:
//! boxes, two-link arms, pallets, feeders, conveyors and a shared zone, as plain numbers and
//! names, and the facts a world measures, as text and fields.
//!
//! Times are durations since the start of the world's clock, as the framework's instants
//! count them, so that a recording's timestamps are the clock's own.
//!
//! A world that draws one box and measures nothing:
//!
//! ```
//! use std::time::Duration;
//! use imrs_scene::{BoxPose, Fact, Layout, Scene, World};
//!
//! struct Crate;
//!
//! impl World for Crate {
//!     fn layout(&self) -> Layout {
//!         Layout::default()
//!     }
//!     fn watch(&self, _period: Duration, mut see: Box<dyn FnMut(&Scene) + Send>) {
//!         let zone = BoxPose { centre: [0.0; 3], half: [0.5; 3] };
//!         see(&Scene { zone: Some(zone), ..Scene::default() });
//!     }
//!     fn facts(&self, _see: Box<dyn FnMut(&Fact) + Send>) {}
//! }
//!
//! use std::sync::Arc;
//! use std::sync::atomic::{AtomicUsize, Ordering};
//!
//! let seen = Arc::new(AtomicUsize::new(0));
//! let counted = Arc::clone(&seen);
//! Crate.watch(
//!     Duration::from_millis(100),
//!     Box::new(move |scene| {
//!         assert!(scene.zone.is_some());
//!         counted.fetch_add(1, Ordering::Relaxed);
//!     }),
//! );
//! assert_eq!(seen.load(Ordering::Relaxed), 1);
//! ```

use std::time::Duration;

/// A world a recorder can draw: its fixed parts, its moving parts as they move, and the
/// facts it measures.
pub trait World {
    /// The parts that never move.
    fn layout(&self) -> Layout;

    /// Calls `see` with the scene now, then as the world moves: at most once per `period`
    /// of its clock while something moves, and once when everything has stopped.
    fn watch(&self, period: Duration, see: Box<dyn FnMut(&Scene) + Send>);

    /// Calls `see` with every fact the world measures from now on, in order.
    fn facts(&self, see: Box<dyn FnMut(&Fact) + Send>);
}

/// The parts of a world that never move.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Layout {
    /// Its conveyors.
    pub conveyors: Vec<Conveyor>,
}

/// A conveyor, drawn as a flat belt with its name beside it.
#[derive(Debug, Clone, PartialEq)]
pub struct Conveyor {
    /// Its name, such as `A`.
    pub name: String,
    /// The belt.
    pub belt: BoxPose,
    /// Where its name is written.
    pub label_at: [f32; 3],
}

/// The moving parts of a world at one moment.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Scene {
    /// When: time since the start of the world's clock.
    pub at: Duration,
    /// Every arm.
    pub arms: Vec<Arm>,
    /// Every pallet.
    pub pallets: Vec<Pallet>,
    /// Every feeder.
    pub feeders: Vec<Feeder>,
    /// The zone the arms share, if the world has one.
    pub zone: Option<BoxPose>,
}

/// An arm: its links, base first.
#[derive(Debug, Clone, PartialEq)]
pub struct Arm {
    /// Its name, such as `chip-robot-A`.
    pub name: String,
    /// Its links, from the base to the tool.
    pub links: Vec<Link>,
    /// Whether it reaches into the shared zone.
    pub in_zone: bool,
}

/// A link: a capsule lying along its own x axis, turned about z.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Link {
    /// The capsule's centre, metres.
    pub centre: [f32; 3],
    /// Its turn about the z axis, radians.
    pub yaw: f32,
    /// The length of its segment, between the centres of its end caps.
    pub length: f32,
    /// Its radius.
    pub radius: f32,
}

/// A pallet, and the card it may carry.
#[derive(Debug, Clone, PartialEq)]
pub struct Pallet {
    /// Its name, unique among the pallets of a world, such as `pallet-3`.
    pub name: String,
    /// Its box.
    pub pose: BoxPose,
    /// Whether a card lies on it.
    pub card: bool,
    /// The chips on its card.
    pub chips: u32,
}

/// A feeder of parts.
#[derive(Debug, Clone, PartialEq)]
pub struct Feeder {
    /// Its name, such as `feeder-0`.
    pub name: String,
    /// The number of the part it holds.
    pub chip: u32,
    /// The parts it has left.
    pub stock: u32,
    /// Where it stands.
    pub at: [f32; 3],
}

/// A box, axis-aligned.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoxPose {
    /// Its centre, metres.
    pub centre: [f32; 3],
    /// Its half extents.
    pub half: [f32; 3],
}

/// A fact a world measured.
#[derive(Debug, Clone, PartialEq)]
pub struct Fact {
    /// When: time since the start of the world's clock.
    pub at: Duration,
    /// What kind of fact, in `snake_case`, such as `zone_entered`.
    pub kind: &'static str,
    /// The fact in words.
    pub text: String,
    /// Its fields beside the kind and the text, by name.
    pub fields: Vec<(&'static str, Field)>,
    /// How much an engineer should see it: `None` for the facts that only make the record.
    pub severity: Option<Severity>,
    /// Who entered or left the shared zone, if the fact says so.
    pub zone: Option<ZoneChange>,
}

/// The value of a fact's field.
#[derive(Debug, Clone, PartialEq)]
pub enum Field {
    /// Words.
    Text(String),
    /// A count or a number that names something.
    Count(u64),
    /// Measurements.
    Numbers(Vec<f32>),
}

/// How much an engineer should see a fact.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Severity {
    /// Something went wrong that the world recovers from, such as a fault or a jam.
    Warning,
    /// Something that must not happen, such as a collision.
    Error,
}

/// An arm entering or leaving the shared zone, by its name.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ZoneChange {
    /// It reached in.
    Entered(String),
    /// It left.
    Left(String),
}
