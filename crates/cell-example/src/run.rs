//! Running the cell: on virtual time (the default) or on the wall clock.

use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use imrs_core::prelude::*;
use imrs_core::{CellErrors, time::drive};
use imrs_ports::{Instant, RealClock, SharedClock, VirtualClock};
use imrs_record::{Recorder, Timeline};
use imrs_sim::{Line, Sim, SimConfig};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use crate::chip::{SharedWaits, feeder_coordinator, feeder_monitor};
use crate::config::{CellConfig, MAX_HOURS};
use crate::devices::Devices;
use crate::faults::inject;
use crate::feeder_policy::FeederPolicy;
use crate::gate::{ReleaseDeath, SharedCycleTimes};
use crate::line_modules::LineModules;
use crate::ports::CellPorts;
use crate::processes;
#[cfg(feature = "ros2")]
use crate::ros2;
use crate::run_error::{RunError, output};
use crate::run_record::RunRecord;
use crate::tally::{Tally, lock};

/// What [`run`] refuses before it simulates anything: hours out of range, a fault set
/// after the end, or a layer this build left out.
pub fn refused(config: &CellConfig) -> Option<RunError> {
    #[cfg(not(feature = "ros2"))]
    if config.ros2.is_some() {
        return Some(RunError::Ros2(crate::cli::not_built("--ros2", "ros2")));
    }
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
    inject(&config.faults, &sim, &deaths);
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
    #[cfg(feature = "ros2")]
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
