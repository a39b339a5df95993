//! A table of SCARA arms sharing zones and a tool, in a rapier3d world stepped on the
//! framework clock: the physical side of a coordinated cell (Jiménez et al. 1992).
//!
//! Each arm drives its tool along straight legs at its own top speed, speeding up and
//! braking at its own limit: its dynamic controller stops at a leg's end as planned, but
//! goes only as far as it is allowed, and beyond the last point allowed it needs its
//! stopping distance to stop ([`TableArm::allow`], [`TableArm::halt`]). Its links are
//! placed by its kinematics ([`Scara`], on nalgebra) at every step. Rapier measures what
//! the coordination must guarantee: whether the links of two arms touched, how close they came, and which
//! grippers were inside which zone, moving or still — an exclusive zone with two grippers
//! in it, or a shared zone with two moving in it, is a conflict. The tool is a body of its
//! own: an arm can grasp it only where rapier finds it within reach of the gripper.
//!
//! ```
//! use std::sync::Arc;
//! use std::time::Duration;
//! use imrs_ports::{Instant, VirtualClock};
//! use imrs_sim::scara::{Elbow, Scara};
//! use imrs_sim::table::{ArmSpec, Table, TableLayout, ZoneSpec, ZoneUse};
//! use nalgebra::{Point2, Point3};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # let runtime = tokio::runtime::Builder::new_current_thread().enable_all().start_paused(true).build()?;
//! # runtime.block_on(async {
//! let layout = TableLayout {
//!     arms: vec![ArmSpec {
//!         name: "ARM_1".into(),
//!         arm: Scara { base: Point2::new(-0.6, 0.0), upper: 0.4, fore: 0.35, side: Elbow::Left },
//!         home: Point2::new(-0.3, 0.0),
//!         speed: 0.5,
//!         acceleration: 2.5,
//!     }],
//!     zones: vec![ZoneSpec {
//!         name: "FIXTURE".into(),
//!         usage: ZoneUse::Exclusive,
//!         centre: Point3::new(0.0, 0.0, 0.3),
//!         half: [0.08, 0.08, 0.3],
//!     }],
//!     tool: Point2::new(-0.3, 0.2),
//! };
//! let clock = VirtualClock::new();
//! let table = Table::new(layout, Arc::new(clock.clone()))?;
//! table.spawn();
//! let arm = table.arm("ARM_1")?;
//! let moving = tokio::spawn(async move {
//!     arm.move_to(Point2::new(-0.3, 0.2)).await?;
//!     arm.grasp_tool()?;
//!     arm.move_to(Point2::new(0.0, 0.0)).await
//! });
//! imrs_core::time::drive(&clock, Instant::from_start(Duration::from_secs(5))).await;
//! moving.await??;
//! let measured = table.measured();
//! assert_eq!(measured.zone_time[0].0, "FIXTURE");
//! assert!(measured.zone_time[0].1 > Duration::ZERO); // rapier saw the gripper in the zone
//! # Ok::<_, Box<dyn std::error::Error>>(())
//! # })?;
//! # Ok(())
//! # }
//! ```

mod drive;
mod physics;
mod world;

use std::fmt;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::Duration;

use imrs_ports::{Instant, Name, SharedClock};
use nalgebra::{Point2, Point3};
use tokio::sync::Notify;

use self::world::TableWorld;
use crate::scara::Scara;

pub use self::drive::Progress;
pub use self::physics::{GRIPPER_RADIUS, LINK_RADIUS, WORK_Z};

/// The step of the table's world: 50 Hz, so that a tool at 1 m/s moves 2 cm a step.
pub const STEP: Duration = Duration::from_millis(20);
/// How near the gripper must come to the tool to grasp it.
pub const GRASP_REACH: f32 = 0.02;

/// One arm of the table.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmSpec {
    /// Its name.
    pub name: Name,
    /// Its kinematics.
    pub arm: Scara,
    /// Where its tool rests at the start.
    pub home: Point2<f32>,
    /// Its tool's top speed, in m/s.
    pub speed: f32,
    /// How fast it speeds up and brakes, in m/s².
    pub acceleration: f32,
}

/// How a zone may be shared: what rapier counts as a conflict in it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ZoneUse {
    /// One gripper inside at a time.
    Exclusive,
    /// Several inside, one moving at a time.
    Shared,
}

/// A zone: a box in space.
#[derive(Debug, Clone, PartialEq)]
pub struct ZoneSpec {
    /// Its name.
    pub name: Name,
    /// How it may be shared.
    pub usage: ZoneUse,
    /// Its centre, in metres.
    pub centre: Point3<f32>,
    /// Its half extents, in metres.
    pub half: [f32; 3],
}

/// The table: its arms, its zones, and where the tool lies at the start.
#[derive(Debug, Clone, PartialEq)]
pub struct TableLayout {
    /// The arms.
    pub arms: Vec<ArmSpec>,
    /// The zones.
    pub zones: Vec<ZoneSpec>,
    /// Where the tool lies.
    pub tool: Point2<f32>,
}

/// What rapier measured over a run.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Measured {
    /// Steps of the world.
    pub steps: u64,
    /// Each time the links of two arms came to touch: the arms, and when.
    pub collisions: Vec<(Name, Name, Instant)>,
    /// The closest the links of two arms came, in metres.
    pub closest: Option<f32>,
    /// Each time a zone came into conflict (two grippers in an exclusive zone, two moving
    /// in a shared one): the zone, when, and the arms inside.
    pub zone_conflicts: Vec<(Name, Instant, Vec<Name>)>,
    /// Each grasp of the tool where it was not (another arm had it, or it lay elsewhere):
    /// the arm, and when.
    pub tool_conflicts: Vec<(Name, Instant)>,
    /// How long each zone had a gripper in it.
    pub zone_time: Vec<(Name, Duration)>,
}

/// What a table operation can fail with; it names the arm.
#[derive(Debug, Clone, PartialEq)]
pub enum TableError {
    /// No arm has that name.
    UnknownArm(Name),
    /// The point lies outside the arm's reach.
    OutOfReach {
        /// The arm.
        arm: Name,
        /// The point, in metres.
        target: [f32; 2],
    },
    /// The tool is not within the gripper's reach (another arm holds it, or it lies
    /// elsewhere).
    ToolNotThere {
        /// The arm.
        arm: Name,
        /// How far the gripper is from the tool, in metres.
        distance: f32,
    },
    /// A leg was started while the arm still moved: a leg starts from rest.
    Moving {
        /// The arm.
        arm: Name,
        /// Its speed, in m/s.
        speed: f32,
    },
    /// A point was allowed to an arm that drives no leg.
    NoLeg {
        /// The arm.
        arm: Name,
    },
    /// The arm put down a tool it did not hold.
    NotHolding {
        /// The arm.
        arm: Name,
    },
    /// The layout cannot be built: what is wrong with it.
    Layout(String),
}

impl fmt::Display for TableError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::UnknownArm(arm) => write!(f, "no arm {arm} on the table"),
            Self::OutOfReach { arm, target } => write!(
                f,
                "{arm} cannot reach ({:.3}, {:.3}) m",
                target[0], target[1]
            ),
            Self::ToolNotThere { arm, distance } => write!(
                f,
                "{arm} found no tool to grasp: it lies {distance:.3} m from the gripper"
            ),
            Self::Moving { arm, speed } => write!(
                f,
                "{arm} still moves at {speed:.3} m/s: a leg starts from rest"
            ),
            Self::NoLeg { arm } => {
                write!(f, "{arm} was allowed a point of no leg: start one first")
            }
            Self::NotHolding { arm } => write!(f, "{arm} holds no tool to put down"),
            Self::Layout(why) => write!(f, "the table's layout cannot be built: {why}"),
        }
    }
}

impl std::error::Error for TableError {}

/// The simulated table. Cheap to clone: every clone drives the same world.
#[derive(Clone)]
pub struct Table {
    shared: Arc<Shared>,
}

struct Shared {
    layout: TableLayout,
    world: Mutex<TableWorld>,
    clock: SharedClock,
    activity: Notify,
    /// Each step taken, for arms waiting on their progress. (A `Notify`, whose waiters
    /// wake in the order they came: a cell runs the same way every time.)
    stepped: Notify,
}

impl Table {
    /// The table of `layout`, on `clock`; refused, naming what is wrong, if two arms share
    /// a name, an arm's home is out of its reach, or a speed or acceleration is not
    /// positive. Nothing moves
    /// until [`Table::run`] runs.
    pub fn new(layout: TableLayout, clock: SharedClock) -> Result<Self, TableError> {
        for (index, arm) in layout.arms.iter().enumerate() {
            if layout.arms[..index]
                .iter()
                .any(|other| other.name == arm.name)
            {
                return Err(TableError::Layout(format!(
                    "two arms are named {}",
                    arm.name
                )));
            }
            if !arm.arm.reaches(&arm.home) {
                return Err(TableError::Layout(format!(
                    "{}'s home ({:.3}, {:.3}) is out of its reach",
                    arm.name, arm.home.x, arm.home.y
                )));
            }
            if !(arm.speed.is_finite() && arm.speed > 0.0) {
                return Err(TableError::Layout(format!(
                    "{}'s speed {} m/s is not a positive number",
                    arm.name, arm.speed
                )));
            }
            if !(arm.acceleration.is_finite() && arm.acceleration > 0.0) {
                return Err(TableError::Layout(format!(
                    "{}'s acceleration {} m/s² is not a positive number",
                    arm.name, arm.acceleration
                )));
            }
        }
        Ok(Self {
            shared: Arc::new(Shared {
                world: Mutex::new(TableWorld::new(&layout)),
                layout,
                clock,
                activity: Notify::new(),
                stepped: Notify::new(),
            }),
        })
    }

    fn world(&self) -> MutexGuard<'_, TableWorld> {
        // Each critical section leaves the world whole: a panic cannot half-change it.
        self.shared
            .world
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
    }

    /// The layout it was built from.
    pub fn layout(&self) -> &TableLayout {
        &self.shared.layout
    }

    /// The stepper: steps the world every [`STEP`] of the clock while anything moves, and
    /// sleeps while nothing does. Spawn it once.
    pub async fn run(self) {
        let clock = Arc::clone(&self.shared.clock);
        let mut last: Option<Instant> = None;
        loop {
            if !self.world().is_active() {
                self.shared.activity.notified().await;
            }
            let now = clock.now().max(last.unwrap_or(Instant::ZERO));
            let next = Instant::from_start(Duration::from_nanos(
                ((now.since_start().as_nanos() / STEP.as_nanos() + 1) * STEP.as_nanos()) as u64,
            ));
            clock.sleep_until(next).await;
            let elapsed = last.map_or(STEP, |last| next.saturating_duration_since(last).min(STEP));
            self.world().step(next, elapsed);
            self.shared.stepped.notify_waiters();
            last = Some(next);
        }
    }

    /// Spawns [`Table::run`] on the current tokio runtime.
    pub fn spawn(&self) -> tokio::task::JoinHandle<()> {
        tokio::spawn(self.clone().run())
    }

    /// Arm `name`'s handle.
    pub fn arm(&self, name: &str) -> Result<TableArm, TableError> {
        let index = self
            .shared
            .layout
            .arms
            .iter()
            .position(|arm| arm.name == name)
            .ok_or_else(|| TableError::UnknownArm(name.into()))?;
        Ok(TableArm {
            table: self.clone(),
            index,
        })
    }

    /// The joints of every arm now (base, elbow, tool), by name: the simulation's own view,
    /// for measuring and showing the cell. A module of the cell is given its own arm
    /// ([`Table::arm`]) and learns where the others are only from them, through its ports.
    pub fn joints(&self) -> Vec<(Name, [Point2<f32>; 3])> {
        let world = self.world();
        world
            .arms
            .iter()
            .filter_map(|arm| {
                let joints = arm.scara().joints(&arm.tool())?;
                Some((arm.spec.name.clone(), joints))
            })
            .collect()
    }

    /// What rapier measured so far.
    pub fn measured(&self) -> Measured {
        self.world().measured.clone()
    }
}

/// One arm's handle.
#[derive(Clone)]
pub struct TableArm {
    table: Table,
    index: usize,
}

impl TableArm {
    fn spec(&self) -> &ArmSpec {
        &self.table.shared.layout.arms[self.index]
    }

    /// Its name.
    pub fn name(&self) -> &Name {
        &self.spec().name
    }

    /// Its kinematics.
    pub fn scara(&self) -> Scara {
        self.spec().arm
    }

    /// Where its tool is now.
    pub fn at(&self) -> Point2<f32> {
        self.table.world().arms[self.index].tool()
    }

    /// Moves the tool in a straight line to `to` and stops there: a leg allowed to its end
    /// ([`TableArm::start_leg`], [`TableArm::allow`]). Refused at once if `to` is out of
    /// reach or the arm still moves.
    pub async fn move_to(&self, to: Point2<f32>) -> Result<(), TableError> {
        self.start_leg(to)?;
        self.allow(to)?;
        while !self.step().await.arrived() {}
        Ok(())
    }

    /// Starts a straight leg from where the tool stands to `to`, allowed nowhere yet: the arm
    /// moves once it is allowed points of it. Refused if `to` is out of reach, or if the
    /// arm still moves (a leg starts from rest).
    pub fn start_leg(&self, to: Point2<f32>) -> Result<(), TableError> {
        if !self.scara().reaches(&to) {
            return Err(TableError::OutOfReach {
                arm: self.name().clone(),
                target: [to.x, to.y],
            });
        }
        self.table
            .world()
            .start_leg(self.index, to)
            .map_err(|speed| TableError::Moving {
                arm: self.name().clone(),
                speed,
            })?;
        self.table.shared.activity.notify_one();
        Ok(())
    }

    /// Allows the arm as far as `point` of its leg (taken where it lies along the leg), and
    /// lifts a halt: the seed's TRAJECTORY_POINT, and CONTINUE. It does not plan to stop at
    /// the last point allowed: there it brakes, and goes on by its stopping distance.
    /// Refused, by the arm's name, if no leg was started ([`TableArm::start_leg`]): it
    /// would allow nothing, and the arm would never move.
    pub fn allow(&self, point: Point2<f32>) -> Result<(), TableError> {
        let Some(drive) = &mut self.table.world().arms[self.index].drive else {
            return Err(TableError::NoLeg {
                arm: self.name().clone(),
            });
        };
        drive.allow(point);
        self.table.shared.activity.notify_one();
        Ok(())
    }

    /// STOP_C: the arm brakes at once, whatever it was allowed.
    pub fn halt(&self) {
        if let Some(drive) = &mut self.table.world().arms[self.index].drive {
            drive.halt();
        }
    }

    /// Its progress along the leg it drives; at rest at the end of its last leg if it
    /// drives none.
    pub fn progress(&self) -> Progress {
        let world = self.table.world();
        let state = &world.arms[self.index];
        state.drive.map_or(
            Progress {
                along: 0.0,
                length: 0.0,
                speed: 0.0,
                allowed: 0.0,
                halted: false,
            },
            |drive| drive.progress(),
        )
    }

    /// Its progress after the world's next step, or now if it stands still and may not
    /// move (a step would not change it).
    pub async fn step(&self) -> Progress {
        // Woken by every step from its creation on, before it is first polled.
        let stepped = self.table.shared.stepped.notified();
        let can_move = self.table.world().arms[self.index]
            .drive
            .is_some_and(|drive| drive.can_move());
        if can_move {
            stepped.await;
        }
        self.progress()
    }

    /// Grasps the tool, if rapier finds it within [`GRASP_REACH`] of the gripper and no
    /// other arm holds it; a grasp that finds no tool is counted as a tool conflict.
    pub fn grasp_tool(&self) -> Result<(), TableError> {
        let now = self.table.shared.clock.now();
        let mut world = self.table.world();
        world.place_arm(self.index);
        let distance = world.gripper_to_tool(self.index);
        let free = world.holder.is_none_or(|holder| holder == self.index);
        if distance > GRASP_REACH || !free {
            world
                .measured
                .tool_conflicts
                .push((self.name().clone(), now));
            return Err(TableError::ToolNotThere {
                arm: self.name().clone(),
                distance,
            });
        }
        world.holder = Some(self.index);
        Ok(())
    }

    /// Puts the tool down where the gripper is.
    pub fn put_tool(&self) -> Result<(), TableError> {
        let mut world = self.table.world();
        if world.holder != Some(self.index) {
            return Err(TableError::NotHolding {
                arm: self.name().clone(),
            });
        }
        world.place_arm(self.index);
        world.holder = None;
        Ok(())
    }

    /// Where the tool lies now, as rapier has it.
    pub fn tool_position(&self) -> Point2<f32> {
        self.table.world().tool_position()
    }
}
