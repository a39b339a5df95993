//! The load workcell: LOAD_IT and its children LOAD_CARD and SCREW_IN_CARD (Appendix, MODULE
//! LOAD_IT, LOAD_CARD, SCREW_IN_CARD): a serialized motion process.

use std::time::Duration;

use imrs_core::prelude::*;
use imrs_sim::{Line, RobotId, Role, Station, Target};

use crate::devices::Devices;

use crate::alarms::{AlarmKind, alarm};
use crate::help::{drive_relay, insisted, retried};
use crate::names::LineNames;
use crate::ports::LinePorts;

/// How LOAD_IT's children are restarted when they stop answering.
const CHILD_RESTARTS: RestartPolicy = RestartPolicy::restart(5, Duration::from_secs(1));

/// LOAD_IT's variables.
#[derive(Debug, Default)]
pub struct LoadItState {
    /// NUM_LOADED, as LOAD_CARD last reported it.
    pub num_loaded: u32,
    /// Cycle times reported since the last FREQUENCY message.
    cycle_times: Vec<f64>,
}

/// LOAD_CARD's variables.
#[derive(Debug, Default)]
pub struct LoadCardState {
    /// NUM_LOADED.
    pub num_loaded: u32,
    /// CYCLE_TIME: the last cycle's time, in seconds.
    pub cycle_time: f64,
}

/// The LOAD_IT module of `line`, which costarts LOAD_CARD and SCREW_IN_CARD.
pub fn load_it(line: Line, ports: &LinePorts, devices: &Devices) -> ModuleSpec<LoadItState> {
    let n = LineNames::of(line);
    let (timeout1, timeout2) = (
        ports.ask_child1.handler("TIMEOUT").name(),
        ports.ask_child2.handler("TIMEOUT").name(),
    );
    let ports = ports.clone();
    let devices = devices.clone();
    let (load_card_name, screw_name) = (n.load_card.clone(), n.screw_in_card.clone());
    ModuleSpec::new(n.load_it.clone(), LoadItState::default())
        .order([
            timeout1.clone(),
            timeout2.clone(),
            n.load_it.as_str().into(),
        ])
        .uses_named(n.frequency.clone(), UsageKind::Send)
        .task(n.load_it.clone(), move |ctx| {
            let (ports, devices, n) = (ports.clone(), devices.clone(), n.clone());
            async move {
                let (child_ports, child_devices) = (ports.clone(), devices.clone());
                ctx.costart_supervised(CHILD_RESTARTS, move || {
                    load_card(line, &child_ports, &child_devices)
                })?;
                let (child_ports, child_devices) = (ports.clone(), devices.clone());
                ctx.costart_supervised(CHILD_RESTARTS, move || {
                    screw_in_card(line, &child_ports, &child_devices)
                })?;
                let mut ask_child1 = ports.ask_child1.owner()?;
                let mut ask_child2 = ports.ask_child2.owner()?;
                let mut frequency = ctx.user(ports.frequency.users_side())?;
                loop {
                    ctx.delay(Duration::from_secs(4)).await;
                    // QUERY ASK_CHILD1.STATUS(RC, NUM_LOADED, CYCLE_TIME): is LOAD_CARD ok?
                    if let Ok((rc, num_loaded, cycle_time)) = ctx.query(&mut ask_child1, ()).await {
                        if rc != 0 {
                            let report = format!("{} reports RC={rc}", n.load_card);
                            alarm(&ctx, AlarmKind::StepFailed, report);
                        }
                        ctx.state().update(|load_it| {
                            load_it.num_loaded = num_loaded;
                            if cycle_time > 0.0 {
                                load_it.cycle_times.push(cycle_time);
                            }
                        });
                    }
                    // QUERY ASK_CHILD2.STATUS(RC): is SCREW_IN_CARD ok?
                    if let Ok(rc) = ctx.query(&mut ask_child2, ()).await
                        && rc != 0
                    {
                        let report = format!("{} reports RC={rc}", n.screw_in_card);
                        alarm(&ctx, AlarmKind::StepFailed, report);
                    }
                    // Average many cycle times, and once in a while SEND FREQUENCY(0, CYCLE_TIME).
                    let average = ctx.state().update(|load_it| {
                        (load_it.cycle_times.len() >= 5).then(|| {
                            let times = std::mem::take(&mut load_it.cycle_times);
                            times.iter().sum::<f64>() / times.len() as f64
                        })
                    });
                    if let Some(average) = average {
                        let _ = ctx.send(&mut frequency, (0, average)).await;
                    }
                }
            }
        })
        .exception(timeout1, move |ctx: Ctx<LoadItState>, _| {
            let child = load_card_name.clone();
            async move {
                alarm(
                    &ctx,
                    AlarmKind::NoAnswer,
                    format!("{child} does not answer: killing it and starting a new copy"),
                );
                ctx.kill(&child);
            }
        })
        .exception(timeout2, move |ctx: Ctx<LoadItState>, _| {
            let child = screw_name.clone();
            async move {
                alarm(
                    &ctx,
                    AlarmKind::NoAnswer,
                    format!("{child} does not answer: killing it and starting a new copy"),
                );
                ctx.kill(&child);
            }
        })
}

/// The LOAD_CARD module of `line`: its robot lays a card on each pallet.
pub fn load_card(line: Line, ports: &LinePorts, devices: &Devices) -> ModuleSpec<LoadCardState> {
    let n = LineNames::of(line);
    let spec = ModuleSpec::new(n.load_card.clone(), LoadCardState::default())
        .order([
            ports.card_in_place.handler("TIMEOUT").name(),
            ports.pallet_in_place.handler("TIMEOUT").name(),
            ports.ask_child1.handler("STATUS").name(),
            n.load_card.as_str().into(),
        ])
        .hardware([
            format!("load robot of line {line:?}"),
            "load station freeze relay".into(),
        ])
        // WHEN ASK_CHILD1.STATUS(RC1, NUM1, CYCLE1) ==> RC1 := 0; NUM1 := NUM_LOADED; ...
        .respond(
            &ports.ask_child1.handler("STATUS"),
            |card: &LoadCardState, ()| (0, card.num_loaded, card.cycle_time),
        );
    let (pallet_port, card_port) = (ports.pallet_in_place.clone(), ports.card_in_place.clone());
    let robot = devices.robot(RobotId::new(line, Role::LoadCard));
    let freeze_port = ports.pallet_in_place.clone();
    let relay = devices.relay(line, Station::Load);
    spec.task(n.load_card.clone(), move |ctx| {
        let (pallet_port, card_port, robot) =
            (pallet_port.clone(), card_port.clone(), robot.clone());
        async move {
            let mut pallet_in_place = pallet_port.owner()?;
            let mut card_in_place = card_port.owner()?;
            loop {
                let start = ctx.now();
                // {grab next card and move to ready position}
                retried(&ctx, "going to the magazine", || {
                    robot.move_to(Target::Magazine)
                })
                .await?;
                retried(&ctx, "picking a card", || robot.pick_card()).await?;
                retried(&ctx, "going to the ready position", || {
                    robot.move_to(Target::Home)
                })
                .await?;
                // RECEIVE PALLET_IN_PLACE(TASK_ID): don't reply until the pallet can go.
                let (pallet, task_id) = match ctx.receive(&mut pallet_in_place).await {
                    Ok(received) => received,
                    Err(error) if error.is_timeout() => continue,
                    Err(error) => return Err(error.into()),
                };
                // {move card to pallet}
                let placed = async {
                    retried(&ctx, "moving the card to the pallet", || {
                        robot.move_to(Target::Card)
                    })
                    .await?;
                    retried(&ctx, "laying the card", || robot.place_card()).await
                }
                .await;
                insisted(&ctx, "clearing the pallet", || robot.move_to(Target::Home)).await;
                if let Err(error) = placed {
                    let kind = AlarmKind::of_error(&error);
                    alarm(
                        &ctx,
                        kind,
                        format!("{pallet}: no card laid ({error}); letting it go"),
                    );
                    task_id.reply(());
                    continue;
                }
                // SEND CARD_IN_PLACE(RC): SCREW_IN_CARD anchors it.
                match ctx.send(&mut card_in_place, pallet).await {
                    Ok(0) => {
                        let cycle = (ctx.now() - start).as_secs_f64();
                        ctx.state().update(|card| {
                            card.cycle_time = cycle;
                            card.num_loaded += 1;
                        });
                    }
                    Ok(rc) => alarm(
                        &ctx,
                        AlarmKind::StepFailed,
                        format!("{pallet}: the card was not screwed (RC={rc})"),
                    ),
                    Err(error) => alarm(&ctx, AlarmKind::NoAnswer, format!("{pallet}: {error}")),
                }
                // REPLY PALLET_IN_PLACE(TASK_ID): release the pallet.
                task_id.reply(());
            }
        }
    })
    .task("FREEZE_PALLET", move |ctx| {
        let (port, relay) = (freeze_port.clone(), relay.clone());
        async move {
            let mut pallet_in_place = ctx.task_user(&port)?;
            drive_relay(&ctx, &relay, &mut pallet_in_place).await?;
            Ok(())
        }
    })
    .exception(
        ports.pallet_in_place.handler("TIMEOUT"),
        |ctx: Ctx<LoadCardState>, _| async move {
            alarm(
                &ctx,
                AlarmKind::Starved,
                "no pallet at the load station for 30 s",
            );
        },
    )
    .exception(
        ports.card_in_place.handler("TIMEOUT"),
        |ctx: Ctx<LoadCardState>, _| async move {
            alarm(
                &ctx,
                AlarmKind::NoAnswer,
                "SCREW_IN_CARD did not answer within 30 s",
            );
        },
    )
}

/// The SCREW_IN_CARD module of `line`: its robot screws each laid card to its pallet.
pub fn screw_in_card(line: Line, ports: &LinePorts, devices: &Devices) -> ModuleSpec<()> {
    let n = LineNames::of(line);
    let timeout = ports.card_in_place.handler("TIMEOUT").name();
    let spec = ModuleSpec::new(n.screw_in_card.clone(), ())
        .order([
            timeout.clone(),
            ports.ask_child2.handler("STATUS").name(),
            n.screw_in_card.as_str().into(),
        ])
        .hardware([format!("screw robot of line {line:?}")])
        .uses(&ports.card_in_place)
        // WHEN ASK_CHILD2.STATUS(RC1) ==> RC1 := 0;
        .respond(&ports.ask_child2.handler("STATUS"), |_: &(), ()| 0);
    let port = ports.card_in_place.clone();
    let robot = devices.robot(RobotId::new(line, Role::ScrewInCard));
    spec.task(n.screw_in_card.clone(), move |ctx| {
        let (port, robot) = (port.clone(), robot.clone());
        async move {
            let mut card_in_place = ctx.user(&port)?.with_timeout(Duration::from_secs(30));
            loop {
                // {Prepare to screw in next card}
                insisted(&ctx, "going home", || robot.move_to(Target::Home)).await;
                let (pallet, task_id) = match ctx.receive(&mut card_in_place).await {
                    Ok(received) => received,
                    Err(error) if error.is_timeout() => continue,
                    Err(error) => return Err(error.into()),
                };
                // {screw card in, set RC=0 if OK, <>0 if error}
                let screwed = async {
                    retried(&ctx, "moving to the card", || robot.move_to(Target::Card)).await?;
                    retried(&ctx, "screwing", || robot.screw()).await
                }
                .await;
                insisted(&ctx, "clearing the pallet", || robot.move_to(Target::Home)).await;
                let rc = match screwed {
                    Ok(()) => 0,
                    Err(error) => {
                        alarm(
                            &ctx,
                            AlarmKind::of_error(&error),
                            format!("{pallet}: {error}"),
                        );
                        1
                    }
                };
                task_id.reply(rc);
            }
        }
    })
    .exception(timeout, |ctx: Ctx<()>, _| async move {
        alarm(&ctx, AlarmKind::Starved, "no card to screw for 30 s");
    })
}
