//! Running the cell: on virtual time (the default) or on the wall clock.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::Duration;

use imrs_core::prelude::*;
use imrs_core::{CellError, CellErrors, Log, ModuleDecl, ModuleTree, time::drive};
use imrs_ports::{Instant, RealClock, SharedClock, VirtualClock};
use imrs_record::{RecordError, Recorder, Timeline};
use imrs_sim::{
    Fault, FaultKind, FeederId, Line, PalletId, RobotId, RobotTimes, Role, Sim, SimConfig,
    SimEvent, Station,
};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::chip::{
    FeederPolicy, SharedWaits, ZoneWaits, chip_it, feeder_coordinator, feeder_monitor,
};
use crate::devices::Devices;
use crate::faults::{CellFault, CellFaultKind};
use crate::gate::{CycleTimeHistory, ReleaseDeath, SharedCycleTimes, gate};
use crate::load::{load_card, load_it, screw_in_card};
use crate::outage::Outage;
use crate::ports::CellPorts;
use crate::processes::{self, DEFAULT_SPEED, LineProcess, Transport};
use crate::ros2;
use crate::tally::Tally;

/// How a run is made.
#[derive(Debug, Clone, PartialEq)]
pub struct CellConfig {
    /// Simulated hours.
    pub hours: f64,
    /// Seeds every random choice.
    pub seed: u64,
    /// How the chip robots share the feeders.
    pub feeder: FeederPolicy,
    /// Run on the wall clock instead of virtual time.
    pub realtime: bool,
    /// Faults to inject.
    pub faults: Vec<CellFault>,
    /// Show a progress bar on a terminal.
    pub progress: bool,
    /// Print the module tree (Shin 1985, §2) before the report.
    pub show_tree: bool,
    /// How many of the most recent events each log keeps in memory for the record (the
    /// report is folded from every event as it comes, whatever this is).
    pub kept_events: usize,
    /// Record the run into this MCAP file.
    pub record: Option<PathBuf>,
    /// Draw a timeline of a window of the run.
    pub timeline: Option<TimelineConfig>,
    /// Run across processes: the world in this one, each line in its own (see
    /// [`processes`]).
    pub processes: bool,
    /// Across processes, how many times as fast as the wall clock the cell runs.
    pub speed: f64,
    /// Across processes, what carries the ports between them.
    pub transport: Transport,
    /// Set in a line's process, which the world started.
    pub line_process: Option<LineProcess>,
    /// Be seen from ROS 2, a zenoh peer listening on this endpoint (see [`crate::ros2`]);
    /// on the wall clock.
    pub ros2: Option<String>,
}

/// Where to draw a timeline, and of which window of the run.
#[derive(Debug, Clone, PartialEq)]
pub struct TimelineConfig {
    /// The SVG file.
    pub path: PathBuf,
    /// Where the window starts, from the start of the run.
    pub from: Duration,
    /// How long it is.
    pub span: Duration,
}

impl Default for CellConfig {
    fn default() -> Self {
        Self {
            hours: 1.0,
            seed: 1985,
            feeder: FeederPolicy::Arbiter,
            realtime: false,
            faults: Vec::new(),
            progress: false,
            show_tree: false,
            kept_events: Log::<Event>::DEFAULT_CAPACITY,
            record: None,
            timeline: None,
            processes: false,
            speed: DEFAULT_SPEED,
            transport: Transport::Ipc,
            line_process: None,
            ros2: None,
        }
    }
}

/// Everything a run measured and logged.
#[derive(Debug, Clone)]
pub struct RunRecord {
    /// The configuration it ran with.
    pub config: CellConfig,
    /// Everything the report counts, folded from every event of the run.
    pub tally: Tally,
    /// The most recent physical facts from the simulation (at most
    /// [`CellConfig::kept_events`]; all of a short run).
    pub sim_events: Vec<SimEvent>,
    /// The most recent events of the modules (at most [`CellConfig::kept_events`]).
    pub cell_events: Vec<Event>,
    /// The pallets still on the conveyors at the end.
    pub pallets_left: Vec<(Line, PalletId, [f32; 3])>,
    /// The chip robots' waits for the zone.
    pub waits: [ZoneWaits; 2],
    /// The module tree at the end of the run, with its vertical and horizontal links.
    pub tree: ModuleTree,
    /// Each feeder at the end: its id, chip number and stock.
    pub feeders: Vec<(FeederId, u32, u32)>,
    /// How each robot spent its time, measured by the simulation.
    pub robot_times: Vec<(RobotId, RobotTimes)>,
    /// The closest two arms came while both were in the feeder zone (rapier), in metres.
    pub closest_in_zone: Option<f32>,
    /// Each line's GATE's CYCLE_TIME over the run.
    pub cycle_times: [CycleTimeHistory; 2],
    /// Simulated time.
    pub simulated: Duration,
    /// Wall time the run took.
    pub wall: Duration,
    /// Across processes: how late each process's timer woke at worst, in wall time (see
    /// [`crate::lateness`]). Empty in one process, on virtual time.
    pub lateness: Vec<(String, Duration)>,
    /// Across processes: each line's process that died, and its return.
    pub outages: Vec<Outage>,
    /// Across processes over zenoh: where the lines' hosts were.
    pub hosts: Option<String>,
}

/// The longest run: a year of shifts.
pub const MAX_HOURS: f64 = 8760.0;

/// Why a run could not be made.
#[derive(Debug, Clone, PartialEq)]
pub enum RunError {
    /// The cell is wired wrong: every problem, each naming its module and port.
    Wiring(CellErrors),
    /// The simulated hours are not a number above 0 and at most [`MAX_HOURS`].
    Hours(f64),
    /// The recording or the timeline could not be written.
    Output {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        error: String,
    },
    /// A run across processes could not be made: which process, and why.
    Processes {
        /// The process: the world, line A or line B.
        process: String,
        /// What went wrong.
        why: String,
    },
    /// The cell could not be made visible to ROS 2 (`--ros2`): why.
    Ros2(String),
    /// A fault is set for after the run's end, so it would never fire.
    FaultAfterEnd {
        /// The fault, as `--fault` writes it.
        fault: String,
        /// The run's length in hours.
        hours: f64,
    },
}

impl std::fmt::Display for RunError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Wiring(problems) => write!(f, "the cell is wired wrong:\n{problems}"),
            Self::Hours(hours) => {
                write!(
                    f,
                    "{hours} hours: expected a number of hours above 0, at most {MAX_HOURS}"
                )
            }
            Self::Output { path, error } => {
                write!(f, "{}: cannot be written: {error}", path.display())
            }
            Self::Processes { process, why } => write!(f, "across processes, {process}: {why}"),
            Self::Ros2(why) => write!(f, "--ros2: {why}"),
            Self::FaultAfterEnd { fault, hours } => write!(
                f,
                "--fault {fault}: set for after the run's end ({hours} h), so it would never fire; \
                 run longer with --hours or set it earlier"
            ),
        }
    }
}

impl std::error::Error for RunError {}

impl From<CellErrors> for RunError {
    fn from(problems: CellErrors) -> Self {
        Self::Wiring(problems)
    }
}

impl From<CellError> for RunError {
    fn from(problem: CellError) -> Self {
        Self::Wiring(problem.into())
    }
}

pub(crate) fn output(path: &Path, error: RecordError) -> RunError {
    RunError::Output {
        path: path.to_path_buf(),
        error: error.to_string(),
    }
}

/// What [`run`] refuses before it simulates anything: hours out of range, or a fault set
/// after the end.
pub fn refused(config: &CellConfig) -> Option<RunError> {
    let hours_ok = config.hours.is_finite() && config.hours > 0.0 && config.hours <= MAX_HOURS;
    if !hours_ok {
        return Some(RunError::Hours(config.hours));
    }
    let end = Duration::from_secs_f64(config.hours * 3600.0);
    if let Some(late) = config.faults.iter().find(|fault| fault.at > end) {
        return Some(RunError::FaultAfterEnd {
            fault: late.to_string(),
            hours: config.hours,
        });
    }
    None
}

/// Runs the cell as `config` says. Fails, naming every problem, if the cell is wired wrong.
pub fn run(config: &CellConfig) -> Result<RunRecord, RunError> {
    if let Some(refused) = refused(config) {
        return Err(refused);
    }
    if config.processes {
        return processes::run_world(config);
    }
    let wall = std::time::Instant::now();
    // ROS 2 sees the cell live: on the wall clock.
    let mut record = if config.realtime || config.ros2.is_some() {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .enable_all()
            .build()
            .expect("a tokio runtime starts");
        runtime.block_on(simulate(config, Arc::new(RealClock::new()), None))
    } else {
        // Time alone: nothing in one process on virtual time does I/O through tokio, and
        // an I/O driver would make every timer the cell sets a write to its wake-up file
        // and every idle turn a poll of it (a tenth of the run's time).
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_time()
            .start_paused(true)
            .build()
            .expect("a tokio runtime starts");
        let clock = VirtualClock::new();
        runtime.block_on(simulate(config, Arc::new(clock.clone()), Some(clock)))
    }?;
    record.wall = wall.elapsed();
    Ok(record)
}

async fn simulate(
    config: &CellConfig,
    clock: SharedClock,
    driver: Option<VirtualClock>,
) -> Result<RunRecord, RunError> {
    let cell = Cell::new(clock.clone());
    // The report counts the time lost to deadlocks from how long each wait lasted.
    cell.observe(true);
    let sim = Sim::new(SimConfig::seeded(config.seed), clock.clone());
    // Off unless asked for: with neither, nothing subscribes and nothing is paid.
    let recorder = match &config.record {
        Some(path) => {
            let recorder = Recorder::create(path).map_err(|error| output(path, error))?;
            recorder.record_cell(&cell);
            recorder.record_sim(&sim, Recorder::SCENE_PERIOD);
            Some(recorder)
        }
        None => None,
    };
    let timeline = config.timeline.as_ref().map(|window| {
        let timeline = Timeline::new(window.from, window.from + window.span);
        timeline.record_cell(&cell);
        timeline.record_sim(&sim);
        (timeline, &window.path)
    });
    cell.events().set_capacity(config.kept_events);
    sim.log().set_capacity(config.kept_events);
    let tally = Arc::new(Mutex::new(Tally::default()));
    let folded = Arc::clone(&tally);
    cell.events()
        .subscribe(move |event| lock(&folded).cell(event));
    let folded = Arc::clone(&tally);
    sim.log().subscribe(move |event| lock(&folded).sim(event));
    let ports = CellPorts::declare(&cell, config.feeder).map_err(CellErrors::from)?;
    let deaths: [ReleaseDeath; 2] = Default::default();
    let cycle_times: [SharedCycleTimes; 2] = Default::default();
    let waits: SharedWaits = Arc::default();
    inject(config, &sim, &deaths);
    let devices = Devices::Local(sim.clone());

    // The load-time check, over every module the cell will run (children included).
    let mut declarations = Vec::new();
    let line_modules = |line: Line| LineModules {
        line,
        run: 0,
        feeder: config.feeder,
        ports: ports.clone(),
        devices: devices.clone(),
        death: Arc::clone(&deaths[line.index()]),
        history: Arc::clone(&cycle_times[line.index()]),
        waits: Arc::clone(&waits),
    };
    for line in Line::ALL {
        declarations.extend(line_modules(line).declarations());
    }
    match config.feeder {
        FeederPolicy::Arbiter => declarations.push(feeder_monitor(&ports).declaration()),
        FeederPolicy::Coordinator => declarations.push(feeder_coordinator(&ports).declaration()),
        FeederPolicy::Appendix => {}
    }
    cell.check(&declarations)?;

    sim.spawn();
    let _ros2 = match &config.ros2 {
        Some(endpoint) => Some(ros2::serve(endpoint, &sim, &cell, Arc::clone(&tally)).await?),
        None => None,
    };
    match config.feeder {
        FeederPolicy::Arbiter => {
            cell.start(feeder_monitor(&ports))?;
        }
        FeederPolicy::Coordinator => {
            cell.start(feeder_coordinator(&ports))?;
        }
        FeederPolicy::Appendix => {}
    }
    for line in Line::ALL {
        line_modules(line).start(&cell)?;
    }

    let total = Duration::from_secs_f64(config.hours * 3600.0);
    let end = Instant::from_start(total);
    match driver {
        Some(virtual_clock) => {
            let chunk = Duration::from_secs(60);
            let bar = progress_bar(config.progress, total);
            let mut reached = Instant::ZERO;
            while reached < end {
                reached = drive(&virtual_clock, (reached + chunk).min(end)).await;
                bar.set_position(reached.since_start().as_secs());
            }
            bar.finish_and_clear();
        }
        None => tokio::time::sleep(total).await,
    }
    if let Some(recorder) = &recorder {
        recorder
            .finish()
            .map_err(|error| output(recorder.path(), error))?;
    }
    if let Some((timeline, path)) = &timeline {
        timeline
            .render_svg(path)
            .map_err(|error| output(path, error))?;
    }
    let waits = *waits.lock().unwrap_or_else(PoisonError::into_inner);
    let cycle_times = cycle_times.each_ref().map(|history| {
        history
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .clone()
    });
    let tally = lock(&tally).clone();
    Ok(RunRecord::measured(
        config,
        tally,
        &sim,
        &cell,
        waits,
        cycle_times,
        total,
    ))
}

impl RunRecord {
    /// The record of a run that simulated `simulated` with `sim`, its modules in `cell` (or,
    /// across processes, the world's), and what was folded from both; its wall time is set
    /// by the caller.
    pub(crate) fn measured(
        config: &CellConfig,
        tally: Tally,
        sim: &Sim,
        cell: &Cell,
        waits: [ZoneWaits; 2],
        cycle_times: [CycleTimeHistory; 2],
        simulated: Duration,
    ) -> Self {
        Self {
            config: config.clone(),
            tally,
            sim_events: sim.log().snapshot(),
            cell_events: cell.events().snapshot(),
            pallets_left: sim.pallets(),
            waits,
            tree: cell.tree(),
            feeders: sim.feeders(),
            robot_times: sim.robot_times(),
            closest_in_zone: sim.closest_in_zone(),
            cycle_times,
            simulated,
            wall: Duration::ZERO,
            lateness: Vec::new(),
            outages: Vec::new(),
            hosts: None,
        }
    }
}

/// The modules of one line, and what they share with the run: everything needed to
/// declare them for the wiring check and to start them, in one process or in a line's own.
pub(crate) struct LineModules {
    pub(crate) line: Line,
    /// Which run of the line's process this is: 0 in one process, counted by the world
    /// across processes.
    pub(crate) run: u32,
    pub(crate) feeder: FeederPolicy,
    pub(crate) ports: CellPorts,
    pub(crate) devices: Devices,
    pub(crate) death: ReleaseDeath,
    pub(crate) history: SharedCycleTimes,
    pub(crate) waits: SharedWaits,
}

impl LineModules {
    /// GATE, LOAD_IT (with its children LOAD_CARD and SCREW_IN_CARD) and CHIP_IT, declared.
    pub(crate) fn declarations(&self) -> Vec<ModuleDecl> {
        let (line, lines) = (self.line, &self.ports.lines[self.line.index()]);
        let history = Arc::clone(&self.history);
        let waits = Arc::clone(&self.waits);
        vec![
            gate(line, lines, &self.devices, Arc::clone(&self.death), history).declaration(),
            load_it(line, lines, &self.devices).declaration(),
            load_card(line, lines, &self.devices).declaration(),
            screw_in_card(line, lines, &self.devices).declaration(),
            chip_it(
                line,
                self.run,
                self.feeder,
                &self.ports,
                &self.devices,
                waits,
            )
            .declaration(),
        ]
    }

    /// Starts the line's modules in `cell`: GATE and CHIP_IT supervised, restarted as a
    /// cell engineer would want; LOAD_IT starts its own children.
    pub(crate) fn start(self, cell: &Cell) -> Result<(), CellErrors> {
        let policy = RestartPolicy::restart(3, Duration::from_secs(5));
        let (line, lines) = (self.line, self.ports.lines[self.line.index()].clone());
        let (gate_lines, gate_devices) = (lines.clone(), self.devices.clone());
        let (death, history) = (self.death, self.history);
        cell.supervise(policy, move || {
            gate(
                line,
                &gate_lines,
                &gate_devices,
                Arc::clone(&death),
                Arc::clone(&history),
            )
        })?;
        cell.start(load_it(line, &lines, &self.devices))?;
        let (ports, devices, waits, feeder) = (self.ports, self.devices, self.waits, self.feeder);
        let run = self.run;
        cell.supervise(policy, move || {
            chip_it(line, run, feeder, &ports, &devices, Arc::clone(&waits))
        })?;
        Ok(())
    }
}

pub(crate) fn inject(config: &CellConfig, sim: &Sim, deaths: &[ReleaseDeath; 2]) {
    for fault in &config.faults {
        let at = Instant::from_start(fault.at);
        let kind = match fault.kind {
            CellFaultKind::ReleaseDies(line) => {
                *deaths[line.index()]
                    .lock()
                    .unwrap_or_else(PoisonError::into_inner) = Some(at);
                continue;
            }
            CellFaultKind::RobotFault(line) => FaultKind::Robot(RobotId::new(line, Role::ChipIt)),
            CellFaultKind::FeederEmpty(feeder) => FaultKind::FeederEmpty(feeder),
            CellFaultKind::PalletJam(line) => FaultKind::Jam(line, Station::Load),
        };
        sim.inject(Fault { at, kind });
    }
}

/// A bar of simulated seconds with its rate and the time left, drawn on stderr only when it
/// is a terminal (indicatif hides it otherwise) and the run asked for one.
fn progress_bar(wanted: bool, total: Duration) -> ProgressBar {
    let target = if wanted {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    };
    let bar = ProgressBar::with_draw_target(Some(total.as_secs()), target);
    if let Ok(style) =
        ProgressStyle::with_template("{bar:40} {pos}/{len} simulated s, {per_sec}, {eta} left")
    {
        bar.set_style(style);
    }
    bar
}

pub(crate) fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    // A fold is one call; a panic in it leaves the tally as the last whole event left it.
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
}
