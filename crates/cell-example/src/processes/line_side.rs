//! A line's process: its modules, the ports it imports from the world and its twin, and
//! the figures it writes for the world.

use super::*;

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
        #[cfg(not(feature = "zenoh"))]
        Some(_) => return Err(refused(name, crate::cli::not_built("--connect", "zenoh"))),
        #[cfg(feature = "zenoh")]
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
#[cfg(feature = "zenoh")]
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
