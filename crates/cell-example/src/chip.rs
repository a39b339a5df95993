//! The chip workcell: CHIP_IT on line A and its twin CHIP_IT2 on line B, sharing the feeders
//! (Appendix, MODULE CHIP_IT), and FEEDER_MONITOR, the arbiter the paper's conclusion points to.

use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use imrs_coord::zones::Reservations;
use imrs_core::prelude::*;
use imrs_ports::{End, QueryError, ReplyHandle, select, usage, when};
use imrs_sim::layout::LINK_RADIUS;
use imrs_sim::{DeviceError, FEEDER_CHIPS, FeederId, Line, RobotId, Role, Station, Target};

use crate::alarms::{AlarmKind, alarm};
use crate::devices::{Devices, MAX_SWEEP_SAMPLES, RobotDevice};
use crate::feeder_policy::FeederPolicy;
use crate::help::{drive_relay, insisted, retried};
use crate::names::{
    FEEDER_COORDINATOR, FEEDER_MONITOR, LineNames, ZONE_FREE, ZONE_RELEASE, ZONE_REQUEST,
    ZONE_RESERVE,
};
use crate::ports::CellPorts;
use crate::reservation::{MAX_POSES, Reservation, chip_robot};
use crate::zone_asker::ZoneAsker;

/// One step of CHIP_IT's work schedule: `GRASP(n), INSERT(X, Y, Z)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChipStep {
    /// The feeder to grasp from.
    pub feeder: FeederId,
    /// Where on the card, in millimetres from its corner.
    pub at: (u32, u32),
}

impl ChipStep {
    /// The step's place on the card, in metres from its corner.
    pub fn place(&self) -> [f32; 2] {
        [self.at.0 as f32 / 1000.0, self.at.1 as f32 / 1000.0]
    }
}

/// CHIP_IT's work schedule: four chips, all of priority 1, so any order will do.
pub fn work_schedule() -> WorkSchedule<ChipStep> {
    WorkSchedule::new()
        .step(
            1,
            ChipStep {
                feeder: FeederId(0),
                at: (20, 30),
            },
        )
        .step(
            1,
            ChipStep {
                feeder: FeederId(1),
                at: (60, 30),
            },
        )
        .step(
            1,
            ChipStep {
                feeder: FeederId(2),
                at: (20, 70),
            },
        )
        .step(
            1,
            ChipStep {
                feeder: FeederId(3),
                at: (60, 70),
            },
        )
}

/// How many chips a good card carries: one per step of the work schedule.
pub fn chips_per_card() -> u32 {
    work_schedule().more() as u32
}

/// Where the work schedule puts chip number `chip` on the card, in metres from its corner.
pub fn place_of_chip(chip: u32) -> Option<[f32; 2]> {
    let schedule = work_schedule();
    (0..)
        .map_while(|index| schedule.get(index))
        .find(|step| FEEDER_CHIPS.get(usize::from(step.feeder.0)) == Some(&chip))
        .map(ChipStep::place)
}

/// What the chip robots measured of their own waiting for the zone.
#[derive(Debug, Default, Clone, Copy, PartialEq)]
pub struct ZoneWaits {
    /// How often a robot asked for the zone.
    pub asks: u32,
    /// How often it was refused (a timeout, or CLEAR = 0).
    pub refused: u32,
    /// The time spent asking, in seconds.
    pub waited: f64,
}

/// Per line, the chip robot's waits.
pub type SharedWaits = Arc<Mutex<[ZoneWaits; 2]>>;

/// CHIP_IT's variables.
#[derive(Debug, Default)]
pub struct ChipItState {
    /// Cards done.
    pub cards: u32,
    /// Cycle times since the last FREQUENCY message.
    cycle_times: Vec<f64>,
}

/// The way into the zone under a policy: the twin's permission, the arbiter's, or the
/// coordinator's reservation of the trajectory's space.
enum Access {
    Appendix(End<(), i32, usage::Query>),
    Arbiter {
        request: End<ZoneAsker, (), usage::Send>,
        release: End<ZoneAsker, (), usage::Send>,
        /// What the monitor is told: who asks, from which run of its line's process.
        asker: ZoneAsker,
    },
    Coordinator {
        reserve: End<Reservation, (), usage::Send>,
        free: End<ZoneAsker, (), usage::Send>,
        /// Who asks, from which run of its line's process, as to the arbiter.
        asker: ZoneAsker,
    },
}

/// How finely a trajectory's sweep is sampled: a pose every few centimetres of tool travel.
const SWEEP_SAMPLES: usize = 12;

// A step's two sweeps fit a reservation, and each fits a device's answer across processes.
const _: () = assert!(2 * (SWEEP_SAMPLES + 1) <= MAX_POSES && SWEEP_SAMPLES <= MAX_SWEEP_SAMPLES);

impl Access {
    /// Asks to enter the zone, and counts the wait; whether it may.
    async fn enter(&mut self, ctx: &Ctx<ChipItState>, waits: &SharedWaits, line: Line) -> bool {
        let asked = ctx.now();
        let ok = match self {
            // QUERY SHARE_FEEDER.CRIT_SECTION(OK)
            Access::Appendix(share_feeder) => match ctx.query(share_feeder, ()).await {
                Ok(clear) => clear != 0,
                // The twin's process died (across processes): no permission until its next
                // run answers. Asked again in a second, not at once.
                Err(QueryError::PeerGone { .. } | QueryError::NoResponse { .. }) => {
                    ctx.delay(Duration::from_secs(1)).await;
                    false
                }
                Err(_) => false,
            },
            Access::Arbiter { request, asker, .. } => ctx.send(request, *asker).await.is_ok(),
            // The coordinator is asked per step, with the step's trajectory: see `reserve`.
            Access::Coordinator { .. } => return true,
        };
        record_wait(waits, line, ok, (ctx.now() - asked).as_secs_f64());
        ok
    }

    /// Under the coordinator, reserves the space the arm sweeps to `feeder` and on to the
    /// card's `place`, waits until it is granted, and counts the wait (the other policies
    /// ask in `enter`). A coordinator that cannot be reached is asked again each second, as
    /// `left` does.
    async fn reserve(
        &mut self,
        ctx: &Ctx<ChipItState>,
        robot: &RobotDevice,
        step: ChipStep,
        waits: &SharedWaits,
    ) -> Result<(), DeviceError> {
        let Access::Coordinator { reserve, asker, .. } = self else {
            return Ok(());
        };
        let (feeder, place) = (step.feeder, step.place());
        let mut sweep = robot
            .sweep(None, Target::Feeder(feeder), SWEEP_SAMPLES)
            .await?;
        sweep.extend(
            robot
                .sweep(
                    Some(Target::Feeder(feeder)),
                    Target::OnCard(place),
                    SWEEP_SAMPLES,
                )
                .await?,
        );
        // Two sweeps of `SWEEP_SAMPLES + 1` poses at most always fit (checked below, at
        // compile time).
        let Some(reservation) = Reservation::new(*asker, &sweep) else {
            unreachable!(
                "a step's sweep has at most {} poses",
                2 * (SWEEP_SAMPLES + 1)
            );
        };
        let asked = ctx.now();
        while ctx.send(reserve, reservation).await.is_err() {
            ctx.delay(Duration::from_secs(1)).await;
        }
        let waited = (ctx.now() - asked).as_secs_f64();
        record_wait(waits, robot.id().line, true, waited);
        Ok(())
    }

    /// Says it has left the zone.
    async fn left(&mut self, ctx: &Ctx<ChipItState>) {
        match self {
            Access::Arbiter { release, asker, .. } => {
                while ctx.send(release, *asker).await.is_err() {
                    ctx.delay(Duration::from_secs(1)).await;
                }
            }
            Access::Coordinator { free, asker, .. } => {
                while ctx.send(free, *asker).await.is_err() {
                    ctx.delay(Duration::from_secs(1)).await;
                }
            }
            Access::Appendix(_) => {}
        }
    }
}

/// The CHIP_IT module of `line` (CHIP_IT2 on line B), in `run` of its line's process (0 in
/// one process; see [`ZoneAsker`]).
pub fn chip_it(
    line: Line,
    run: u32,
    policy: FeederPolicy,
    ports: &CellPorts,
    devices: &Devices,
    waits: SharedWaits,
) -> ModuleSpec<ChipItState> {
    let n = LineNames::of(line);
    let twin_line = line.other();
    let line_ports = &ports.lines[line.index()];
    let twin_ports = &ports.lines[twin_line.index()];
    let crit_section = twin_ports.share_feeder.handler("CRIT_SECTION").name();
    let own_timeout = line_ports.share_feeder.handler("TIMEOUT").name();
    let mut spec = ModuleSpec::new(n.chip_it.clone(), ChipItState::default())
        // 1) timeouts first; 2) never preempt the background, else a QUERY could be
        // interrupted by a QUERY from the twin; 3) nor the critical region; 4) then the twin's
        // query; 5) the insertion last: a query is answered only while inserting.
        .order([
            line_ports.ready_to_chip.handler("TIMEOUT").name(),
            own_timeout.clone(),
            n.chip_it.as_str().into(),
            "GRASP".into(),
            crit_section.clone(),
            "INSERT".into(),
            "BACK_OFF".into(),
        ])
        .hardware([
            format!("chip robot of line {line:?}"),
            "chip station freeze relay".into(),
        ])
        .uses_named(n.frequency.clone(), UsageKind::Send)
        // The Appendix's feeder ports are declared under both policies, so that the module
        // keeps the Appendix's shape; under the arbiter nobody queries them.
        // WHEN SHARE_FEEDER1.CRIT_SECTION(CLEAR) ==> CLEAR := 1: the order decides when.
        .respond(
            &twin_ports.share_feeder.handler("CRIT_SECTION"),
            |_: &ChipItState, ()| 1,
        );
    match policy {
        FeederPolicy::Arbiter => {
            spec = spec
                .uses_named(ZONE_REQUEST, UsageKind::Send)
                .uses_named(ZONE_RELEASE, UsageKind::Send);
        }
        FeederPolicy::Coordinator => {
            spec = spec
                .uses_named(ZONE_RESERVE, UsageKind::Send)
                .uses_named(ZONE_FREE, UsageKind::Send);
        }
        FeederPolicy::Appendix => {}
    }
    // The asymmetric timeout handlers (note 6): CHIP_IT steps into a procedure ranked below
    // CRIT_SECTION for a moment, so its twin's pending query is answered; CHIP_IT2 just
    // retries.
    let backs_off = line == Line::A;
    spec = spec.exception(own_timeout, move |ctx: Ctx<ChipItState>, _| async move {
        if backs_off {
            ctx.section(
                &Section::new("BACK_OFF"),
                ctx.delay(Duration::from_millis(500)),
            )
            .await;
        }
    });

    let (ready_port, share_feeder, frequency) = (
        line_ports.ready_to_chip.clone(),
        line_ports.share_feeder.clone(),
        line_ports.frequency.clone(),
    );
    let (zone_request, zone_release) = (ports.zone_request.clone(), ports.zone_release.clone());
    let (zone_reserve, zone_free) = (ports.zone_reserve.clone(), ports.zone_free.clone());
    let robot = devices.robot(RobotId::new(line, Role::ChipIt));
    let background = move |ctx: Ctx<ChipItState>| {
        let (ready_port, share_feeder, frequency) =
            (ready_port.clone(), share_feeder.clone(), frequency.clone());
        let (zone_request, zone_release, robot) =
            (zone_request.clone(), zone_release.clone(), robot.clone());
        let (zone_reserve, zone_free) = (zone_reserve.clone(), zone_free.clone());
        let waits = Arc::clone(&waits);
        async move {
            let mut ready_to_chip = ready_port.owner()?;
            let mut frequency = ctx.user(frequency.users_side())?;
            let mut access = match policy {
                FeederPolicy::Appendix => Access::Appendix(share_feeder.owner()?),
                FeederPolicy::Arbiter => Access::Arbiter {
                    request: zone_request.user(&ctx)?,
                    release: zone_release.user(&ctx)?,
                    asker: ZoneAsker::new(ctx.module().as_str(), line, run),
                },
                FeederPolicy::Coordinator => Access::Coordinator {
                    reserve: zone_reserve.user(&ctx)?,
                    free: zone_free.user(&ctx)?,
                    asker: ZoneAsker::new(ctx.module().as_str(), line, run),
                },
            };
            let mut work = work_schedule();
            loop {
                // {Start timer}
                let start = ctx.now();
                // RECEIVE READY_TO_CHIP(TASK_ID): get signal to begin.
                let (pallet, task_id) = match ctx.receive(&mut ready_to_chip).await {
                    Ok(received) => received,
                    Err(error) if error.is_timeout() => continue,
                    Err(error) => return Err(error.into()),
                };
                work.reinstate();
                while work.more() > 0 {
                    if !access.enter(&ctx, &waits, line).await {
                        // {Signal operator}: counted; a timeout already raised SHARE_FEEDER.TIMEOUT.
                        continue;
                    }
                    ctx.perform(&mut work, |step| {
                        chip_step(&ctx, &robot, *step, &mut access, &waits)
                    })
                    .await;
                }
                task_id.reply(());
                let _ = pallet;
                // {stop timer, update and average cycle time, and once in a while do
                //  SEND FREQUENCY(1, CYCLE_TIME)}
                let cycle = (ctx.now() - start).as_secs_f64();
                let average = ctx.state().update(|chip| {
                    chip.cards += 1;
                    chip.cycle_times.push(cycle);
                    (chip.cycle_times.len() >= 5).then(|| {
                        let times = std::mem::take(&mut chip.cycle_times);
                        times.iter().sum::<f64>() / times.len() as f64
                    })
                });
                if let Some(average) = average {
                    let _ = ctx.send(&mut frequency, (1, average)).await;
                }
            }
        }
    };
    let (freeze_port, relay) = (
        line_ports.ready_to_chip.clone(),
        devices.relay(line, Station::Chip),
    );
    spec.task(n.chip_it.clone(), background)
        .task("FREEZE_CARD", move |ctx| {
            let (port, relay) = (freeze_port.clone(), relay.clone());
            async move {
                let mut ready_to_chip = ctx.task_user(&port)?;
                drive_relay(&ctx, &relay, &mut ready_to_chip).await?;
                Ok(())
            }
        })
        .exception(
            line_ports.ready_to_chip.handler("TIMEOUT"),
            |ctx: Ctx<ChipItState>, _| async move {
                alarm(
                    &ctx,
                    AlarmKind::Starved,
                    "no card at the chip station for 60 s",
                );
            },
        )
}

fn record_wait(waits: &SharedWaits, line: Line, ok: bool, waited: f64) {
    let mut waits = waits.lock().unwrap_or_else(PoisonError::into_inner);
    let waits = &mut waits[line.index()];
    waits.asks += 1;
    waits.refused += u32::from(!ok);
    waits.waited += waited;
}

/// One step: GRASP (enter the zone, grasp from the feeder, leave the zone), then INSERT.
async fn chip_step(
    ctx: &Ctx<ChipItState>,
    robot: &RobotDevice,
    step: ChipStep,
    access: &mut Access,
    waits: &SharedWaits,
) -> Result<(), DeviceError> {
    access.reserve(ctx, robot, step, waits).await?;
    let grasped = ctx
        .section(&Section::new("GRASP"), async {
            let grasped = async {
                retried(ctx, "reaching into the feeders", || {
                    robot.move_to(Target::Feeder(step.feeder))
                })
                .await?;
                retried(ctx, "grasping a chip", || robot.grasp(step.feeder)).await
            }
            .await;
            // Out of the zone before anything else, whatever happened in it: to the step's
            // place on the card, INSERT(X, Y, Z).
            insisted(ctx, "leaving the feeder zone", || {
                robot.move_to(Target::OnCard(step.place()))
            })
            .await;
            access.left(ctx).await;
            grasped
        })
        .await;
    if let Err(error) = grasped {
        // Note 5: an empty feeder is reported, and the other steps still run.
        alarm(
            ctx,
            AlarmKind::of_error(&error),
            format!("{error}: skipping this chip"),
        );
        return Err(error);
    }
    ctx.section(&Section::new("INSERT"), async {
        retried(ctx, "inserting the chip", || robot.insert())
            .await
            .map(|_| ())
    })
    .await
}

/// FEEDER_COORDINATOR: reserves for each chip robot the space its trajectory to the feeder
/// and back to the card will sweep, granting it at once where it keeps clear of the other
/// robot's reservation, and in turn where it does not.
///
/// Across processes the world tells it, on LINE_DOWN, that a line's process has died and
/// which run of it comes next, once the dead line's chip robot is home: what the dead run
/// held or asked for is let go, and the word of a dead run is not heeded, as FEEDER_MONITOR
/// does. In one process nothing is said on LINE_DOWN, and every word is of run 0.
pub fn feeder_coordinator(ports: &CellPorts) -> ModuleSpec<()> {
    let (reserve, free, line_down) = (
        ports.zone_reserve.clone(),
        ports.zone_free.clone(),
        ports.coordinator_down.clone(),
    );
    ModuleSpec::new(FEEDER_COORDINATOR, ()).task(FEEDER_COORDINATOR, move |_ctx| {
        let (reserve, free, line_down) = (reserve.clone(), free.clone(), line_down.clone());
        async move {
            let (mut reserve, mut free) = (reserve.owner()?, free.owner()?);
            let mut line_down = line_down.owner()?;
            let mut space = Reservations::new(LINK_RADIUS, SWEEP_MARGIN);
            // The run of each line's process whose word counts.
            let mut runs = [0_u32; 2];
            // Requests not yet granted: answered when their space frees.
            let mut asleep: Vec<(ZoneAsker, ReplyHandle<()>)> = Vec::new();
            // The line of a word from a live run of a chip robot; `None` for any other.
            let live = |asker: &ZoneAsker, runs: &[u32; 2]| {
                chip_robot(asker).filter(|line| runs[line.index()] == asker.run())
            };
            loop {
                enum Event {
                    Down(Line, u32, ReplyHandle<()>),
                    // Boxed: a reservation is a record of 1.6 KiB.
                    Reserve(Box<Reservation>, ReplyHandle<()>),
                    Free(ZoneAsker, ReplyHandle<()>),
                }
                let event = select()
                    .or(&mut line_down, |((line, next), reply)| {
                        Event::Down(line, next, reply)
                    })
                    .or(&mut free, |(asker, reply)| Event::Free(asker, reply))
                    .or(&mut reserve, |(reservation, reply)| {
                        Event::Reserve(Box::new(reservation), reply)
                    })
                    .await?;
                let granted = match event {
                    Event::Down(line, next, reply) => {
                        runs[line.index()] = next;
                        // A dead run's request still asleep is dropped: nobody is there.
                        asleep.retain(|(asker, _)| asker.line() != Some(line));
                        reply.reply(());
                        space.withdraw(&LineNames::of(line).chip_it)
                    }
                    Event::Reserve(reservation, reply) => {
                        // A record no live chip robot wrote (a garbled peer, a dead run) is
                        // not answered: its sender fails. Its name is never kept.
                        let (Some(_), Some(sweep)) =
                            (live(reservation.asker(), &runs), reservation.sweep())
                        else {
                            continue;
                        };
                        let asker = *reservation.asker();
                        if space.request(asker.robot().as_str(), &sweep.to_vec()) {
                            reply.reply(());
                        } else {
                            asleep.push((asker, reply));
                        }
                        continue;
                    }
                    // A free from any but a live chip robot (a dead run's, sent on its way
                    // out) is answered, and changes nothing.
                    Event::Free(asker, reply) => {
                        reply.reply(());
                        match live(&asker, &runs) {
                            Some(_) => space.release(asker.robot().as_str()),
                            None => continue,
                        }
                    }
                };
                for granted in granted {
                    if let Some(at) = asleep
                        .iter()
                        .position(|(asker, _)| granted == asker.robot().as_str())
                    {
                        asleep.swap_remove(at).1.reply(());
                    }
                }
            }
        }
    })
}

/// How far apart two reservations keep the arms' links.
const SWEEP_MARGIN: f32 = 0.03;

/// FEEDER_MONITOR: hands the feeder zone to one chip robot at a time.
///
/// Across processes the world tells it, on LINE_DOWN, that a line's process has died and
/// which run of it comes next, once the dead line's chip robot is out of the zone: the
/// zone a dead run held is free again, and the word of a dead run is not heeded (a request
/// it left waiting is dropped: nobody is there to enter). In one process nothing is said
/// on LINE_DOWN, and every word is of run 0.
pub fn feeder_monitor(ports: &CellPorts) -> ModuleSpec<()> {
    let (request, release, line_down) = (
        ports.zone_request.clone(),
        ports.zone_release.clone(),
        ports.line_down.clone(),
    );
    ModuleSpec::new(FEEDER_MONITOR, ()).task(FEEDER_MONITOR, move |_ctx| {
        let (request, release, line_down) = (request.clone(), release.clone(), line_down.clone());
        async move {
            let (mut request, mut release) = (request.owner()?, release.owner()?);
            let mut line_down = line_down.owner()?;
            // The run of each line's process whose word counts.
            let mut runs = [0_u32; 2];
            let mut holder: Option<ZoneAsker> = None;
            loop {
                enum Event {
                    Down(Line, u32, ReplyHandle<()>),
                    Left(ZoneAsker, ReplyHandle<()>),
                    Asked(ZoneAsker, ReplyHandle<()>),
                }
                let event = select()
                    .or(&mut line_down, |((line, next), reply)| {
                        Event::Down(line, next, reply)
                    })
                    .or(&mut release, |(asker, reply)| Event::Left(asker, reply))
                    // Take no other request until the zone is back.
                    .or(when(holder.is_none(), &mut request), |(asker, reply)| {
                        Event::Asked(asker, reply)
                    })
                    .await?;
                match event {
                    Event::Down(line, next, reply) => {
                        runs[line.index()] = next;
                        if holder.is_some_and(|held| held.line() == Some(line)) {
                            holder = None;
                        }
                        reply.reply(());
                    }
                    // A release from any but the holder (a dead run's, sent on its way
                    // out) is answered, and changes nothing.
                    Event::Left(asker, returned) => {
                        returned.reply(());
                        if holder == Some(asker) {
                            holder = None;
                        }
                    }
                    Event::Asked(asker, granted) => {
                        let live = asker
                            .line()
                            .is_some_and(|line| runs[line.index()] == asker.run());
                        if live {
                            granted.reply(());
                            holder = Some(asker);
                        }
                    }
                }
            }
        }
    })
}
