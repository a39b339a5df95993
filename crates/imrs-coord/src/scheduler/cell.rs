//! The cell the scheduler works in: robots, the elementary tasks of a unit, a shared zone,
//! and the parts' arrivals.

use imrs_ports::Name;

/// What a robot can do.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Skill {
    /// Pick and place.
    Place,
    /// Insert with force control.
    Insert,
    /// Screw.
    Screw,
}

/// A robot: its skills, how fast it is (1 = nominal), where it rests, and how far it
/// reaches.
#[derive(Debug, Clone, PartialEq)]
pub struct Robot {
    /// Its name.
    pub name: Name,
    /// What it can do.
    pub skills: Vec<Skill>,
    /// Its speed: work and travel take `1 / speed` of their nominal time.
    pub speed: f64,
    /// Where it starts, in metres on the table.
    pub home: [f64; 2],
    /// Where it stands, and how far from there it may work (infinite: anywhere).
    pub reach: ([f64; 2], f64),
}

impl Robot {
    /// Whether it is capable of `task`: it has the skill and reaches the place.
    pub fn can(&self, task: &TaskSpec) -> bool {
        self.skills.contains(&task.skill) && distance(self.reach.0, task.at) <= self.reach.1
    }
}

/// An elementary task of a unit, independent of any robot.
#[derive(Debug, Clone, PartialEq)]
pub struct TaskSpec {
    /// Its name.
    pub name: &'static str,
    /// The skill it needs.
    pub skill: Skill,
    /// Its nominal work time, in seconds.
    pub work: f64,
    /// Where it is done (its entry point), in metres.
    pub at: [f64; 2],
    /// The tasks of the same unit that must be done first (indices).
    pub after: Vec<usize>,
    /// The parts that must have arrived (part kinds, indices into [`Workcell::parts`]).
    pub parts: Vec<usize>,
}

impl TaskSpec {
    /// A task: what it needs, how long, where, after which tasks and parts.
    pub fn new(
        name: &'static str,
        skill: Skill,
        work: f64,
        at: [f64; 2],
        after: &[usize],
        parts: &[usize],
    ) -> Self {
        Self {
            name,
            skill,
            work,
            at,
            after: after.to_vec(),
            parts: parts.to_vec(),
        }
    }
}

/// A region only one robot may work in at a time, as the scheduler plans it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Zone {
    /// Its centre, in metres.
    pub centre: [f64; 2],
    /// Its radius.
    pub radius: f64,
}

impl Zone {
    /// Whether `at` lies in the zone.
    pub fn contains(&self, at: [f64; 2]) -> bool {
        distance(self.centre, at) <= self.radius
    }
}

pub(crate) fn distance(a: [f64; 2], b: [f64; 2]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}

impl Workcell {
    /// How long a robot of speed `speed` takes to travel `distance` m from rest to rest:
    /// up to its top speed and down again at the cell's acceleration, or, on a move too
    /// short to reach it, speeding up half the way and braking the other half.
    pub fn travel_time(&self, distance: f64, speed: f64) -> f64 {
        let (top, a) = (self.travel * speed, self.acceleration);
        if distance >= top * top / a {
            distance / top + top / a
        } else {
            2.0 * (distance / a).sqrt()
        }
    }
}

/// A cell: its robots, the tasks of one unit, the kinds of part, and its shared zones.
#[derive(Debug, Clone, PartialEq)]
pub struct Workcell {
    /// The robots.
    pub robots: Vec<Robot>,
    /// The elementary tasks of one unit.
    pub tasks: Vec<TaskSpec>,
    /// The kinds of part a unit needs, by name.
    pub parts: Vec<&'static str>,
    /// The zones shared by the robots, each worked in by one at a time.
    pub zones: Vec<Zone>,
    /// How fast a robot of speed 1 travels, in m/s.
    pub travel: f64,
    /// How fast a robot speeds up and brakes, in m/s² (infinite: at once).
    pub acceleration: f64,
    /// How far a robot's way must keep from the tool of a robot at work, in metres: one
    /// that passes nearer goes round it (0 or less: robots never meet).
    pub clearance: f64,
}

impl Workcell {
    /// An assembly cell of three robots of different skills and speeds, a unit of six
    /// tasks over four kinds of part, and a fixture zone in the middle that three of the
    /// tasks work in (placing the base, inserting the shaft, screwing the cover).
    pub fn assembly() -> Self {
        let robot = |name: &str, skills: &[Skill], speed, home| Robot {
            name: name.into(),
            skills: skills.to_vec(),
            speed,
            home,
            reach: (home, f64::INFINITY),
        };
        let task = TaskSpec::new;
        use Skill::{Insert, Place, Screw};
        Self {
            robots: vec![
                robot("ARM_1", &[Place, Insert], 1.0, [-0.6, 0.0]),
                robot("ARM_2", &[Place, Screw], 1.3, [0.6, 0.0]),
                robot("ARM_3", &[Place, Insert, Screw], 0.8, [0.0, 0.6]),
            ],
            tasks: vec![
                task("place base", Place, 2.0, [0.0, 0.0], &[], &[0]),
                task("place cover", Place, 4.0, [-0.4, -0.3], &[], &[1]),
                task("insert shaft", Insert, 4.0, [0.0, 0.05], &[0], &[2]),
                task("place gear", Place, 4.0, [0.4, -0.3], &[], &[3]),
                task("insert gear", Insert, 6.0, [0.35, -0.35], &[3], &[]),
                task("screw cover", Screw, 5.0, [0.05, 0.0], &[1, 2, 4], &[]),
            ],
            parts: vec!["base", "cover", "shaft", "gear"],
            zones: vec![Zone {
                centre: [0.0, 0.0],
                radius: 0.15,
            }],
            travel: 0.5,
            acceleration: f64::INFINITY,
            clearance: 0.0,
        }
    }
}

impl Workcell {
    /// The zone `at` lies in, if any (the first, where zones overlap).
    pub fn zone_of(&self, at: [f64; 2]) -> Option<usize> {
        self.zones.iter().position(|zone| zone.contains(at))
    }
}

impl Workcell {
    /// The assembly cell with most of a unit's work in the fixture zone (17 of 28 s
    /// nominal): the zone, not the robots, bounds the throughput, whoever does what.
    pub fn zone_bound() -> Self {
        let mut cell = Self::assembly();
        for (task, work) in cell.tasks.iter_mut().zip([4.0, 3.0, 6.0, 3.0, 5.0, 7.0]) {
            task.work = work;
        }
        cell
    }
}

/// When each part of each unit arrives, in seconds.
#[derive(Debug, Clone, PartialEq)]
pub struct Arrivals {
    /// `at[unit][part]`.
    pub at: Vec<Vec<f64>>,
}

impl Arrivals {
    /// Parts for `units` units, in random order at random times: the unit's parts come
    /// within a window that opens every 12 s on average, each at a uniform time within
    /// 30 s of it. Seeded: the same seed, the same arrivals.
    pub fn random(cell: &Workcell, units: usize, seed: u64) -> Self {
        let mut rng = SplitMix64(seed);
        let mut unit = || (rng.next_u64() >> 11) as f64 / (1u64 << 53) as f64;
        let mut opens = 0.0;
        let at = (0..units)
            .map(|_| {
                opens += 12.0 * 2.0 * unit();
                cell.parts.iter().map(|_| opens + 30.0 * unit()).collect()
            })
            .collect();
        Self { at }
    }
}

/// The arrivals' generator: SplitMix64, the simulation's own, here so that the scheduler
/// needs no simulated world for its randomness and a seed still gives the arrivals it gave.
struct SplitMix64(u64);

impl SplitMix64 {
    /// The next 64 random bits.
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
}
