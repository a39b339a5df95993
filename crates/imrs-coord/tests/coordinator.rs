//! The zone coordinator as a module, with robot modules talking to it through its ports on
//! virtual time: an exclusive zone taken in turn, a deadlock resolved, an alarm that stops
//! every robot, a bad name refused.

use std::sync::{Arc, Mutex};
use std::time::Duration;

use imrs_coord::coordinator::{CoordinatorLog, CoordinatorPorts, Message, Refused, coordinator};
use imrs_coord::zones::{Resources, ZoneDef, ZoneKind};
use imrs_core::prelude::*;

const ROBOTS: [&str; 3] = ["ROBOT_A", "ROBOT_B", "ROBOT_C"];

fn table() -> Resources {
    Resources::new(
        [
            ZoneDef::boxed(
                "FIXTURE",
                ZoneKind::Exclusive,
                [0.0, 0.0, 0.2],
                [0.1, 0.1, 0.2],
            ),
            ZoneDef::boxed(
                "TRAY",
                ZoneKind::Exclusive,
                [0.5, 0.0, 0.2],
                [0.1, 0.1, 0.2],
            ),
        ],
        ["SCREWDRIVER"],
        ROBOTS,
    )
}

/// (robot, entered, left) for each stay in a zone, in seconds.
type Stays = Arc<Mutex<Vec<(String, f64, f64)>>>;

fn start() -> (
    Cell,
    VirtualClock,
    CoordinatorPorts,
    Arc<Mutex<CoordinatorLog>>,
) {
    let (cell, clock) = Cell::virtual_clock();
    let ports = CoordinatorPorts::new("COORDINATOR", &ROBOTS, cell.clock());
    let log = Arc::new(Mutex::new(CoordinatorLog::default()));
    cell.start(coordinator(
        "COORDINATOR",
        table(),
        &ports,
        Arc::clone(&log),
    ))
    .unwrap();
    (cell, clock, ports, log)
}

fn seconds(ctx: &Ctx<()>) -> f64 {
    ctx.now().since_start().as_secs_f64()
}

#[tokio::test(start_paused = true)]
async fn an_exclusive_zone_is_taken_in_turn_through_the_coordinator() {
    let (cell, clock, ports, log) = start();
    let stays: Stays = Arc::default();
    let mut robots = Vec::new();
    for robot in ["ROBOT_A", "ROBOT_B"] {
        let (ports, stays) = (ports.clone(), Arc::clone(&stays));
        let spec = ModuleSpec::new(robot, ()).task(robot, move |ctx| {
            let (ports, stays) = (ports.clone(), Arc::clone(&stays));
            async move {
                let mut link = ports.link(robot)?;
                for _ in 0..5 {
                    link.acquire("FIXTURE")
                        .await
                        .map_err(|e| format!("{e:?}"))?;
                    let entered = seconds(&ctx);
                    ctx.delay(Duration::from_secs(1)).await;
                    stays
                        .lock()
                        .unwrap()
                        .push((robot.into(), entered, seconds(&ctx)));
                    link.tell(Message::Release("FIXTURE".into()))
                        .await
                        .map_err(|e| format!("{e:?}"))?;
                    ctx.delay(Duration::from_millis(300)).await;
                }
                link.tell(Message::TrajectoryEnd)
                    .await
                    .map_err(|e| format!("{e:?}"))?;
                Ok(())
            }
        });
        robots.push(cell.start(spec).unwrap());
    }
    imrs_core::time::drive(&clock, Instant::from_start(Duration::from_secs(30))).await;
    for robot in &mut robots {
        assert_eq!(robot.finished().await, ModuleOutcome::Finished);
    }
    let stays = stays.lock().unwrap().clone();
    assert_eq!(stays.len(), 10);
    for (i, a) in stays.iter().enumerate() {
        for b in &stays[i + 1..] {
            let overlap = a.1 < b.2 && b.1 < a.2;
            assert!(
                !(overlap && a.0 != b.0),
                "{a:?} and {b:?} were in FIXTURE together"
            );
        }
    }
    let log = log.lock().unwrap();
    assert!(
        log.slept > 0,
        "no robot ever waited: the test proves nothing"
    );
    assert!(log.refused.is_empty(), "{:?}", log.refused);
}

#[tokio::test(start_paused = true)]
async fn a_deadlock_between_two_robots_is_resolved_by_the_coordinator() {
    let (cell, clock, ports, log) = start();
    let mut robots = Vec::new();
    for (robot, first, second) in [
        ("ROBOT_A", "FIXTURE", "TRAY"),
        ("ROBOT_B", "TRAY", "FIXTURE"),
    ] {
        let ports = ports.clone();
        let spec = ModuleSpec::new(robot, ()).task(robot, move |ctx| {
            let ports = ports.clone();
            async move {
                let mut link = ports.link(robot)?;
                loop {
                    link.acquire(first).await.map_err(|e| format!("{e:?}"))?;
                    ctx.delay(Duration::from_secs(1)).await;
                    match link.acquire(second).await {
                        Ok(()) => break,
                        // The victim gave up what it held; it waits, then tries again.
                        Err(Refused::BackOff) => ctx.delay(Duration::from_secs(3)).await,
                        Err(other) => return Err(format!("{other:?}").into()),
                    }
                }
                ctx.delay(Duration::from_secs(1)).await;
                for zone in [first, second] {
                    link.tell(Message::Release(zone.into()))
                        .await
                        .map_err(|e| format!("{e:?}"))?;
                }
                Ok(())
            }
        });
        robots.push(cell.start(spec).unwrap());
    }
    imrs_core::time::drive(&clock, Instant::from_start(Duration::from_secs(30))).await;
    for robot in &mut robots {
        assert_eq!(robot.finished().await, ModuleOutcome::Finished);
    }
    assert_eq!(log.lock().unwrap().deadlocks, ["ROBOT_B"]);
}

#[tokio::test(start_paused = true)]
async fn an_alarm_stops_every_robot_and_a_bad_name_is_refused() {
    let (cell, clock, ports, log) = start();
    let heard = Arc::new(Mutex::new(Vec::new()));
    for robot in ["ROBOT_A", "ROBOT_B"] {
        let (ports, heard) = (ports.clone(), Arc::clone(&heard));
        let spec = ModuleSpec::new(robot, ()).task(robot, move |_ctx| {
            let (ports, heard) = (ports.clone(), Arc::clone(&heard));
            async move {
                let mut link = ports.link(robot)?;
                let text = link.emergency().await.map_err(|e| format!("{e:?}"))?;
                heard.lock().unwrap().push((robot, text));
                Ok(())
            }
        });
        cell.start(spec).unwrap();
    }
    let spec = ModuleSpec::new("ROBOT_C", ()).task("ROBOT_C", move |ctx| {
        let ports = ports.clone();
        async move {
            let mut link = ports.link("ROBOT_C")?;
            let refused = link.acquire("DOOR").await.unwrap_err();
            assert_eq!(
                refused,
                Refused::Failed("no zone or tool DOOR was defined before start".into())
            );
            ctx.delay(Duration::from_secs(1)).await;
            link.alarm("gripper jammed")
                .await
                .map_err(|e| format!("{e:?}"))?;
            Ok(())
        }
    });
    let mut c = cell.start(spec).unwrap();
    imrs_core::time::drive(&clock, Instant::from_start(Duration::from_secs(5))).await;
    assert_eq!(c.finished().await, ModuleOutcome::Finished);
    let mut heard = heard.lock().unwrap().clone();
    heard.sort();
    assert_eq!(
        heard,
        [
            ("ROBOT_A", "ROBOT_C: gripper jammed".to_string()),
            ("ROBOT_B", "ROBOT_C: gripper jammed".to_string())
        ]
    );
    let log = log.lock().unwrap();
    assert_eq!(log.alarms.len(), 1);
    assert_eq!(log.refused.len(), 1);
}
