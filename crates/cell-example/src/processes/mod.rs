//! The chip cell split over processes (`chip_cell --processes`): the world — the simulation,
//! WORLD serving the devices, and the feeder zone's keeper (FEEDER_MONITOR under the
//! arbiter's policy, FEEDER_COORDINATOR under the coordinator's) — in the process started by
//! the command, and each line's modules (GATE, LOAD_IT, LOAD_CARD, SCREW_IN_CARD, CHIP_IT)
//! in a process of its own, which the world starts. The lines reach their robots, gate and
//! relays through the world's device ports (a chip robot's sweep, too, is computed there),
//! and the feeder zone through the keeper's ports or, under the Appendix's policy, through
//! each other's SHARE_FEEDER, all carried by iceoryx2 (`imrs-ipc`), or with
//! `--transport zenoh` by zenoh (`imrs-zenoh`), each line then a host of its own (a network
//! namespace, where they can be made); the modules' code is that of the single-process
//! cell.
//!
//! Time: every process runs on the wall clock sped up by `--speed`, from one epoch the world
//! chooses and hands to the lines when it starts them, so the processes agree on one time
//! with no message between them. Virtual time does not cross processes: it moves only when
//! the whole cell is idle, which no single process can see. A run across processes is
//! therefore not reproducible to the step, as a single-process run is; its figures are
//! those of the same cell, measured by the same simulation.
//!
//! Each process measures how late its runtime wakes a timer ([`crate::lateness`]): that
//! delay, times the speed, is lived in the cell's time, and the report says the worst, so
//! that a timeout a machine too loaded for `--speed` caused can be told from one the cell
//! did.
//!
//! Each line writes its modules' figures so far (timeouts, alarms, restarts, deadlocks,
//! waits for the zone, GATE's cycle times, its lateness) as one JSON line on its standard
//! output every minute of the cell's time, and at the end; the world folds them into its
//! own and reports as a single process does. A line whose world dies sees its standard
//! input close and exits.
//!
//! The world supervises the lines' processes, as a module's supervisor does its tasks: a
//! line's process that dies before the end (killed, crashed) is started again, at most
//! [`RESTARTS`] times a line, and the other line goes on. Each run of a line's process is
//! numbered, and its device calls and words to the zone carry the number. Before the next
//! run starts, the world stops WORLD taking calls of the dead run (one a device had already
//! taken is let end), drives the dead line's chip robot home through the robot's own port,
//! takes off as scrap the pallets the dead line's stations held (in a state nobody knows),
//! and tells the feeder zone's keeper on LINE_DOWN: FEEDER_MONITOR then frees the zone if
//! the dead line held it, FEEDER_COORDINATOR lets go of what the dead line's chip robot held
//! or asked for, and neither heeds a word of the dead run (see [`crate::zone_asker`]). The
//! report shows each outage: when, how long, and the pallets scrapped. Under the
//! Appendix's policy, with no keeper between the lines, the dead line's twin has no
//! permission to enter the zone until the next run answers its queries.

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use imrs_core::CellErrors;
use imrs_core::prelude::*;
use imrs_ipc::Remote;
use imrs_ports::{End, Instant, RealClock, SharedClock, usage};
use imrs_sim::{DeviceError, Line, RobotId, Role, Sim, SimConfig, Target};
#[cfg(feature = "zenoh")]
use imrs_zenoh::Host;
use serde_json::{Value, json};
use tokio::sync::mpsc::{UnboundedReceiver, UnboundedSender, unbounded_channel};

use crate::alarms::AlarmKind;
use crate::carrier::{Carrier, CarrierError, Crossing, Exported, Imported};
use crate::chip::{SharedWaits, ZoneWaits, feeder_coordinator, feeder_monitor};
use crate::config::{CellConfig, LineProcess, Transport};
use crate::devices::{
    Answer, Device, DeviceAnswer, DeviceCall, DevicePorts, Devices, LineRuns, Op, RemoteDevices,
    world,
};
use crate::faults::{CellFault, CellFaultKind, inject};
use crate::feeder_policy::FeederPolicy;
use crate::gate::{CycleTimeHistory, ReleaseDeath, SharedCycleTimes};
use crate::lateness::Lateness;
use crate::line_modules::LineModules;
use crate::names::{
    FEEDER_COORDINATOR, FEEDER_MONITOR, LINE_SUPERVISOR, LineNames, ZONE_FREE, ZONE_RELEASE,
    ZONE_REQUEST, ZONE_RESERVE,
};
use crate::outage::Outage;
use crate::ports::{CellPorts, ZoneLink};
use crate::run_error::RunError;
use crate::run_record::RunRecord;
use crate::tally::{Tally, lock};

/// How long the world gives the lines' processes to start before the epoch.
const STARTUP: Duration = Duration::from_secs(2);

/// How long the world waits, in wall time, for a line to say it is ready, and for its
/// figures once the run has ended.
const PATIENCE: Duration = Duration::from_secs(30);

/// How many times, in one run of the cell, the world starts a line's process again after
/// it died, before it gives up and fails the run.
pub const RESTARTS: u32 = 3;

/// How often, in the cell's time, a line's process sends its figures so far: a line that
/// dies loses at most this much of them.
const SNAPSHOT_PERIOD: Duration = Duration::from_secs(60);

fn refused(process: &str, why: impl std::fmt::Display) -> RunError {
    RunError::Processes {
        process: process.into(),
        why: why.to_string(),
    }
}

/// What `--processes` cannot do yet, refused before anything starts.
pub(crate) fn check_config(config: &CellConfig) -> Result<(), RunError> {
    let unsupported = if config.record.is_some() || config.timeline.is_some() {
        Some("--record and --timeline: a recording sees one process's modules")
    } else if config.show_tree {
        Some("--tree: each process has a module tree of its own")
    } else if config.realtime {
        Some("--realtime: a run across processes is on the wall clock already (see --speed)")
    } else if config.transport == Transport::Zenoh && config.feeder == FeederPolicy::Appendix {
        Some(
            "--transport zenoh with --feeder appendix: under the Appendix's policy the lines \
             ask each other, and over zenoh each line's host reaches the world's only",
        )
    } else {
        None
    };
    match unsupported {
        Some(why) => Err(refused("world", format!("not with --processes: {why}"))),
        None => Ok(()),
    }
}

fn runtime(process: &str) -> Result<tokio::runtime::Runtime, RunError> {
    tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .map_err(|error| refused(process, format!("no tokio runtime: {error}")))
}

fn clock(process: &str, epoch: SystemTime, speed: f64) -> Result<SharedClock, RunError> {
    match RealClock::from_epoch(epoch, speed) {
        Some(clock) => Ok(Arc::new(clock)),
        None => Err(refused(
            process,
            format!(
                "--speed {speed}: expected 1 to {}, with an epoch within a year",
                RealClock::MAX_SPEED
            ),
        )),
    }
}

fn carried<E: std::fmt::Display>(process: &str) -> impl Fn(E) -> RunError + '_ {
    move |error| refused(process, error)
}

fn process_name(line: Line) -> &'static str {
    match line {
        Line::A => "line A",
        Line::B => "line B",
    }
}

mod line_figures;
mod line_side;
mod world_side;

use line_figures::{absorb, figures};
pub use line_side::run_line;
pub use world_side::run_world;
