//! Running the cell: on virtual time (the default) or on the wall clock.

use std::io::{IsTerminal, Write};
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
use std::time::Duration;

use imrs_sim::imrs_core::imrs_ports::{Instant, RealClock, SharedClock, VirtualClock};
use imrs_sim::imrs_core::prelude::*;
use imrs_sim::imrs_core::{CellErrors, Log, ModuleTree, time::drive};
use imrs_sim::{
    Fault, FaultKind, Line, PalletId, RobotId, Role, Sim, SimConfig, SimEvent, Station,
};

use crate::chip::{FeederPolicy, SharedWaits, ZoneWaits, chip_it, feeder_monitor};
use crate::faults::{CellFault, CellFaultKind};
use crate::gate::{ReleaseDeath, gate};
use crate::load::{load_card, load_it, screw_in_card};
use crate::ports::CellPorts;
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
    /// Print the module tree (seed 000 §2) before the report.
    pub show_tree: bool,
    /// How many of the most recent events each log keeps in memory for the record (the
    /// report is folded from every event as it comes, whatever this is).
    pub kept_events: usize,
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
    /// Simulated time.
    pub simulated: Duration,
    /// Wall time the run took.
    pub wall: Duration,
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
            Self::FaultAfterEnd { fault, hours } => write!(
                f,
                "--fault {fault}: set for after the run's end ({hours} h), so it would never fire; \
                 run longer with --hours or set it earlier"
            ),
        }
    }
}

impl std::error::Error for RunError {}

/// Runs the cell as `config` says. Fails, naming every problem, if the cell is wired wrong.
pub fn run(config: &CellConfig) -> Result<RunRecord, RunError> {
    let hours_ok = config.hours.is_finite() && config.hours > 0.0 && config.hours <= MAX_HOURS;
    if !hours_ok {
        return Err(RunError::Hours(config.hours));
    }
    let end = Duration::from_secs_f64(config.hours * 3600.0);
    if let Some(late) = config.faults.iter().find(|fault| fault.at > end) {
        return Err(RunError::FaultAfterEnd {
            fault: late.to_string(),
            hours: config.hours,
        });
    }
    let wall = std::time::Instant::now();
    let mut record = if config.realtime {
        let runtime = tokio::runtime::Builder::new_multi_thread()
            .enable_all()
            .build()
            .expect("a tokio runtime starts");
        runtime
            .block_on(simulate(config, Arc::new(RealClock::new()), None))
            .map_err(RunError::Wiring)
    } else {
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .start_paused(true)
            .build()
            .expect("a tokio runtime starts");
        let clock = VirtualClock::new();
        runtime
            .block_on(simulate(config, Arc::new(clock.clone()), Some(clock)))
            .map_err(RunError::Wiring)
    }?;
    record.wall = wall.elapsed();
    Ok(record)
}

async fn simulate(
    config: &CellConfig,
    clock: SharedClock,
    driver: Option<VirtualClock>,
) -> Result<RunRecord, CellErrors> {
    let cell = Cell::new(clock.clone());
    let sim = Sim::new(SimConfig::seeded(config.seed), clock.clone());
    cell.events().set_capacity(config.kept_events);
    sim.log().set_capacity(config.kept_events);
    let tally = Arc::new(Mutex::new(Tally::default()));
    let folded = Arc::clone(&tally);
    cell.events()
        .subscribe(move |event| lock(&folded).cell(event));
    let folded = Arc::clone(&tally);
    sim.log().subscribe(move |event| lock(&folded).sim(event));
    let ports = CellPorts::declare(&cell, config.feeder == FeederPolicy::Arbiter)?;
    let deaths: [ReleaseDeath; 2] = Default::default();
    let waits: SharedWaits = Arc::default();
    inject(config, &sim, &deaths);

    // The load-time check, over every module the cell will run (children included).
    let mut declarations = Vec::new();
    for line in Line::ALL {
        let lines = &ports.lines[line.index()];
        declarations.push(gate(line, lines, &sim, Arc::clone(&deaths[line.index()])).declaration());
        declarations.push(load_it(line, lines, &sim).declaration());
        declarations.push(load_card(line, lines, &sim).declaration());
        declarations.push(screw_in_card(line, lines, &sim).declaration());
        declarations
            .push(chip_it(line, config.feeder, &ports, &sim, Arc::clone(&waits)).declaration());
    }
    if config.feeder == FeederPolicy::Arbiter {
        declarations.push(feeder_monitor(&ports).declaration());
    }
    cell.check(&declarations)?;

    sim.spawn();
    let policy = RestartPolicy::restart(3, Duration::from_secs(5));
    if config.feeder == FeederPolicy::Arbiter {
        cell.start(feeder_monitor(&ports))?;
    }
    for line in Line::ALL {
        let (lines, sim) = (ports.lines[line.index()].clone(), sim.clone());
        let death = Arc::clone(&deaths[line.index()]);
        let (gate_lines, gate_sim) = (lines.clone(), sim.clone());
        cell.supervise(policy, move || {
            gate(line, &gate_lines, &gate_sim, Arc::clone(&death))
        })?;
        cell.start(load_it(line, &lines, &sim))?;
        let (all_ports, chip_sim, chip_waits, feeder) = (
            ports.clone(),
            sim.clone(),
            Arc::clone(&waits),
            config.feeder,
        );
        cell.supervise(policy, move || {
            chip_it(line, feeder, &all_ports, &chip_sim, Arc::clone(&chip_waits))
        })?;
    }

    let total = Duration::from_secs_f64(config.hours * 3600.0);
    let end = Instant::from_start(total);
    match driver {
        Some(virtual_clock) => {
            let chunk = Duration::from_secs(60);
            let show = config.progress && std::io::stderr().is_terminal();
            let mut reached = Instant::ZERO;
            while reached < end {
                reached = drive(&virtual_clock, (reached + chunk).min(end)).await;
                if show {
                    progress(reached, end);
                }
            }
            if show {
                eprintln!();
            }
        }
        None => tokio::time::sleep(total).await,
    }
    let waits = *waits.lock().unwrap_or_else(PoisonError::into_inner);
    Ok(RunRecord {
        config: config.clone(),
        tally: lock(&tally).clone(),
        sim_events: sim.log().snapshot(),
        cell_events: cell.events().snapshot(),
        pallets_left: sim.pallets(),
        waits,
        tree: cell.tree(),
        simulated: total,
        wall: Duration::ZERO,
    })
}

fn inject(config: &CellConfig, sim: &Sim, deaths: &[ReleaseDeath; 2]) {
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

fn progress(reached: Instant, end: Instant) {
    let share = reached.since_start().as_secs_f64() / end.since_start().as_secs_f64().max(1e-9);
    let filled = (share * 40.0).round() as usize;
    eprint!(
        "\r[{}{}] {:>5.1}% of the simulated run",
        "#".repeat(filled),
        ".".repeat(40 - filled.min(40)),
        share * 100.0
    );
    let _ = std::io::stderr().flush();
}

fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    // A fold is one call; a panic in it leaves the tally as the last whole event left it.
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
}
