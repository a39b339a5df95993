//! The world's process: the simulation, WORLD serving the devices and the feeder zone's
//! keeper, and the supervision of the lines' processes it starts. Where the lines' hosts
//! are is in `hosts`; how the world starts, hears and stops the lines' processes in
//! `lines`; and what it does to a line whose process died in `supervisor`.

use super::*;

mod hosts;
mod lines;
mod supervisor;

use self::hosts::{Netns, watch_hosts, world_carrier};
use self::lines::{LinePlace, Lines, Said, hear_from, start_line};
use self::supervisor::Supervisor;

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
    let watchers = watch_hosts(&carrier, &exported, &tell).await?;
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
