//! The coordinated table cell: four SCARA arms on the simulated table share an exclusive
//! fixture, a parts tray shared with restrictions (several arms inside, one moving) and one
//! screwdriver, under the zone coordinator, fed by the run-time task scheduler — `cargo run
//! --release --example coord_cell`.
//!
//! Why a crate of its own: this is a cell built on the coordination layer (`imrs-coord`),
//! as `cell-example` is a cell built on the core, and it drives a simulated world
//! (`imrs-sim`'s `table`). Kept apart, the coordination layer compiles no world and no
//! physics engine, with no feature to remember, and this cell's tests and example still run
//! with the workspace's.
//!
//! Every module talks through ports: each arm ([`arm`](self) module `ARM_1` … `ARM_4`)
//! asks the `SCHEDULER` for its next job on `NEXT_JOB`, and the `COORDINATOR` for zones and
//! the tool on the seed's message set. An arm's trajectory runs through its pipeline: points
//! computed ahead, a zone requested before the arm reaches it (a *sleep* stops the arm
//! short of the border, STOP_C), released once the arm has left it. Every arm tells the
//! coordinator where its links are after every step (position information), and before
//! every step asks it to check its links a few points ahead against where the other arms
//! told it they are: a stopped arm in the way is waited for, then gone round on the
//! alternative trajectory the coordinator computes, and two arms in each other's way are
//! parted by one backing off (home, or a short way back or aside). No arm reads another's state from the
//! simulation: an arm module holds its own arm of the table, and nothing else of it.
//!
//! Rapier measures the outcome: collisions between arms, the closest they came, zone
//! conflicts (two grippers in the fixture, two moving in the tray) and grasps of a tool that
//! was not there. The [`Report`] sets them beside the units made and what the coordinator
//! did, deadlocks included.
//!
//! ```no_run
//! use table_cell::{CellConfig, run};
//!
//! let report = run(&CellConfig::new(1, 1.0))?;
//! assert!(report.measured.collisions.is_empty());
//! println!("{report}");
//! # Ok::<(), table_cell::CellError>(())
//! ```

mod ablation;
mod arm;
mod layout;
mod report;
mod runs;
mod schedule;

use std::fmt;
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::Duration;

use imrs_coord::zones::ZoneKind;
use imrs_core::prelude::*;
use imrs_ports::{Instant, SharedClock, VirtualClock};
use imrs_sim::table::{LINK_RADIUS, Table, TableError, ZoneSpec, ZoneUse};

pub use self::ablation::{Ablation, AblationRow, ablation};
pub use self::layout::{
    ACCELERATION, FIXTURE, NoVariant, RACK, SCREWDRIVER, TRAY, Variant, layout, needs_tool,
    workcell,
};
pub use self::report::Report;
pub use self::runs::run_all;
pub use self::schedule::{Asking, Job, JobAsker, JobPort, SCHEDULER};

use self::arm::{MARGIN, Mechanisms, arm_module};
use self::schedule::{job_port, scheduler};
use imrs_coord::coordinator::{CoordinatorLog, CoordinatorPorts, coordinator};
use imrs_coord::network::{Bus, Placement, report};
use imrs_coord::scheduler::{Arrivals, Dispatch, PartDriven, Policy, RunTime, Static};
use imrs_coord::zones::{Positions, Resources, ZoneDef};

/// The coordinator module's name.
pub const COORDINATOR: &str = "COORDINATOR";
/// The longest run, in simulated hours.
pub const MAX_HOURS: f64 = 24.0;

/// Who decides which arm does what.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Assignment {
    /// The run-time scheduler.
    RunTime,
    /// A static assignment, each arm running its program in a fixed order.
    Programs,
    /// The same static assignment, each arm taking its oldest ready task.
    Dispatching,
    /// The part-driven variant: tasks in the order their parts came, by whichever capable
    /// arm asks first.
    PartDriven,
}

impl fmt::Display for Assignment {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::RunTime => "run-time scheduler",
            Self::Programs => "static programs",
            Self::Dispatching => "static, dispatched",
            Self::PartDriven => "part-driven",
        })
    }
}

/// Which of the seed's mechanisms keep the arms apart: the rows of the ablation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Coordination {
    /// Zones only: an arm asks for a zone as it is about to move towards it (the pipeline's
    /// offset 0), and nothing checks its way against the other arms.
    ZonesOnly,
    /// Zones through the pipeline, its offset computed from each arm's stopping distance;
    /// nothing checks the way against the other arms.
    Pipeline,
    /// Zones through the pipeline with an offset chosen, in points, whatever the arm needs
    /// to stop: a negative control.
    PipelineOffset(usize),
    /// The pipeline, and the coordinator checks each arm's way ahead against where the
    /// others told it they are, and computes the alternative trajectory round them.
    Full,
}

impl fmt::Display for Coordination {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::ZonesOnly => f.write_str("zones only"),
            Self::Pipeline => f.write_str("zones + pipeline"),
            Self::PipelineOffset(offset) => write!(f, "zones + pipeline, offset {offset}"),
            Self::Full => f.write_str("zones + pipeline + geometric check"),
        }
    }
}

impl Coordination {
    fn mechanisms(self, travel: Travel, variant: Variant) -> Mechanisms {
        let (offset, geometric) = match self {
            Self::ZonesOnly => (Some(0), false),
            Self::Pipeline => (None, false),
            Self::PipelineOffset(offset) => (Some(offset), false),
            Self::Full => (None, true),
        };
        Mechanisms {
            offset,
            geometric,
            via_home: travel == Travel::ViaHome,
            gives_up_rights: variant != Variant::RightsKept,
        }
    }
}

/// How an arm goes from one job to the next.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Travel {
    /// Home between jobs, out of the others' way: an arm holds nothing while it waits for
    /// the tool, and no zone or tool deadlock arises.
    ViaHome,
    /// Straight on to the next job: an arm that finished in the fixture asks for the tool
    /// from inside it, and one coming from the tray asks for the fixture from inside the
    /// tray, where rights to move are given up at the fixture's border.
    Straight,
}

impl fmt::Display for Travel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::ViaHome => "home between jobs",
            Self::Straight => "straight on between jobs",
        })
    }
}

/// A run of the table cell.
#[derive(Debug, Clone, PartialEq)]
pub struct CellConfig {
    /// Seeds the parts' arrivals.
    pub seed: u64,
    /// How long to run, in simulated hours.
    pub hours: f64,
    /// Who decides which arm does what.
    pub assignment: Assignment,
    /// Which mechanisms keep the arms apart.
    pub coordination: Coordination,
    /// How an arm goes from one job to the next.
    pub travel: Travel,
    /// The cell as laid out, or changed so that deadlocks of one kind happen: a variant
    /// other than [`Variant::AsLaidOut`] runs only with [`Travel::Straight`], and is
    /// refused by name otherwise.
    pub variant: Variant,
}

impl CellConfig {
    /// A run of `hours` on the arrivals of `seed`, with every mechanism: the run-time
    /// scheduler and [`Coordination::Full`], the arms going home between jobs.
    pub fn new(seed: u64, hours: f64) -> Self {
        Self {
            seed,
            hours,
            assignment: Assignment::RunTime,
            coordination: Coordination::Full,
            travel: Travel::ViaHome,
            variant: Variant::AsLaidOut,
        }
    }
}

/// Why a run could not be made.
#[derive(Debug)]
pub enum CellError {
    /// The run's length is not a number of hours in (0, [`MAX_HOURS`]].
    Hours(f64),
    /// The simulated table refused its layout.
    Table(TableError),
    /// A module could not be started.
    Start(String),
    /// A variant made to provoke deadlocks, with arms that go home between jobs, where it
    /// would provoke none.
    Variant(Variant),
}

impl fmt::Display for CellError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Hours(hours) => write!(
                f,
                "a run lasts more than 0 and at most {MAX_HOURS} hours, not {hours}"
            ),
            Self::Table(error) => write!(f, "{error}"),
            Self::Start(why) => write!(f, "the cell could not start: {why}"),
            Self::Variant(variant) => write!(
                f,
                "the variant {} makes its deadlocks only with arms that go straight on to \
                 their next job (Travel::Straight)",
                variant.flag()
            ),
        }
    }
}

impl std::error::Error for CellError {}

/// What the arms did, beside what the coordinator and rapier saw.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CellStats {
    /// Jobs each arm finished.
    pub jobs: Vec<u32>,
    /// How long each arm spent on its jobs, travel and waits included.
    pub busy: Vec<Duration>,
    /// Times an arm found another in its way and stopped.
    pub geometric_blocks: u32,
    /// Times it went round a stopped arm instead (the alternative trajectory).
    pub detours: u32,
    /// Times one of two arms in each other's way backed off.
    pub back_offs: u32,
    /// Rights to move in a shared zone given up by an arm stopped at the border of
    /// another zone, and asked for again once that zone was granted.
    pub rights_given_up: u32,
    /// Times an arm told by the coordinator to back off, the victim of a deadlock, got out
    /// of the way.
    pub victims: u32,
    /// Arms that stopped working, and why.
    pub failures: Vec<String>,
}

pub(crate) fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    // Each critical section is a few field updates: a panic cannot leave it half-changed.
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Runs the cell for `config.hours` of simulated time on a virtual clock, as fast as it
/// computes; the same config gives the same report.
pub fn run(config: &CellConfig) -> Result<Report, CellError> {
    if !(config.hours.is_finite() && config.hours > 0.0 && config.hours <= MAX_HOURS) {
        return Err(CellError::Hours(config.hours));
    }
    if config.variant != Variant::AsLaidOut && config.travel == Travel::ViaHome {
        return Err(CellError::Variant(config.variant));
    }
    let wall = std::time::Instant::now();
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .start_paused(true)
        .build()
        .map_err(|error| CellError::Start(error.to_string()))?;
    let mut report = runtime.block_on(simulate(config))?;
    report.wall = wall.elapsed();
    Ok(report)
}

async fn simulate(config: &CellConfig) -> Result<Report, CellError> {
    let clock = VirtualClock::new();
    let shared: SharedClock = Arc::new(clock.clone());
    let cell = Cell::new(Arc::clone(&shared));
    let layout = config.variant.layout();
    let table = Table::new(layout.clone(), Arc::clone(&shared)).map_err(CellError::Table)?;
    let names: Vec<&str> = layout.arms.iter().map(|arm| arm.name.as_str()).collect();
    let zones: Arc<Vec<ZoneDef>> = Arc::new(layout.zones.iter().map(zone_def).collect());

    let plan = config.variant.workcell();
    // Enough units that parts keep coming for the whole run (a window opens every 12 s on
    // average).
    let units = (config.hours * 3600.0 / 12.0 * 1.5).ceil() as usize;
    let arrivals = Arrivals::random(&plan, units, config.seed);
    let policy: Box<dyn Policy + Send> = match config.assignment {
        Assignment::RunTime => Box::new(RunTime::default()),
        Assignment::Programs => Box::new(Static::programs(&plan)),
        Assignment::Dispatching => Box::new(Static::dispatching(&plan)),
        Assignment::PartDriven => Box::new(PartDriven),
    };
    let completions: schedule::Completions = Arc::default();
    let jobs = job_port(&shared);
    let coordinator_ports = CoordinatorPorts::new(COORDINATOR, &names, &shared);
    let coordinator_log = Arc::new(Mutex::new(CoordinatorLog::default()));
    let stats = Arc::new(Mutex::new(CellStats {
        jobs: vec![0; names.len()],
        busy: vec![Duration::ZERO; names.len()],
        ..CellStats::default()
    }));

    let declared = coordinator_ports
        .declare_to(&cell)
        .and_then(|()| cell.declare(&jobs));
    declared.map_err(|error| CellError::Start(error.to_string()))?;
    table.spawn();
    let start = |spec: ModuleSpec<()>| {
        cell.start(spec)
            .map(drop)
            .map_err(|error| CellError::Start(error.to_string()))
    };
    start(coordinator(
        COORDINATOR,
        Resources::new(zones.iter().cloned(), [SCREWDRIVER], names.iter().copied()),
        Positions::new(names.iter().copied(), LINK_RADIUS, MARGIN),
        &coordinator_ports,
        Arc::clone(&coordinator_log),
    ))?;
    start(scheduler(
        &jobs,
        Dispatch::new(plan.clone(), arrivals),
        policy,
        Arc::clone(&completions),
    ))?;
    for (index, spec) in layout.arms.iter().enumerate() {
        start(arm_module(
            (
                table.arm(spec.name.as_str()).map_err(CellError::Table)?,
                spec,
                index,
            ),
            &coordinator_ports,
            &jobs,
            Arc::clone(&zones),
            Arc::clone(&stats),
            config
                .coordination
                .mechanisms(config.travel, config.variant),
        ))?;
    }

    // The cell on the paper's bus: the coordinator and the scheduler on one station, each
    // arm on a station of its own. Each port that crosses stations gets its worst case.
    let placement = names.iter().enumerate().fold(
        Placement::new().place(COORDINATOR, 0).place(SCHEDULER, 0),
        |placement, (index, name)| placement.place(*name, index as u32 + 1),
    );
    let network = report(&cell.ports(), &placement, &Bus::ieee_802_3(100.0))
        .map_err(|error| CellError::Start(error.to_string()))?;

    let end = Instant::from_start(Duration::from_secs_f64(config.hours * 3600.0));
    imrs_core::time::drive(&clock, end).await;

    let completed = lock(&completions).iter().filter(|at| **at <= end).count();
    Ok(Report {
        config: config.clone(),
        arms: names.iter().map(|name| (*name).into()).collect(),
        units: completed,
        measured: table.measured(),
        coordinator: lock(&coordinator_log).clone(),
        stats: lock(&stats).clone(),
        network,
        wall: Duration::ZERO,
    })
}

/// The coordinator's zone for a zone of the simulated table: its box, as the table's
/// sensor is built.
fn zone_def(zone: &ZoneSpec) -> ZoneDef {
    let kind = match zone.usage {
        ZoneUse::Exclusive => ZoneKind::Exclusive,
        ZoneUse::Shared => ZoneKind::Shared,
    };
    let c = zone.centre;
    ZoneDef::boxed(zone.name.clone(), kind, [c.x, c.y, c.z], zone.half)
}
