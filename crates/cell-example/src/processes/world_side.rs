//! The world's process: the simulation, WORLD serving the devices and the feeder zone's
//! keeper, and the supervision of the lines' processes it starts.

use super::*;

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
    inject(&config.faults, &sim, &Default::default());

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
