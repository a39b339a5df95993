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
use imrs_zenoh::Host;
use imrs_zenoh::netns::Netns;
use serde_json::{Value, json};
use tokio::sync::mpsc::{UnboundedReceiver, UnboundedSender, unbounded_channel};

use crate::alarms::AlarmKind;
use crate::carrier::{Carrier, CarrierError, Crossing, Exported, Imported};
use crate::chip::{FeederPolicy, SharedWaits, ZoneWaits, feeder_coordinator, feeder_monitor};
use crate::devices::{
    Answer, Device, DeviceAnswer, DeviceCall, DevicePorts, Devices, LineRuns, Op, RemoteDevices,
    world,
};
use crate::faults::{CellFault, CellFaultKind};
use crate::gate::{CycleTimeHistory, ReleaseDeath, SharedCycleTimes};
use crate::lateness::Lateness;
use crate::names::{
    FEEDER_COORDINATOR, FEEDER_MONITOR, LINE_SUPERVISOR, LineNames, ZONE_FREE, ZONE_RELEASE,
    ZONE_REQUEST, ZONE_RESERVE,
};
use crate::outage::Outage;
use crate::ports::{CellPorts, ZoneLink};
use crate::run::{CellConfig, LineModules, RunError, RunRecord, inject, lock};
use crate::tally::Tally;

/// How much faster than the wall clock a run across processes goes, unless `--speed` says.
pub const DEFAULT_SPEED: f64 = 60.0;

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

/// What carries the ports between the processes of a run across processes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Transport {
    /// iceoryx2: the processes of one host, through shared memory.
    Ipc,
    /// zenoh: each process a host of its own (a network namespace, where they can be made).
    Zenoh,
}

impl Transport {
    /// Its name, as `--transport` takes it.
    pub fn name(self) -> &'static str {
        match self {
            Transport::Ipc => "ipc",
            Transport::Zenoh => "zenoh",
        }
    }
}

/// What makes a process one line's part of a cell run across processes: the line, the
/// cell's name, where the world's host is (over zenoh), and the moment its time starts.
#[derive(Debug, Clone, PartialEq)]
pub struct LineProcess {
    /// The line whose modules it runs.
    pub line: Line,
    /// Which run of the line's process it is: 0 first, then one more each time the world
    /// starts it again.
    pub run: u32,
    /// The cell's name, from which every port's service name (or key) is derived.
    pub remote: String,
    /// Over zenoh, the world's host's endpoint, which the line's host connects to; over
    /// iceoryx2, `None`.
    pub connect: Option<String>,
    /// When the cell's time is zero, on the system clock.
    pub epoch: SystemTime,
}

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

/// Over zenoh, where the lines' hosts are: a network namespace each, joined to the world's
/// by a veth link, or (where namespaces cannot be made) this host's loopback.
struct Hosts {
    /// Per line: its namespace, if made.
    netns: Vec<Netns>,
    /// Per line: the world's endpoint as the line reaches it.
    endpoints: [String; 2],
    /// How the report names them.
    described: String,
}

/// The world's side of what carries the ports: iceoryx2 under the cell's name, or a zenoh
/// host listening for the lines' hosts.
async fn world_carrier(
    config: &CellConfig,
    cell: &str,
) -> Result<(Carrier, Option<Hosts>), RunError> {
    match config.transport {
        Transport::Ipc => Ok((
            Carrier::Ipc(Remote::new(cell).map_err(carried("world"))?),
            None,
        )),
        Transport::Zenoh => {
            let netns = Netns::make(0).and_then(|a| Ok(vec![a, Netns::make(1)?]));
            // The world listens only where its lines reach it: on each namespace's link, or
            // on loopback. A port found free may be taken before it is listened on: another
            // is tried.
            let mut tries = 0;
            loop {
                tries += 1;
                let port = free_port()?;
                let addresses: Vec<&str> = match &netns {
                    Ok(netns) => netns.iter().map(Netns::outside_address).collect(),
                    Err(_) => vec!["127.0.0.1"],
                };
                let mut builder = Host::builder(cell);
                for address in &addresses {
                    builder = builder.listen(format!("tcp/{address}:{port}"));
                }
                match builder.open().await {
                    Ok(host) => return Ok((Carrier::Zenoh(host), Some(hosts(netns, port)))),
                    Err(error) if tries >= 3 => return Err(refused("world", error)),
                    Err(_) => {}
                }
            }
        }
    }
}

/// A port of this host free now.
fn free_port() -> Result<u16, RunError> {
    let probe = std::net::TcpListener::bind("0.0.0.0:0")
        .map_err(|error| refused("world", format!("no free port: {error}")))?;
    Ok(probe
        .local_addr()
        .map_err(|error| refused("world", error))?
        .port())
}

/// The lines' hosts: in `netns`, or on loopback (said loudly) where they could not be
/// made; the world listening on `port`.
fn hosts(netns: Result<Vec<Netns>, String>, port: u16) -> Hosts {
    match netns {
        Ok(netns) => Hosts {
            endpoints: [0, 1].map(|i| format!("tcp/{}:{port}", netns[i].outside_address())),
            netns,
            described: "each a host of its own (a network namespace, joined to the \
                                world's by a veth link)"
                .into(),
        },
        Err(why) => {
            eprintln!(
                "\n*** HOSTS ON LOOPBACK, NOT APART: network namespaces could not be \
                         made ({why}); the lines run as processes of this host, over zenoh \
                         on 127.0.0.1 ***\n"
            );
            Hosts {
                netns: Vec::new(),
                endpoints: [0, 1].map(|_| format!("tcp/127.0.0.1:{port}")),
                described: format!(
                    "ON LOOPBACK, not hosts apart (network namespaces could not be \
                             made: {why})"
                ),
            }
        }
    }
}

/// Runs the cell across three processes — this one the world's — and folds the lines'
/// figures into one record.
pub fn run_world(config: &CellConfig) -> Result<RunRecord, RunError> {
    check_config(config)?;
    let wall = std::time::Instant::now();
    let mut record = runtime("world")?.block_on(world_process(config))?;
    record.wall = wall.elapsed();
    Ok(record)
}

async fn world_process(config: &CellConfig) -> Result<RunRecord, RunError> {
    let nanos = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .unwrap_or_default()
        .subsec_nanos();
    // Unique on this host: two runs never meet.
    let cell_name = format!("chip_cell-{}-{nanos}", std::process::id());
    // The hosts are made before the epoch is chosen: the lines get all of STARTUP.
    let (carrier, hosts) = world_carrier(config, &cell_name).await?;
    let epoch = SystemTime::now() + STARTUP;
    let clock = clock("world", epoch, config.speed)?;
    let lateness = Lateness::probe(clock.sleep_until(Instant::ZERO));
    let cell = Cell::new(clock.clone());
    let sim = Sim::new(SimConfig::seeded(config.seed), clock.clone());
    cell.events().set_capacity(config.kept_events);
    sim.log().set_capacity(config.kept_events);
    let tally = Arc::new(Mutex::new(Tally::default()));
    let folded = Arc::clone(&tally);
    sim.log().subscribe(move |event| lock(&folded).sim(event));
    let folded = Arc::clone(&tally);
    cell.events()
        .subscribe(move |event| lock(&folded).cell(event));
    // A line's RELEASE dies in the line's process; the simulation's faults happen here.
    inject(config, &sim, &Default::default());

    let ports = CellPorts::new(&clock);
    // The arbiter, or the coordinator, runs here; under the Appendix's policy the lines ask
    // each other.
    let (arbiter, coordinator) = (
        config.feeder == FeederPolicy::Arbiter,
        config.feeder == FeederPolicy::Coordinator,
    );
    let asked: Vec<_> = [&ports.zone_request, &ports.zone_release]
        .into_iter()
        .filter_map(ZoneLink::here)
        .filter(|_| arbiter)
        .collect();
    let free = ports.zone_free.here().filter(|_| coordinator);
    let reserve = ports.zone_reserve.here().filter(|_| coordinator);
    let devices = DevicePorts::declare(&clock);
    for port in &asked {
        cell.declare(*port).map_err(CellErrors::from)?;
    }
    if arbiter {
        cell.declare(&ports.line_down).map_err(CellErrors::from)?;
    }
    if coordinator {
        cell.declare(&ports.coordinator_down)
            .map_err(CellErrors::from)?;
    }
    if let Some(port) = free {
        cell.declare(port).map_err(CellErrors::from)?;
    }
    if let Some(port) = reserve {
        cell.declare(port).map_err(CellErrors::from)?;
    }
    for port in devices.iter() {
        cell.declare(port).map_err(CellErrors::from)?;
    }
    let keeper = match config.feeder {
        FeederPolicy::Arbiter => Some(feeder_monitor(&ports)),
        FeederPolicy::Coordinator => Some(feeder_coordinator(&ports)),
        FeederPolicy::Appendix => None,
    };
    // The run of each line's process whose device calls WORLD carries out.
    let runs: LineRuns = Arc::default();
    let mut declarations = vec![world(&devices, &sim, &runs).declaration()];
    declarations.extend(keeper.iter().map(ModuleSpec::declaration));
    cell.check(&declarations)?;
    // Exported before a line starts: a line imports them at once.
    let mut exported: Vec<Exported> = Vec::new();
    for port in asked {
        exported.push(carrier.export(port).await.map_err(carried("world"))?);
    }
    if let Some(port) = free {
        exported.push(carrier.export(port).await.map_err(carried("world"))?);
    }
    if let Some(port) = reserve {
        exported.push(carrier.export(port).await.map_err(carried("world"))?);
    }
    for port in devices.iter() {
        exported.push(carrier.export(port).await.map_err(carried("world"))?);
    }
    sim.spawn();
    cell.start(world(&devices, &sim, &runs))?;
    if let Some(keeper) = keeper {
        cell.start(keeper)?;
    }

    // The world's hands on a dead line: its chip robot's port, and the zone keeper's ear.
    // It holds a place on every device port under every policy; it restarts a line under
    // the arbiter's and the coordinator's.
    let supervisor = Supervisor::new(&devices, &ports, &runs, config.feeder)?;
    let (tell, mut hear) = unbounded_channel();
    let mut lines = Lines(Vec::new());
    let start = |line: Line, run: u32, faults: &[CellFault]| {
        let place = LinePlace {
            cell: &cell_name,
            netns: hosts
                .as_ref()
                .and_then(|hosts| hosts.netns.get(line.index())),
            connect: hosts
                .as_ref()
                .map(|hosts| hosts.endpoints[line.index()].as_str()),
        };
        start_line(config, line, run, &place, epoch, faults, tell.clone())
    };
    for line in Line::ALL {
        lines.0.push((line, 0, start(line, 0, &config.faults)?));
    }
    // Over zenoh, each line's host is watched: one cut off is treated as one that died.
    let mut watchers = Vec::new();
    if let Carrier::Zenoh(_) = &carrier {
        for line in Line::ALL {
            let gate = Device::Gate(line);
            let exported_gate = exported
                .iter()
                .find_map(|exported| match exported {
                    Exported::Zenoh(exported) if exported.port() == gate.port() => Some(exported),
                    _ => None,
                })
                .ok_or_else(|| refused("world", format!("port {} is not exported", gate.port())))?;
            let mut watch = exported_gate
                .watch_user(&gate.user())
                .await
                .map_err(carried("world"))?;
            let tell = tell.clone();
            watchers.push(tokio::spawn(async move {
                loop {
                    watch.gone().await;
                    if tell.send((line, UNSEEN, Said::Unseen)).is_err() {
                        return;
                    }
                }
            }));
        }
    }
    // A line that cannot start (or dies before it is first ready) fails the run: there is
    // nothing yet to go on from.
    for _ in Line::ALL {
        match hear_from(&mut hear).await? {
            (_, _, Said::Ready) => {}
            (line, _, other) => return Err(other.refusal(line, "ready")),
        }
    }

    let total = Duration::from_secs_f64(config.hours * 3600.0);
    let mut runs = [0_u32; 2];
    // Per line: the latest figures of its run now, and the last of each run that died.
    let mut latest: [Option<Value>; 2] = Default::default();
    let mut banked: [Vec<Value>; 2] = Default::default();
    let mut finals: [Option<Value>; 2] = Default::default();
    let mut outages: Vec<Outage> = Vec::new();
    // Per line: whether its run now has said it is ready, and whether its host was cut off.
    let mut ready = [true; 2];
    let mut cut_off = [false; 2];
    // Until the end, a line that dies is started again (or fails the run, past its
    // restarts); then each line's figures are due.
    let end = clock.sleep_until(Instant::from_start(total));
    tokio::pin!(end);
    let mut ended = false;
    while finals.iter().any(Option::is_none) {
        let (line, run, said) = if ended {
            hear_from(&mut hear).await?
        } else {
            tokio::select! {
                () = &mut end => {
                    ended = true;
                    continue;
                }
                said = hear.recv() => said.ok_or_else(|| refused("world", "the lines' processes are gone"))?,
            }
        };
        let i = line.index();
        // A line's host out of sight: its run, ready and not yet seen dead, is stopped, and
        // its end is a death. (A run not yet ready is what started after a death.)
        if let Said::Unseen = said {
            if !ended && ready[i] && finals[i].is_none() {
                cut_off[i] = true;
                lines.stop(line, runs[i]);
            }
            continue;
        }
        // The last words of a run that has died, heard late.
        if run != runs[i] {
            continue;
        }
        match said {
            Said::Ready => {
                ready[i] = true;
                let now = clock.now().since_start().as_secs_f64();
                if let Some(outage) = outages
                    .iter_mut()
                    .rev()
                    .find(|outage| outage.line == line && outage.back.is_none())
                {
                    outage.back = Some(now);
                }
            }
            Said::Snapshot(figures) => latest[i] = Some(figures),
            Said::Figures(figures) if finals[i].is_none() => finals[i] = Some(figures),
            // A line that sent its figures may end before the other sends its own.
            Said::Ended(_) if finals[i].is_some() => {}
            // A line's last words cut short by its death: the death follows.
            Said::Garbled(text) => {
                eprintln!(
                    "{}: said {text:?}, which the world does not read",
                    process_name(line)
                );
            }
            // A line that dies after the end, before its figures: its figures of the last
            // minute stand for them.
            Said::Ended(_) | Said::Failed(_) if ended && (latest[i].is_some() || runs[i] > 0) => {
                finals[i] = Some(latest[i].take().unwrap_or_else(|| {
                    // A run that died before its first minute: nothing more to count.
                    figures(
                        &Tally::default(),
                        &ZoneWaits::default(),
                        &CycleTimeHistory::default(),
                        Duration::ZERO,
                    )
                }));
            }
            Said::Ended(_) | Said::Failed(_) if !ended => {
                if runs[i] >= RESTARTS {
                    return Err(refused(
                        process_name(line),
                        format!(
                            "died {} times: the world starts a line again at most {RESTARTS} times",
                            runs[i] + 1
                        ),
                    ));
                }
                let died = clock.now();
                let next = runs[i] + 1;
                banked[i].extend(latest[i].take());
                // A run that said it failed may still be ending: it goes first.
                lines.stop(line, runs[i]);
                let scrapped = supervisor.take_over(line, next, &sim).await? as u32;
                runs[i] = next;
                // Faults still to come; those past happened to the run that died.
                let faults: Vec<CellFault> = config
                    .faults
                    .iter()
                    .filter(|fault| Instant::from_start(fault.at) > clock.now())
                    .cloned()
                    .collect();
                lines.0.push((line, next, start(line, next, &faults)?));
                ready[i] = false;
                let cut = std::mem::take(&mut cut_off[i]);
                // A run that died before it was ready prolongs the outage it was to end.
                match outages
                    .iter_mut()
                    .find(|outage| outage.line == line && outage.back.is_none())
                {
                    Some(outage) => {
                        outage.run = next;
                        outage.scrapped += scrapped;
                    }
                    None => outages.push(Outage {
                        line,
                        cut_off: cut,
                        died: died.since_start().as_secs_f64(),
                        back: None,
                        run: next,
                        scrapped,
                    }),
                }
            }
            other => return Err(other.refusal(line, "its figures")),
        }
    }
    for watcher in watchers {
        watcher.abort();
    }
    lines.ended().await;
    drop(exported);
    let mut tally = lock(&tally).clone();
    let mut waits = [ZoneWaits::default(); 2];
    let mut cycle_times: [CycleTimeHistory; 2] = Default::default();
    let mut late = [Duration::ZERO; 2];
    for line in Line::ALL {
        let i = line.index();
        // The runs that died, in order, then the last.
        for figures in banked[i].iter().chain(finals[i].iter()) {
            absorb(
                &mut tally,
                &mut waits[i],
                &mut cycle_times[i],
                &mut late[i],
                figures,
            )
            .ok_or_else(|| refused(process_name(line), "its figures do not read"))?;
        }
    }
    let mut record = RunRecord::measured(config, tally, &sim, &cell, waits, cycle_times, total);
    record.lateness = vec![("world".into(), lateness.worst())];
    record.lateness.extend(
        Line::ALL
            .into_iter()
            .map(|line| (process_name(line).into(), late[line.index()])),
    );
    record.outages = outages;
    record.hosts = hosts.map(|hosts| hosts.described);
    Ok(record)
}

/// The world's hands on a line whose process died: a place, as [`LINE_SUPERVISOR`], on
/// every device's port (a port is never left without a user while a line's next run
/// attaches, which would end WORLD's service of it for good), the feeder zone's keeper's
/// LINE_DOWN, and the runs WORLD carries out calls of.
struct Supervisor {
    devices: Vec<(Device, tokio::sync::Mutex<DeviceEnd>)>,
    /// The feeder zone's keeper's ear: FEEDER_MONITOR's or FEEDER_COORDINATOR's.
    line_down: Option<tokio::sync::Mutex<LineDownEnd>>,
    runs: LineRuns,
}

/// The supervision's end on a device's port.
type DeviceEnd = End<DeviceCall, DeviceAnswer, usage::Send>;

/// The supervision's end on LINE_DOWN.
type LineDownEnd = End<(Line, u32), (), usage::Send>;

/// How long, in wall time, the world lets a device finish a call of a dead run.
const MARKER_PATIENCE: Duration = Duration::from_secs(1);

/// How many times the world tries to drive a dead line's chip robot home while a robot
/// fault stops it.
const HOMING_TRIES: u32 = 5;

impl Supervisor {
    fn new(
        devices: &DevicePorts,
        ports: &CellPorts,
        runs: &LineRuns,
        policy: FeederPolicy,
    ) -> Result<Self, RunError> {
        let ends = Line::ALL
            .into_iter()
            .flat_map(Device::of_line)
            .map(|device| {
                let port = devices
                    .of(device)
                    .ok_or_else(|| refused("world", format!("no port for {}", device.port())))?;
                let end = port
                    .user_named(LINE_SUPERVISOR)
                    .map_err(|error| refused("world", error))?;
                Ok((device, tokio::sync::Mutex::new(end)))
            })
            .collect::<Result<_, RunError>>()?;
        // The feeder zone's keeper's ear.
        let line_down = match policy {
            FeederPolicy::Arbiter => Some(&ports.line_down),
            FeederPolicy::Coordinator => Some(&ports.coordinator_down),
            FeederPolicy::Appendix => None,
        };
        let line_down = line_down
            .map(|port| port.user_named(LINE_SUPERVISOR))
            .transpose()
            .map_err(|error| refused("world", error))?
            .map(tokio::sync::Mutex::new);
        Ok(Self {
            devices: ends,
            line_down,
            runs: Arc::clone(runs),
        })
    }

    /// Makes `line`, whose process died, safe for its `next` run: WORLD takes no call of the
    /// dead run from now on, and the call each device was carrying out for it is let end;
    /// the chip robot is driven home; the pallets the line's stations hold are scrapped;
    /// then the feeder zone's keeper is told. Returns how many pallets were scrapped.
    async fn take_over(&self, line: Line, next: u32, sim: &Sim) -> Result<usize, RunError> {
        self.runs[line.index()].store(next, Ordering::Release);
        // A call of the dead run's that a device took before the store is carried out to
        // its end: a word of a run before it, answered `Stale` once that call is done, marks
        // the end. A relay waiting for a pallet may wait long: it is given a while.
        for (_, end) in self
            .devices
            .iter()
            .filter(|(device, _)| device.line() == line)
        {
            let marker = DeviceCall::new(Op::LetGo).in_run(next - 1);
            let done = async { end.lock().await.send(marker).await };
            let _ = tokio::time::timeout(MARKER_PATIENCE, done).await;
        }
        let robot = Device::Robot(RobotId::new(line, Role::ChipIt));
        let Some((_, end)) = self.devices.iter().find(|(device, _)| *device == robot) else {
            return Err(refused("world", format!("no port for {}", robot.port())));
        };
        let mut end = end.lock().await;
        let home = DeviceCall::new(Op::Move(Target::Home)).in_run(next);
        let mut tries = 0;
        loop {
            tries += 1;
            let answer = end
                .send(home)
                .await
                .map_err(|error| refused("world", format!("{}: {error}", robot.port())))?;
            match answer.answer() {
                // A robot fault is passing (an injected one): try again, as a module would.
                Some(Answer::Failed(DeviceError::RobotFault { .. })) if tries < HOMING_TRIES => {}
                // A robot that cannot go home stays where it is: the run cannot go on safely.
                Some(Answer::Failed(error)) => {
                    return Err(refused(
                        process_name(line),
                        format!("its chip robot could not be driven home: {error}"),
                    ));
                }
                _ => break,
            }
        }
        drop(end);
        let scrapped = sim.scrap_held(line).len();
        if let Some(line_down) = &self.line_down {
            line_down
                .lock()
                .await
                .send((line, next))
                .await
                .map_err(|error| refused("world", format!("LINE_DOWN: {error}")))?;
        }
        Ok(scrapped)
    }
}

fn process_name(line: Line) -> &'static str {
    match line {
        Line::A => "line A",
        Line::B => "line B",
    }
}

/// What a line's process said on its standard output.
#[derive(Debug)]
enum Said {
    /// Its ports are imported and its modules started.
    Ready,
    /// Its figures so far, once a minute of the cell's time.
    Snapshot(Value),
    /// Its figures, at the end of the run.
    Figures(Value),
    /// It could not run, and why.
    Failed(String),
    /// Its output closed: it ended, with this status if known.
    Ended(Option<ExitStatus>),
    /// Over zenoh: its host is gone from the world's sight (killed, or cut off), as the
    /// world watches it, whatever run it is in.
    Unseen,
    /// A line the world does not understand.
    Garbled(String),
}

impl Said {
    fn refusal(self, line: Line, expected: &str) -> RunError {
        let why = match self {
            Said::Failed(why) => why,
            Said::Ended(status) => format!(
                "ended ({}) before it sent {expected}",
                status.map_or("status unknown".into(), |status| status.to_string())
            ),
            Said::Garbled(text) => format!("said {text:?} where {expected} was due"),
            Said::Ready | Said::Snapshot(_) | Said::Figures(_) => {
                format!("answered out of turn, before {expected}")
            }
            Said::Unseen => format!("was cut off before it sent {expected}"),
        };
        refused(process_name(line), why)
    }
}

/// What a line's process said, with its line and run.
type Heard = (Line, u32, Said);

/// The run of what the world's watch of a line's host says: whichever run is up.
const UNSEEN: u32 = u32::MAX;

async fn hear_from(hear: &mut UnboundedReceiver<Heard>) -> Result<Heard, RunError> {
    match tokio::time::timeout(PATIENCE, hear.recv()).await {
        Ok(Some(said)) => Ok(said),
        Ok(None) => Err(refused("world", "the lines' processes are gone")),
        Err(_) => Err(refused(
            "world",
            format!("no line's process said anything for {PATIENCE:?}"),
        )),
    }
}

/// The lines' processes: killed if the world gives up on them.
struct Lines(Vec<(Line, u32, Child)>);

impl Lines {
    /// Kills `line`'s process of `run`, if it still runs, and waits for its end.
    fn stop(&mut self, line: Line, run: u32) {
        for (_, _, child) in self
            .0
            .iter_mut()
            .filter(|(l, r, _)| (*l, *r) == (line, run))
        {
            if let Ok(None) = child.try_wait() {
                let _ = child.kill();
            }
            // Killed: its end is at hand, and the runtime's other workers go on meanwhile.
            tokio::task::block_in_place(|| {
                let _ = child.wait();
            });
        }
    }

    /// Gives the lines, which have sent their figures, the world's patience to end on
    /// their own (so that they let go of their shared memory); any still running then is
    /// killed when `self` drops. The world never hangs on a line that does not end.
    async fn ended(&mut self) {
        let deadline = std::time::Instant::now() + PATIENCE;
        while std::time::Instant::now() < deadline
            && self
                .0
                .iter_mut()
                .any(|(_, _, child)| matches!(child.try_wait(), Ok(None)))
        {
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    }
}

impl Drop for Lines {
    fn drop(&mut self) {
        for (_, _, child) in &mut self.0 {
            if let Ok(None) = child.try_wait() {
                let _ = child.kill();
                let _ = child.wait();
            }
        }
    }
}

/// Starts `line`'s process — this same program, told which line it is — and a thread that
/// hands on what it says.
/// Where a line's process runs: the cell's name, and over zenoh its host's namespace (if
/// made) and the world's endpoint as it reaches it.
struct LinePlace<'a> {
    cell: &'a str,
    netns: Option<&'a Netns>,
    connect: Option<&'a str>,
}

fn start_line(
    config: &CellConfig,
    line: Line,
    run: u32,
    place: &LinePlace<'_>,
    epoch: SystemTime,
    faults: &[CellFault],
    said: UnboundedSender<Heard>,
) -> Result<Child, RunError> {
    let name = process_name(line);
    let program = std::env::current_exe()
        .map_err(|error| refused(name, format!("this program cannot be found: {error}")))?;
    let epoch_ns = epoch
        .duration_since(UNIX_EPOCH)
        .map_err(|_| refused(name, "the epoch lies before 1970"))?
        .as_nanos();
    let mut command = match place.netns {
        Some(netns) => netns.command(program),
        None => Command::new(program),
    };
    command
        .args(["--processes", "--line-process", &format!("{line:?}")])
        .args(["--run", &run.to_string()])
        .args(["--remote", place.cell, "--epoch", &epoch_ns.to_string()])
        .args(["--speed", &config.speed.to_string()])
        .args(["--hours", &config.hours.to_string()])
        .args(["--seed", &config.seed.to_string()])
        .args(["--feeder", config.feeder.name()]);
    for fault in faults {
        command.arg(format!("--fault={fault}"));
    }
    if let Some(endpoint) = place.connect {
        command.args(["--transport", "zenoh", "--connect", endpoint]);
    }
    let mut child = command
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .map_err(|error| refused(name, format!("cannot be started: {error}")))?;
    let Some(out) = child.stdout.take() else {
        return Err(refused(name, "has no standard output"));
    };
    std::thread::spawn(move || {
        for text in BufReader::new(out).lines() {
            let Ok(text) = text else { break };
            let heard = match text.split_once(' ') {
                _ if text == "ready" => Said::Ready,
                Some(("snapshot", json)) => match serde_json::from_str(json) {
                    Ok(figures) => Said::Snapshot(figures),
                    Err(_) => Said::Garbled(text),
                },
                Some(("figures", json)) => match serde_json::from_str(json) {
                    Ok(figures) => Said::Figures(figures),
                    Err(_) => Said::Garbled(text),
                },
                Some(("failed", why)) => Said::Failed(why.into()),
                _ => Said::Garbled(text),
            };
            if said.send((line, run, heard)).is_err() {
                return;
            }
        }
        let _ = said.send((line, run, Said::Ended(None)));
    });
    Ok(child)
}

/// Runs one line's modules in this process, as the world started it; says `ready`, then its
/// figures at the end, or `failed` and why.
pub fn run_line(config: &CellConfig, process: &LineProcess) -> Result<(), RunError> {
    let name = process_name(process.line);
    let runtime = runtime(name)?;
    let outcome = runtime.block_on(line_process(config, process));
    let mut out = std::io::stdout().lock();
    let written = match &outcome {
        Ok(figures) => writeln!(out, "figures {figures}"),
        Err(error) => writeln!(out, "failed {}", error.to_string().replace('\n', "; ")),
    };
    let _ = written.and_then(|()| out.flush());
    // The modules still run: stop them without waiting on their next step.
    runtime.shutdown_timeout(Duration::from_millis(100));
    outcome.map(drop)
}

async fn line_process(config: &CellConfig, process: &LineProcess) -> Result<Value, RunError> {
    let (line, name) = (process.line, process_name(process.line));
    let clock = clock(name, process.epoch, config.speed)?;
    let lateness = Lateness::probe(clock.sleep_until(Instant::ZERO));
    let carrier = match &process.connect {
        None => Carrier::Ipc(Remote::new(&process.remote).map_err(carried(name))?),
        Some(endpoint) => {
            let host = Host::builder(&process.remote)
                .connect(endpoint)
                .open()
                .await
                .map_err(carried(name))?;
            // A run started while its host is cut off waits for the link to come back.
            await_world(&host, line)
                .await
                .map_err(|why| refused(name, why))?;
            Carrier::Zenoh(host)
        }
    };
    let cell = Cell::new(clock.clone());
    // The report counts the time lost to deadlocks from how long each wait lasted.
    cell.observe(true);
    cell.events().set_capacity(config.kept_events);
    let tally = Arc::new(Mutex::new(Tally::default()));
    let folded = Arc::clone(&tally);
    cell.events()
        .subscribe(move |event| lock(&folded).cell(event));

    let (names, twin) = (LineNames::of(line), LineNames::of(line.other()));
    let mut ports = CellPorts::new(&clock);
    // The feeder zone's keeper runs in the world's process: its ports are imported.
    let failed = |error: ZoneImport| match error {
        ZoneImport::Carrier(error) => refused(name, error),
        ZoneImport::Wiring(error) => RunError::from(CellErrors::from(error)),
    };
    let chip_it = &names.chip_it;
    match config.feeder {
        FeederPolicy::Arbiter => {
            ports.zone_request = zone_link(&carrier, &cell, ZONE_REQUEST, FEEDER_MONITOR, chip_it)
                .await
                .map_err(failed)?;
            ports.zone_release = zone_link(&carrier, &cell, ZONE_RELEASE, FEEDER_MONITOR, chip_it)
                .await
                .map_err(failed)?;
        }
        FeederPolicy::Coordinator => {
            ports.zone_free = zone_link(&carrier, &cell, ZONE_FREE, FEEDER_COORDINATOR, chip_it)
                .await
                .map_err(failed)?;
            ports.zone_reserve =
                zone_link(&carrier, &cell, ZONE_RESERVE, FEEDER_COORDINATOR, chip_it)
                    .await
                    .map_err(failed)?;
        }
        FeederPolicy::Appendix => {}
    }
    ports.lines[line.index()]
        .declare_to(&cell)
        .map_err(CellErrors::from)?;
    // CHIP_IT queries its twin through its own SHARE_FEEDER, and answers its twin's, owned in
    // the other line's process. Under the Appendix's policy both cross: each line exports
    // its own, then imports its twin's once the twin has exported it. Under the arbiter
    // nobody queries them, and the twin's stays a port of this process.
    let mut shared: Option<(Exported, Imported<(), i32, usage::Query>)> = None;
    if config.feeder == FeederPolicy::Appendix {
        let own = carrier
            .export(&ports.lines[line.index()].share_feeder)
            .await
            .map_err(carried(name))?;
        let imported = import_twin(&carrier, &twin.share_feeder, &twin.chip_it, &names.chip_it)
            .await
            .map_err(carried(name))?;
        ports.lines[line.other().index()].share_feeder = imported.port().clone();
        shared = Some((own, imported));
    }
    cell.declare_imported(&ports.lines[line.other().index()].share_feeder)
        .map_err(CellErrors::from)?;
    let devices = RemoteDevices::import(&carrier, line, process.run)
        .await
        .map_err(carried(name))?;

    let death: ReleaseDeath = Arc::default();
    for fault in &config.faults {
        if fault.kind == CellFaultKind::ReleaseDies(line) {
            *lock(&death) = Some(Instant::from_start(fault.at));
        }
    }
    let history: SharedCycleTimes = Arc::default();
    let waits: SharedWaits = Arc::default();
    let modules = LineModules {
        line,
        run: process.run,
        feeder: config.feeder,
        ports,
        devices: Devices::Remote(Arc::new(devices)),
        death,
        history: Arc::clone(&history),
        waits: Arc::clone(&waits),
    };
    cell.check(&modules.declarations())?;
    modules.start(&cell)?;
    println!("ready");
    let _ = std::io::stdout().flush();
    // The world holds our standard input: when it closes, the world is gone.
    std::thread::spawn(|| {
        let _ = std::io::copy(&mut std::io::stdin().lock(), &mut std::io::sink());
        std::process::exit(3);
    });

    let total = Duration::from_secs_f64(config.hours * 3600.0);
    let so_far = || {
        let waits = lock(&waits)[line.index()];
        let history = lock(&history).clone();
        figures(&lock(&tally), &waits, &history, lateness.worst())
    };
    // The figures so far, once a minute: if this process dies, the world keeps them.
    let mut next = clock.now() + SNAPSHOT_PERIOD;
    while next < Instant::from_start(total) {
        clock.sleep_until(next).await;
        println!("snapshot {}", so_far());
        let _ = std::io::stdout().flush();
        next = next + SNAPSHOT_PERIOD;
    }
    clock.sleep_until(Instant::from_start(total)).await;
    drop(shared);
    Ok(so_far())
}

/// Waits (up to the world's patience) until the world's host is seen exporting `line`'s
/// gate device.
async fn await_world(host: &Host, line: Line) -> Result<(), String> {
    let port = Device::Gate(line).port();
    let deadline = std::time::Instant::now() + PATIENCE;
    while !host.is_exported(&port).await.map_err(|e| e.to_string())? {
        if std::time::Instant::now() >= deadline {
            return Err(format!("the world's host was not seen for {PATIENCE:?}"));
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    Ok(())
}

/// Why a port of the feeder zone's keeper could not be imported.
enum ZoneImport {
    Carrier(CarrierError),
    Wiring(imrs_ports::WireError),
}

/// The keeper's port `port`, imported for `module` and made known to `cell`.
async fn zone_link<Req: Crossing>(
    carrier: &Carrier,
    cell: &Cell,
    port: &str,
    keeper: &str,
    module: &str,
) -> Result<ZoneLink<Req>, ZoneImport> {
    let imported = carrier
        .import::<Req, (), usage::Receive>(port, keeper, module)
        .await
        .map_err(ZoneImport::Carrier)?;
    cell.declare_imported(imported.port())
        .map_err(ZoneImport::Wiring)?;
    Ok(ZoneLink::Imported(imported))
}

/// Imports the twin's SHARE_FEEDER for `module`, waiting (up to the world's patience) until
/// the twin's process has exported it: the two lines start at once, and each exports its own
/// before it imports the other's.
async fn import_twin(
    carrier: &Carrier,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<Imported<(), i32, usage::Query>, CarrierError> {
    let deadline = std::time::Instant::now() + PATIENCE;
    loop {
        match carrier.import(port, owner, module).await {
            Err(error) if error.is_no_owner() && std::time::Instant::now() < deadline => {
                tokio::time::sleep(Duration::from_millis(20)).await;
            }
            other => return other,
        }
    }
}

/// A line's figures: what its modules' events counted, its chip robot's waits, its GATE's
/// cycle times, and how late its timer woke at worst.
fn figures(
    tally: &Tally,
    waits: &ZoneWaits,
    history: &CycleTimeHistory,
    lateness: Duration,
) -> Value {
    let alarm_kinds: Vec<Value> = tally
        .alarm_kinds
        .iter()
        .map(|(kind, count)| json!([kind.map(AlarmKind::label), count]))
        .collect();
    json!({
        "timeouts": tally.timeouts,
        "restarts": tally.restarts,
        "alarms": tally.alarms,
        "alarm_kinds": alarm_kinds,
        "deadlocks": tally.deadlocks,
        "last_deadlock": tally.last_deadlock,
        "deadlock_lost": tally.deadlock_lost,
        "waits": [waits.asks, waits.refused, waits.waited],
        "cycle_time": {
            "first": history.first,
            "now": history.now,
            "range": history.range.map(|(low, high)| [low, high]),
            "changes": history.changes,
            "recent": history.recent.iter().map(|(at, value)| [*at, *value]).collect::<Vec<_>>(),
        },
        "lateness_us": u64::try_from(lateness.as_micros()).unwrap_or(u64::MAX),
    })
}

/// Folds a line's figures into the world's; `None` if they do not read.
fn absorb(
    tally: &mut Tally,
    waits: &mut ZoneWaits,
    history: &mut CycleTimeHistory,
    lateness: &mut Duration,
    figures: &Value,
) -> Option<()> {
    let count = |value: &Value| value.as_u64().and_then(|n| u32::try_from(n).ok());
    let float = |value: &Value| {
        if value.is_null() {
            Some(None)
        } else {
            value.as_f64().map(Some)
        }
    };
    for (port, n) in figures["timeouts"].as_object()? {
        *tally.timeouts.entry(port.clone()).or_insert(0) += count(n)?;
    }
    tally.restarts += count(&figures["restarts"])?;
    tally.alarms += count(&figures["alarms"])?;
    for pair in figures["alarm_kinds"].as_array()? {
        let kind = match &pair[0] {
            Value::Null => None,
            label => {
                let label = label.as_str()?;
                Some(
                    AlarmKind::ALL
                        .into_iter()
                        .find(|kind| kind.label() == label)?,
                )
            }
        };
        *tally.alarm_kinds.entry(kind).or_insert(0) += count(&pair[1])?;
    }
    tally.deadlocks += count(&figures["deadlocks"])?;
    if let Some(last) = float(&figures["last_deadlock"])? {
        tally.last_deadlock = Some(tally.last_deadlock.map_or(last, |other| other.max(last)));
    }
    tally.deadlock_lost += figures["deadlock_lost"].as_f64()?;
    // A line's runs, folded in order: the waits of each add up.
    let asked = &figures["waits"];
    waits.asks += count(&asked[0])?;
    waits.refused += count(&asked[1])?;
    waits.waited += asked[2].as_f64()?;
    let cycle = &figures["cycle_time"];
    let pair = |value: &Value| Some((value[0].as_f64()?, value[1].as_f64()?));
    let run = CycleTimeHistory {
        first: float(&cycle["first"])?,
        now: float(&cycle["now"])?,
        range: match &cycle["range"] {
            Value::Null => None,
            range => Some(pair(range)?),
        },
        changes: count(&cycle["changes"])?,
        recent: cycle["recent"]
            .as_array()?
            .iter()
            .map(pair)
            .collect::<Option<_>>()?,
    };
    history.follow(run);
    *lateness = (*lateness).max(Duration::from_micros(figures["lateness_us"].as_u64()?));
    Some(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_lines_figures_cross_as_json_and_fold_into_the_worlds() {
        let mut line = Tally::default();
        line.timeouts.insert("LET_1_GO".into(), 2);
        line.restarts = 1;
        line.alarms = 3;
        line.alarm_kinds.insert(Some(AlarmKind::EmptyFeeder), 2);
        line.alarm_kinds.insert(None, 1);
        line.deadlocks = 1;
        line.last_deadlock = Some(120.5);
        line.deadlock_lost = 4.25;
        let waits = ZoneWaits {
            asks: 10,
            refused: 1,
            waited: 12.5,
        };
        let history = CycleTimeHistory {
            first: Some(10.0),
            now: Some(9.0),
            range: Some((8.0, 10.0)),
            changes: 2,
            recent: vec![(100.0, 9.5), (200.0, 9.0)],
        };
        // Sent over a pipe as text, and read back.
        let text = figures(&line, &waits, &history, Duration::from_micros(2500)).to_string();
        let read: Value = serde_json::from_str(&text).unwrap();
        let mut world = Tally::default();
        world.timeouts.insert("LET_1_GO".into(), 1);
        world.alarms = 1;
        let (mut got_waits, mut got_history, mut got_lateness) = Default::default();
        absorb(
            &mut world,
            &mut got_waits,
            &mut got_history,
            &mut got_lateness,
            &read,
        )
        .unwrap();
        assert_eq!(world.timeouts["LET_1_GO"], 3);
        assert_eq!(world.restarts, 1);
        assert_eq!(world.alarms, 4);
        assert_eq!(world.alarm_kinds[&Some(AlarmKind::EmptyFeeder)], 2);
        assert_eq!(world.alarm_kinds[&None], 1);
        assert_eq!((world.deadlocks, world.last_deadlock), (1, Some(120.5)));
        assert_eq!(world.deadlock_lost, 4.25);
        assert_eq!(got_waits, waits);
        assert_eq!(got_history, history);
        assert_eq!(got_lateness, Duration::from_micros(2500));
    }

    #[test]
    fn figures_that_do_not_read_are_refused() {
        let read = |figures: &Value| {
            let (mut waits, mut history, mut lateness) = Default::default();
            absorb(
                &mut Tally::default(),
                &mut waits,
                &mut history,
                &mut lateness,
                figures,
            )
        };
        let good = figures(
            &Tally::default(),
            &ZoneWaits::default(),
            &CycleTimeHistory::default(),
            Duration::ZERO,
        );
        assert_eq!(read(&good), Some(()));
        for broken in [
            "restarts",
            "waits",
            "cycle_time",
            "alarm_kinds",
            "lateness_us",
        ] {
            let mut figures = good.clone();
            figures[broken] = json!("garbage");
            assert_eq!(read(&figures), None, "{broken}");
        }
        let mut unknown_kind = good;
        unknown_kind["alarm_kinds"] = json!([["no such kind", 1]]);
        assert_eq!(read(&unknown_kind), None);
    }
}
