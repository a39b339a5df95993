//! A small cell for the recorder's and the timeline's tests: two chip robots of the
//! simulation that query each other for the feeders (the deadlock of Shin 1985's note 6,
//! broken by asymmetric timeouts), then each reach into the feeder zone, grasp a chip,
//! and insert it.
#![allow(dead_code, unreachable_pub)]

use std::sync::Arc;
use std::time::Duration;

use imrs_core::Event;
use imrs_core::prelude::*;
use imrs_core::time::drive;
use imrs_ports::Instant;
use imrs_ports::Name;
use imrs_record::{Recorder, Timeline};
use imrs_sim::{FeederId, Line, RobotId, Role, Scene, Sim, SimConfig, SimEvent, Target};

/// `n` seconds.
pub fn secs(n: u64) -> Duration {
    Duration::from_secs(n)
}

/// What a run of the small cell logged, and the scene at its end.
pub struct Ran {
    pub events: Vec<Event>,
    pub sim_events: Vec<SimEvent>,
    pub scene: Scene,
}

fn chip_robot(
    line: Line,
    asks: Port<(), i32, usage::Query>,
    answers: &Port<(), i32, usage::Query>,
    sim: &Sim,
    feeder: FeederId,
) -> ModuleSpec<()> {
    let name = match line {
        Line::A => "CHIP_IT",
        Line::B => "CHIP_IT2",
    };
    let (asks_name, answers_name) = (asks.name().to_string(), answers.name().to_string());
    let crit_section = format!("{answers_name}.CRIT_SECTION");
    let robot = sim.robot(RobotId::new(line, Role::ChipIt));
    ModuleSpec::new(name, ())
        .order([
            format!("{asks_name}.TIMEOUT"),
            name.to_string(),
            "GRASP".into(),
            crit_section.clone(),
            "INSERT".into(),
            "BACK_OFF".into(),
        ])
        .respond(&answers.handler("CRIT_SECTION"), |_: &(), ()| 1)
        .task(name, move |ctx| {
            let (asks, robot) = (asks.clone(), robot.clone());
            async move {
                let mut share_feeder = asks.owner()?;
                loop {
                    match ctx.query(&mut share_feeder, ()).await {
                        Ok(_) => break,
                        Err(error) if error.is_timeout() => {
                            ctx.section(&Section::new("BACK_OFF"), ctx.delay(secs(1)))
                                .await;
                        }
                        Err(error) => return Err(error.into()),
                    }
                }
                ctx.section(&Section::new("GRASP"), async {
                    robot.move_to(Target::Feeder(feeder)).await?;
                    robot.grasp(feeder).await?;
                    robot.move_to(Target::Home).await
                })
                .await?;
                ctx.section(&Section::new("INSERT"), ctx.delay(secs(5)))
                    .await;
                Ok(())
            }
        })
}

/// Runs the small cell for 40 simulated seconds, recording into `record` and folding into
/// `timeline` if given.
pub fn run(record: Option<&Recorder>, timeline: Option<&Timeline>) -> Ran {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .start_paused(true)
        .build()
        .unwrap();
    runtime.block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let sim = Sim::new(SimConfig::seeded(7), Arc::clone(cell.clock()));
        if let Some(recorder) = record {
            recorder.record_cell(&cell);
            recorder.record_sim(&sim, Recorder::SCENE_PERIOD);
        }
        if let Some(timeline) = timeline {
            timeline.record_cell(&cell);
            timeline.record_sim(&sim);
        }
        sim.spawn();
        let share_feeder: Port<(), i32, usage::Query> = cell
            .port(
                PortSpec::new("SHARE_FEEDER", "CHIP_IT")
                    .user_list(["CHIP_IT2"])
                    .owner_timeout(secs(3)),
            )
            .unwrap()
            .shown();
        let share_feeder1: Port<(), i32, usage::Query> = cell
            .port(
                PortSpec::new("SHARE_FEEDER1", "CHIP_IT2")
                    .user_list(["CHIP_IT"])
                    .owner_timeout(secs(5)),
            )
            .unwrap()
            .shown();
        let a = chip_robot(
            Line::A,
            share_feeder.clone(),
            &share_feeder1,
            &sim,
            FeederId(0),
        );
        let b = chip_robot(Line::B, share_feeder1, &share_feeder, &sim, FeederId(3));
        let mut handles = [cell.start(a).unwrap(), cell.start(b).unwrap()];
        drive(&clock, Instant::from_start(secs(40))).await;
        for handle in &mut handles {
            assert_eq!(handle.finished().await, ModuleOutcome::Finished);
        }
        Ran {
            events: cell.events().snapshot(),
            sim_events: sim.log().snapshot(),
            scene: sim.scene(),
        }
    })
}

/// The name of a port or module as the recorder's topics use it.
pub fn name(text: &str) -> Name {
    Name::from(text)
}
