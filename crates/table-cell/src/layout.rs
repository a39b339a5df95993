//! The table cell's layout: four arms at the four sides of a 1.2 m table, their elbows all
//! bent the same way (a pinwheel, so that no two folded arms meet), an exclusive fixture in
//! the middle, a shared parts tray in one corner, and the screwdriver's rack in another;
//! and the unit the scheduler plans: robot-independent tasks over three kinds of part.

use imrs_sim::scara::{Elbow, Scara};
use imrs_sim::table::{ArmSpec, TableLayout, ZoneSpec, ZoneUse};
use std::fmt;

use nalgebra::{Point2, Point3};

use imrs_coord::scheduler::{Robot, Skill, TaskSpec, Workcell, Zone};

/// The exclusive zone: the fixture the unit is assembled on.
pub const FIXTURE: &str = "FIXTURE";
/// The zone shared with restrictions: the parts tray (several arms inside, one moving).
pub const TRAY: &str = "TRAY";
/// The tool: always exclusive.
pub const SCREWDRIVER: &str = "SCREWDRIVER";
/// Where the screwdriver lies when nobody holds it.
pub const RACK: [f32; 2] = [0.26, 0.26];

/// The arms' upper arm and forearm, as in the chip cell.
const UPPER: f32 = 0.4;
const FORE: f32 = 0.35;
/// How far from its base an arm takes work: within its 0.75 m reach, clear of full
/// stretch.
const WORK_REACH: f64 = 0.7;
/// The nominal tool speed (a robot of speed 1), in m/s.
const NOMINAL_SPEED: f64 = 0.5;
/// How fast every arm speeds up and brakes, in m/s²: stopping from its top speed takes it
/// 3 to 9 cm.
pub const ACCELERATION: f32 = 2.5;

struct Side {
    name: &'static str,
    base: [f32; 2],
    skills: &'static [Skill],
    speed: f64,
}

const SIDES: [Side; 4] = [
    Side {
        name: "ARM_1",
        base: [-0.6, 0.0],
        skills: &[Skill::Place, Skill::Insert],
        speed: 1.0,
    },
    Side {
        name: "ARM_2",
        base: [0.6, 0.0],
        skills: &[Skill::Place, Skill::Screw],
        speed: 1.3,
    },
    Side {
        name: "ARM_3",
        base: [0.0, -0.6],
        skills: &[Skill::Place, Skill::Insert],
        speed: 0.8,
    },
    Side {
        name: "ARM_4",
        base: [0.0, 0.6],
        skills: &[Skill::Place, Skill::Insert, Skill::Screw],
        speed: 1.0,
    },
];

/// Where an arm rests: 0.28 m from its base towards the middle, folded.
fn home(base: [f32; 2]) -> Point2<f32> {
    let base = Point2::from(base);
    base + (Point2::origin() - base).normalize() * 0.28
}

/// The cell as laid out and programmed, or changed in one thing so that deadlocks of one
/// kind happen when arms go straight on to their next job ([`Travel::Straight`]).
///
/// [`Travel::Straight`]: crate::Travel::Straight
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variant {
    /// As laid out, as the seed would have it: the tray shared with restrictions, a right to
    /// move given up at a border, one screw a unit. No deadlock can pass through the tray.
    AsLaidOut,
    /// The tray for exclusive use: an arm in it asks for the fixture, next to it, from
    /// inside, and one in the fixture asks for the tray — zone deadlocks.
    ExclusiveTray,
    /// The base screwed down before the shaft goes in: an arm that placed it asks for the
    /// screwdriver from inside the fixture, which the screwdriver's holder may be waiting
    /// for — tool deadlocks.
    ScrewedBase,
    /// Against the seed's rule, an arm refused at a border keeps its right to move in the
    /// tray: one in the fixture that asks to move in the tray closes a cycle — mixed
    /// deadlocks.
    RightsKept,
}

/// A variant's [`flag`](Variant::flag) that names none.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NoVariant(pub String);

impl fmt::Display for NoVariant {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let flags: Vec<&str> = Variant::ALL.iter().map(|v| v.flag()).collect();
        write!(f, "no variant {}; use {}", self.0, flags.join(", "))
    }
}

impl std::error::Error for NoVariant {}

impl std::str::FromStr for Variant {
    type Err = NoVariant;

    fn from_str(flag: &str) -> Result<Self, NoVariant> {
        Self::ALL
            .into_iter()
            .find(|variant| variant.flag() == flag)
            .ok_or_else(|| NoVariant(flag.into()))
    }
}

impl fmt::Display for Variant {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::AsLaidOut => "as laid out",
            Self::ExclusiveTray => "tray exclusive",
            Self::ScrewedBase => "base screwed down",
            Self::RightsKept => "rights to move kept at a border",
        })
    }
}

impl Variant {
    /// Every variant, the cell as laid out first.
    pub const ALL: [Self; 4] = [
        Self::AsLaidOut,
        Self::ExclusiveTray,
        Self::ScrewedBase,
        Self::RightsKept,
    ];

    /// Its name on a command line: `as-laid-out`, `exclusive-tray`, `screwed-base`,
    /// `rights-kept`.
    pub fn flag(self) -> &'static str {
        match self {
            Self::AsLaidOut => "as-laid-out",
            Self::ExclusiveTray => "exclusive-tray",
            Self::ScrewedBase => "screwed-base",
            Self::RightsKept => "rights-kept",
        }
    }

    /// The simulated table.
    pub fn layout(self) -> TableLayout {
        let tray = if self == Self::ExclusiveTray {
            ZoneUse::Exclusive
        } else {
            ZoneUse::Shared
        };
        let mut layout = layout();
        for zone in layout.zones.iter_mut().filter(|zone| zone.name == TRAY) {
            zone.usage = tray;
        }
        layout
    }

    /// The cell as the run-time scheduler sees it.
    pub fn workcell(self) -> Workcell {
        let mut cell = workcell();
        if self == Self::ScrewedBase {
            // Screwed down after it is placed, and before the shaft goes in.
            let screw = TaskSpec::new("screw base", Skill::Screw, 3.0, [0.02, 0.02], &[0], &[]);
            cell.tasks.push(screw);
            let screwed = cell.tasks.len() - 1;
            cell.tasks[INSERT_SHAFT].after.push(screwed);
        }
        cell
    }
}

/// The simulated table, as laid out.
pub fn layout() -> TableLayout {
    let zone = |name: &str, usage, centre: [f32; 2], half: f32| ZoneSpec {
        name: name.into(),
        usage,
        centre: Point3::new(centre[0], centre[1], 0.3),
        half: [half, half, 0.3],
    };
    TableLayout {
        arms: SIDES
            .iter()
            .map(|side| ArmSpec {
                name: side.name.into(),
                arm: Scara {
                    base: side.base.into(),
                    upper: UPPER,
                    fore: FORE,
                    side: Elbow::Right,
                },
                home: home(side.base),
                speed: (NOMINAL_SPEED * side.speed) as f32,
                acceleration: ACCELERATION,
            })
            .collect(),
        zones: vec![
            zone(FIXTURE, ZoneUse::Exclusive, [0.0, 0.0], 0.08),
            zone(TRAY, ZoneUse::Shared, [-0.25, -0.25], 0.15),
        ],
        tool: RACK.into(),
    }
}

/// The unit's tasks, as the scheduler plans them: which need the screwdriver.
pub fn needs_tool(task: &TaskSpec) -> bool {
    task.skill == Skill::Screw
}

/// Where "insert shaft" is among the unit's tasks.
const INSERT_SHAFT: usize = 3;

/// The cell as the run-time scheduler sees it, as laid out: the four arms (skills, speeds, where they
/// stand and how far they reach), the six tasks of a unit, and the fixture as its zone.
pub fn workcell() -> Workcell {
    let robots = SIDES
        .iter()
        .map(|side| {
            let home = home(side.base);
            Robot {
                name: side.name.into(),
                skills: side.skills.to_vec(),
                speed: side.speed,
                home: [f64::from(home.x), f64::from(home.y)],
                reach: (side.base.map(f64::from), WORK_REACH),
            }
        })
        .collect();
    let task = TaskSpec::new;
    use Skill::{Insert, Place, Screw};
    Workcell {
        robots,
        tasks: vec![
            task("place base", Place, 2.0, [0.0, 0.0], &[], &[0]),
            task("kit cover", Place, 3.0, [-0.38, -0.16], &[], &[1]),
            task("kit shaft", Place, 3.0, [-0.16, -0.38], &[], &[2]),
            task("insert shaft", Insert, 4.0, [0.03, -0.02], &[0, 2], &[]),
            task("place cover", Place, 3.0, [-0.02, 0.03], &[1, 3], &[]),
            task("screw cover", Screw, 5.0, [0.0, 0.0], &[4], &[]),
        ],
        parts: vec!["base", "cover", "shaft"],
        zones: vec![Zone {
            centre: [0.0, 0.0],
            radius: 0.08 * std::f64::consts::SQRT_2,
        }],
        travel: NOMINAL_SPEED,
        acceleration: f64::from(ACCELERATION),
        // An arm's tool at work, its links round it, and the margin.
        clearance: 0.1,
    }
}
