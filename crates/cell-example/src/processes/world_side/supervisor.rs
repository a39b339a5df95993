//! The world's hands on a line whose process died: it stops WORLD taking the dead run's
//! calls, drives the line's chip robot home, scraps the pallets its stations held, and
//! tells the feeder zone's keeper.

use super::*;

/// The world's hands on a line whose process died: a place, as [`LINE_SUPERVISOR`], on
/// every device's port (a port is never left without a user while a line's next run
/// attaches, which would end WORLD's service of it for good), the feeder zone's keeper's
/// LINE_DOWN, and the runs WORLD carries out calls of.
pub(super) struct Supervisor {
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
    pub(super) fn new(
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
    pub(super) async fn take_over(
        &self,
        line: Line,
        next: u32,
        sim: &Sim,
    ) -> Result<usize, RunError> {
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
