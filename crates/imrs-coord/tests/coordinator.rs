//! The zone coordinator as a module, with robot modules talking to it through its ports on
//! virtual time: an exclusive zone taken in turn, a deadlock resolved, an alarm that stops
//! every robot, a bad name refused, a robot stopped at a border giving up its right to move
//! in the shared zone it is in, and a robot's way checked against where the others told the
//! coordinator they are, with an alternative round them.

use std::sync::{Arc, Mutex};
use std::time::Duration;

use imrs_coord::coordinator::{CoordinatorLog, CoordinatorPorts, Message, Refused, coordinator};
use imrs_coord::zones::{DeadlockKind, Pose, Positions, Resources, ZoneDef, ZoneKind};
use imrs_core::prelude::*;
use imrs_ports::Name;

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
            ZoneDef::boxed(
                "PASSAGE",
                ZoneKind::Shared,
                [1.0, 0.0, 0.2],
                [0.1, 0.1, 0.2],
            ),
        ],
        ["SCREWDRIVER"],
        ROBOTS,
    )
}

/// Runs the cell to `seconds` of virtual time, then checks that each of `robots` finished.
async fn run_until(clock: &VirtualClock, seconds: u64, robots: &mut [ModuleHandle]) {
    imrs_core::time::drive(clock, Instant::from_start(Duration::from_secs(seconds))).await;
    for robot in robots {
        assert_eq!(robot.finished().await, ModuleOutcome::Finished);
    }
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
        Positions::new(ROBOTS, 0.035, 0.03),
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
                    link.acquire("FIXTURE").await?;
                    let entered = seconds(&ctx);
                    ctx.delay(Duration::from_secs(1)).await;
                    stays
                        .lock()
                        .unwrap()
                        .push((robot.into(), entered, seconds(&ctx)));
                    link.tell(Message::Release("FIXTURE".into())).await?;
                    ctx.delay(Duration::from_millis(300)).await;
                }
                link.tell(Message::TrajectoryEnd).await?;
                Ok(())
            }
        });
        robots.push(cell.start(spec).unwrap());
    }
    run_until(&clock, 30, &mut robots).await;
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
                    link.acquire(first).await?;
                    ctx.delay(Duration::from_secs(1)).await;
                    match link.acquire(second).await {
                        Ok(()) => break,
                        // The victim gets out of what it holds, says so, waits, and tries
                        // again.
                        Err(Refused::BackOff) => {
                            link.tell(Message::Release(first.into())).await?;
                            ctx.delay(Duration::from_secs(3)).await;
                        }
                        Err(other) => return Err(format!("{other:?}").into()),
                    }
                }
                ctx.delay(Duration::from_secs(1)).await;
                for zone in [first, second] {
                    link.tell(Message::Release(zone.into())).await?;
                }
                Ok(())
            }
        });
        robots.push(cell.start(spec).unwrap());
    }
    run_until(&clock, 30, &mut robots).await;
    let victims: Vec<Name> = (log.lock().unwrap().deadlocks.iter())
        .map(|deadlock| deadlock.victim.clone())
        .collect();
    assert_eq!(victims, ["ROBOT_B"]);
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
                let text = link.emergency().await?;
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
            // Said as the coordinator said it, and an error a task can return with `?`.
            let said: Box<dyn std::error::Error + Send + Sync> = refused.into();
            assert_eq!(
                said.to_string(),
                "no zone or tool DOOR was defined before start"
            );
            ctx.delay(Duration::from_secs(1)).await;
            link.alarm("gripper jammed").await?;
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

/// An arm along the x axis at height `y`, from x = 0 to 0.5.
fn along(y: f32) -> Pose {
    [[0.0, y], [0.25, y], [0.5, y]]
}

#[tokio::test(start_paused = true)]
async fn a_way_is_checked_against_where_the_others_said_they_are() {
    let (cell, clock, ports, log) = start();
    // ROBOT_A says where it is, later that it moved; ROBOT_B checks its way each time.
    let a = {
        let ports = ports.clone();
        ModuleSpec::new("ROBOT_A", ()).task("ROBOT_A", move |ctx| {
            let ports = ports.clone();
            async move {
                let mut link = ports.link("ROBOT_A")?;
                // Its arm reaches across the line y = 0.05, its tool at (0.5, 0).
                let across = [[0.5, -0.6], [0.5, -0.3], [0.5, 0.0]];
                link.at(across).await?;
                ctx.delay(Duration::from_secs(2)).await;
                link.at(along(1.0)).await?;
                Ok(())
            }
        })
    };
    let seen = Arc::new(Mutex::new(Vec::new()));
    let b = {
        let seen = Arc::clone(&seen);
        ModuleSpec::new("ROBOT_B", ()).task("ROBOT_B", move |ctx| {
            let (ports, seen) = (ports.clone(), Arc::clone(&seen));
            async move {
                let mut link = ports.link("ROBOT_B")?;
                let way = vec![along(0.05)];
                ctx.delay(Duration::from_secs(1)).await;
                let blocked = link.check(way.clone()).await?;
                let round = link
                    .alternative([0.0, 0.05], [1.0, 0.05], blocked.clone())
                    .await?;
                ctx.delay(Duration::from_secs(2)).await;
                let later = link.check(way).await?;
                let nowhere = link
                    .at([[f32::NAN, 0.0], [0.0, 0.0], [0.0, 0.0]])
                    .await
                    .unwrap_err();
                seen.lock().unwrap().push((blocked, round, later, nowhere));
                Ok(())
            }
        })
    };
    let mut robots = [cell.start(a).unwrap(), cell.start(b).unwrap()];
    run_until(&clock, 5, &mut robots).await;
    let (blocked, round, later, nowhere) = seen.lock().unwrap().pop().expect("B checked");
    // Where A said it was, it blocked B's way; the alternative goes round it.
    assert_eq!(blocked, ["ROBOT_A"]);
    let round = round.expect("a way round ROBOT_A");
    assert_eq!(round.first(), Some(&[0.0, 0.05]));
    assert_eq!(round.last(), Some(&[1.0, 0.05]));
    assert!(round.len() > 2, "the straight way was blocked: {round:?}");
    // Once A said it had moved, the same way was clear.
    assert!(later.is_empty(), "{later:?}");
    // A position that is no place is refused by name, and kept out of the books.
    assert_eq!(
        nowhere,
        Refused::Failed("robot ROBOT_B gave a position that is no place (not finite)".into())
    );
    let log = log.lock().unwrap();
    assert_eq!((log.checked, log.blocked, log.alternatives), (2, 1, (1, 1)));
}

/// ROBOT_C holds FIXTURE for 2 s. ROBOT_A moves in the shared PASSAGE and asks for FIXTURE;
/// ROBOT_B asks to move in PASSAGE at 0.5 s. Returns when B was granted PASSAGE, and what A
/// gave up while it slept at FIXTURE's border.
async fn border_sleep(give_up: bool) -> (f64, Vec<String>) {
    let (cell, clock, ports, log) = start();
    let granted = Arc::new(Mutex::new(None));
    let given_up = Arc::new(Mutex::new(Vec::new()));
    let c = {
        let ports = ports.clone();
        ModuleSpec::new("ROBOT_C", ()).task("ROBOT_C", move |ctx| {
            let ports = ports.clone();
            async move {
                let mut link = ports.link("ROBOT_C")?;
                link.acquire("FIXTURE").await?;
                ctx.delay(Duration::from_secs(2)).await;
                link.tell(Message::Release("FIXTURE".into())).await?;
                Ok(())
            }
        })
    };
    let a = {
        let (ports, given_up) = (ports.clone(), Arc::clone(&given_up));
        ModuleSpec::new("ROBOT_A", ()).task("ROBOT_A", move |ctx| {
            let (ports, given_up) = (ports.clone(), Arc::clone(&given_up));
            async move {
                let mut link = ports.link("ROBOT_A")?;
                ctx.delay(Duration::from_millis(100)).await;
                link.acquire("PASSAGE").await?;
                let moving_in = if give_up {
                    vec!["PASSAGE".into()]
                } else {
                    Vec::new()
                };
                let gave = link.acquire_giving_up("FIXTURE", &moving_in).await?;
                // It asks again for what it gave up before it moves on.
                for zone in &gave {
                    link.acquire(zone.as_str()).await?;
                }
                given_up
                    .lock()
                    .unwrap()
                    .extend(gave.iter().map(ToString::to_string));
                for zone in ["FIXTURE", "PASSAGE"] {
                    link.tell(Message::Release(zone.into())).await?;
                }
                Ok(())
            }
        })
    };
    let b = {
        let granted = Arc::clone(&granted);
        ModuleSpec::new("ROBOT_B", ()).task("ROBOT_B", move |ctx| {
            let (ports, granted) = (ports.clone(), Arc::clone(&granted));
            async move {
                let mut link = ports.link("ROBOT_B")?;
                ctx.delay(Duration::from_millis(500)).await;
                link.acquire("PASSAGE").await?;
                *granted.lock().unwrap() = Some(seconds(&ctx));
                ctx.delay(Duration::from_millis(500)).await;
                link.tell(Message::Release("PASSAGE".into())).await?;
                Ok(())
            }
        })
    };
    let mut robots = [
        cell.start(c).unwrap(),
        cell.start(a).unwrap(),
        cell.start(b).unwrap(),
    ];
    run_until(&clock, 10, &mut robots).await;
    assert!(log.lock().unwrap().refused.is_empty());
    let granted = granted.lock().unwrap().expect("B was granted PASSAGE");
    let given_up = given_up.lock().unwrap().clone();
    (granted, given_up)
}

#[tokio::test(start_paused = true)]
async fn a_robot_asleep_at_a_border_gives_up_moving_in_its_shared_zone() {
    // A gives up PASSAGE while it sleeps at FIXTURE's border: B moves there at once.
    let (granted, given_up) = border_sleep(true).await;
    assert_eq!(given_up, ["PASSAGE"]);
    assert!(granted < 0.6, "B waited for PASSAGE until {granted} s");
    // Without giving it up, B waits until A has FIXTURE and leaves PASSAGE: after 2 s.
    let (granted, given_up) = border_sleep(false).await;
    assert!(given_up.is_empty());
    assert!(
        granted >= 2.0,
        "B moved in PASSAGE at {granted} s, beside A"
    );
}

/// ROBOT_C holds FIXTURE until `release` s. ROBOT_A moves in the shared PASSAGE and, at
/// 0.1 s, asks for FIXTURE as it moves: told to sleep, it needs 0.3 s to stop. ROBOT_B
/// asks to move in PASSAGE at `b_asks` s. Returns when B and A were granted PASSAGE and
/// FIXTURE, and what A gave up.
async fn stopping_at_border(release: f64, b_asks: f64) -> (f64, f64, Vec<String>, Vec<Name>) {
    const BRAKING: Duration = Duration::from_millis(300);
    let (cell, clock, ports, log) = start();
    let seen: Arc<Mutex<Vec<Name>>> = Arc::default();
    let granted = Arc::new(Mutex::new((None, None)));
    let given_up = Arc::new(Mutex::new(Vec::new()));
    let c = {
        let ports = ports.clone();
        ModuleSpec::new("ROBOT_C", ()).task("ROBOT_C", move |ctx| {
            let ports = ports.clone();
            async move {
                let mut link = ports.link("ROBOT_C")?;
                link.acquire("FIXTURE").await?;
                ctx.delay(Duration::from_secs_f64(release)).await;
                link.tell(Message::Release("FIXTURE".into())).await?;
                Ok(())
            }
        })
    };
    let a = {
        let (ports, given_up, granted) =
            (ports.clone(), Arc::clone(&given_up), Arc::clone(&granted));
        ModuleSpec::new("ROBOT_A", ()).task("ROBOT_A", move |ctx| {
            let (ports, given_up, granted) =
                (ports.clone(), Arc::clone(&given_up), Arc::clone(&granted));
            async move {
                let mut link = ports.link("ROBOT_A")?;
                link.acquire("PASSAGE").await?;
                ctx.delay(Duration::from_millis(100)).await;
                let braking = &ctx;
                let gave = link
                    .acquire_stopping("FIXTURE", &["PASSAGE".into()], || async {
                        braking.delay(BRAKING).await;
                        // Stopped across the line y = 0.05.
                        (Some([[0.5, -0.6], [0.5, -0.3], [0.5, 0.0]]), true)
                    })
                    .await?;
                granted.lock().unwrap().1 = Some(seconds(&ctx));
                for zone in &gave {
                    link.acquire(zone.as_str()).await?;
                }
                given_up
                    .lock()
                    .unwrap()
                    .extend(gave.iter().map(ToString::to_string));
                ctx.delay(Duration::from_millis(200)).await;
                for zone in ["FIXTURE", "PASSAGE"] {
                    link.tell(Message::Release(zone.into())).await?;
                }
                Ok(())
            }
        })
    };
    let b = {
        let (granted, seen) = (Arc::clone(&granted), Arc::clone(&seen));
        ModuleSpec::new("ROBOT_B", ()).task("ROBOT_B", move |ctx| {
            let (ports, granted) = (ports.clone(), Arc::clone(&granted));
            let seen_stopped = Arc::clone(&seen);
            async move {
                let mut link = ports.link("ROBOT_B")?;
                ctx.delay(Duration::from_secs_f64(b_asks)).await;
                link.acquire("PASSAGE").await?;
                granted.lock().unwrap().0 = Some(seconds(&ctx));
                // Where A stopped, if it said: in the way along y = 0.05.
                let blocked = link.check(vec![along(0.05)]).await?;
                seen_stopped.lock().unwrap().extend(blocked);
                ctx.delay(Duration::from_millis(100)).await;
                link.tell(Message::Release("PASSAGE".into())).await?;
                Ok(())
            }
        })
    };
    let mut robots = [
        cell.start(c).unwrap(),
        cell.start(a).unwrap(),
        cell.start(b).unwrap(),
    ];
    run_until(&clock, 10, &mut robots).await;
    assert!(log.lock().unwrap().refused.is_empty());
    let (b, a) = *granted.lock().unwrap();
    let given_up = given_up.lock().unwrap().clone();
    let seen = seen.lock().unwrap().clone();
    (
        b.expect("B was granted PASSAGE"),
        a.expect("A was granted FIXTURE"),
        given_up,
        seen,
    )
}

#[tokio::test(start_paused = true)]
async fn a_robot_told_to_sleep_keeps_its_right_to_move_until_it_has_stopped() {
    // A brakes from 0.1 s to 0.4 s in PASSAGE: B, asking at 0.2 s, moves there only once A
    // has stopped and given it up.
    let (b, a, given_up, seen) = stopping_at_border(2.0, 0.2).await;
    // Stopped, A told where: B's check finds it in the way.
    assert_eq!(seen, ["ROBOT_A"]);
    assert_eq!(given_up, ["PASSAGE"]);
    assert!((0.4..0.45).contains(&b), "B moved in PASSAGE at {b} s");
    assert!(a >= 2.0, "A had FIXTURE at {a} s, before C left it");
    // Woken while it still brakes, A is granted at once, and gives nothing up: B waits
    // until A leaves PASSAGE.
    let (b, a, given_up, seen) = stopping_at_border(0.2, 0.25).await;
    // Woken before it stopped, A told nothing yet.
    assert!(seen.is_empty(), "{seen:?}");
    assert!(given_up.is_empty(), "{given_up:?}");
    assert!((0.2..0.25).contains(&a), "A had FIXTURE at {a} s");
    assert!(b >= a + 0.2, "B moved in PASSAGE at {b} s, beside A");
}

/// The robot that closes a cycle, and is chosen to back off, is one that gives up its
/// right to move in a shared zone as it sleeps: the coordinator must not wait on it.
#[tokio::test(start_paused = true)]
async fn a_victim_that_gives_up_a_shared_zone_as_it_sleeps_is_told_to_back_off() {
    let (cell, clock, ports, log) = start();
    let a = {
        let ports = ports.clone();
        ModuleSpec::new("ROBOT_A", ()).task("ROBOT_A", move |ctx| {
            let ports = ports.clone();
            async move {
                let mut link = ports.link("ROBOT_A")?;
                link.acquire("FIXTURE").await?;
                ctx.delay(Duration::from_secs(1)).await;
                // Sleeps: ROBOT_B has TRAY; granted once B backs off.
                link.acquire("TRAY").await?;
                Ok(())
            }
        })
    };
    let outcome = Arc::new(Mutex::new(None));
    let b = {
        let outcome = Arc::clone(&outcome);
        ModuleSpec::new("ROBOT_B", ()).task("ROBOT_B", move |ctx| {
            let (ports, outcome) = (ports.clone(), Arc::clone(&outcome));
            async move {
                let mut link = ports.link("ROBOT_B")?;
                link.acquire("TRAY").await?;
                link.acquire("PASSAGE").await?;
                ctx.delay(Duration::from_secs(2)).await;
                // FIXTURE is A's, A waits for TRAY: B closes the cycle, and is its victim.
                let asked = link.acquire_giving_up("FIXTURE", &["PASSAGE".into()]).await;
                *outcome.lock().unwrap() = Some(asked);
                // Backed off: it gets out of TRAY and says so.
                link.tell(Message::Release("TRAY".into())).await?;
                Ok(())
            }
        })
    };
    let mut robots = [cell.start(a).unwrap(), cell.start(b).unwrap()];
    run_until(&clock, 10, &mut robots).await;
    assert_eq!(*outcome.lock().unwrap(), Some(Err(Refused::BackOff)));
    assert_eq!(
        Refused::BackOff.to_string(),
        "told to back off, the victim of a deadlock"
    );
    let victims: Vec<Name> = (log.lock().unwrap().deadlocks.iter())
        .map(|deadlock| deadlock.victim.clone())
        .collect();
    assert_eq!(victims, ["ROBOT_B"]);
}

/// A robot woken once is on its way to ask again: a second event that would wake it (here
/// a release of the zone it waits for, by a robot that was not in it) must not make the
/// coordinator wait for it, or neither would move again.
#[tokio::test(start_paused = true)]
async fn a_robot_woken_twice_before_it_asks_again_is_not_waited_for() {
    let (cell, clock, ports, _log) = start();
    let moved = Arc::new(Mutex::new(None));
    let spec = |robot: &'static str| {
        let (ports, moved) = (ports.clone(), Arc::clone(&moved));
        ModuleSpec::new(robot, ()).task(robot, move |ctx| {
            let (ports, moved) = (ports.clone(), Arc::clone(&moved));
            async move {
                let mut link = ports.link(robot)?;
                match robot {
                    // Moves in PASSAGE, and at 1 s stops inside it.
                    "ROBOT_A" => {
                        link.acquire("PASSAGE").await?;
                        ctx.delay(Duration::from_secs(1)).await;
                        link.tell(Message::Position("PASSAGE".into())).await?;
                    }
                    // At 1 s too, just after A, says it left PASSAGE, which it was never
                    // in: its timer is set later than A's for the same instant.
                    "ROBOT_B" => {
                        ctx.delay(Duration::from_millis(500)).await;
                        ctx.delay(Duration::from_millis(500)).await;
                        link.tell(Message::Release("PASSAGE".into())).await?;
                    }
                    // Waits to move in PASSAGE.
                    _ => {
                        ctx.delay(Duration::from_millis(100)).await;
                        link.acquire("PASSAGE").await?;
                        *moved.lock().unwrap() = Some(seconds(&ctx));
                    }
                }
                Ok(())
            }
        })
    };
    let mut robots = ROBOTS.map(|robot| cell.start(spec(robot)).unwrap());
    imrs_core::time::drive(&clock, Instant::from_start(Duration::from_secs(5))).await;
    // Frozen, no robot would finish: fail then, rather than wait for ever.
    for robot in &mut robots {
        let finished = tokio::time::timeout(Duration::from_secs(60), robot.finished()).await;
        assert_eq!(finished.ok(), Some(ModuleOutcome::Finished));
    }
    assert_eq!(*moved.lock().unwrap(), Some(1.0));
}

/// ROBOT_A is in FIXTURE. ROBOT_B says it stands across A's way out, and asks for `wants`
/// (FIXTURE, or TRAY, which ROBOT_C holds for 3 s): it sleeps. A checks its way out at 1 s,
/// and at 1.5 s says it waits on it. Returns what A's check found, what B heard and when,
/// and the coordinator's log.
async fn asleep_in_the_way(wants: &'static str) -> (Vec<String>, (String, f64), CoordinatorLog) {
    let (cell, clock, ports, log) = start();
    let found = Arc::new(Mutex::new(Vec::new()));
    let heard = Arc::new(Mutex::new((String::new(), 0.0)));
    let c = {
        let ports = ports.clone();
        ModuleSpec::new("ROBOT_C", ()).task("ROBOT_C", move |ctx| {
            let ports = ports.clone();
            async move {
                let mut link = ports.link("ROBOT_C")?;
                link.acquire("TRAY").await?;
                ctx.delay(Duration::from_secs(3)).await;
                link.tell(Message::Release("TRAY".into())).await?;
                Ok(())
            }
        })
    };
    let a = {
        let (ports, found) = (ports.clone(), Arc::clone(&found));
        ModuleSpec::new("ROBOT_A", ()).task("ROBOT_A", move |ctx| {
            let (ports, found) = (ports.clone(), Arc::clone(&found));
            async move {
                let mut link = ports.link("ROBOT_A")?;
                link.acquire("FIXTURE").await?;
                ctx.delay(Duration::from_secs(1)).await;
                let blocked = link.check(vec![along(0.05)]).await?;
                found
                    .lock()
                    .unwrap()
                    .extend(blocked.iter().map(ToString::to_string));
                ctx.delay(Duration::from_millis(500)).await;
                link.wait_on(vec![along(0.05)]).await?;
                ctx.delay(Duration::from_millis(500)).await;
                link.tell(Message::Release("FIXTURE".into())).await?;
                Ok(())
            }
        })
    };
    let b = {
        let heard = Arc::clone(&heard);
        ModuleSpec::new("ROBOT_B", ()).task("ROBOT_B", move |ctx| {
            let (ports, heard) = (ports.clone(), Arc::clone(&heard));
            async move {
                let mut link = ports.link("ROBOT_B")?;
                ctx.delay(Duration::from_millis(500)).await;
                // Its arm reaches across the line y = 0.05.
                link.at([[0.5, -0.6], [0.5, -0.3], [0.5, 0.0]]).await?;
                let asked = link.acquire(wants).await;
                *heard.lock().unwrap() = (format!("{asked:?}"), seconds(&ctx));
                Ok(())
            }
        })
    };
    let mut robots = [
        cell.start(c).unwrap(),
        cell.start(a).unwrap(),
        cell.start(b).unwrap(),
    ];
    run_until(&clock, 10, &mut robots).await;
    let found = found.lock().unwrap().clone();
    let heard = heard.lock().unwrap().clone();
    let log = log.lock().unwrap().clone();
    (found, heard, log)
}

#[tokio::test(start_paused = true)]
async fn a_robot_asleep_in_the_way_of_the_one_it_waits_for_is_told_to_back_off() {
    // B sleeps on FIXTURE, which A holds, across A's way out: neither could go on. A
    // check alone tells nobody to back off; once A says it waits, B is told to.
    let (found, (heard, at), log) = asleep_in_the_way("FIXTURE").await;
    assert_eq!(found, ["ROBOT_B"]);
    assert_eq!(heard, "Err(BackOff)");
    assert!((1.5..1.6).contains(&at), "B was told at {at} s");
    assert_eq!(log.in_the_way, [("ROBOT_B".into(), DeadlockKind::Zone)]);
    // B sleeps on TRAY, which C holds: A waits for B's space, B for C, C for nothing. Not a
    // deadlock: B is granted once C leaves.
    let (found, (heard, at), log) = asleep_in_the_way("TRAY").await;
    assert_eq!(found, ["ROBOT_B"]);
    assert_eq!(heard, "Ok(())");
    assert!(at >= 3.0, "B was granted TRAY at {at} s");
    assert!(log.in_the_way.is_empty(), "{:?}", log.in_the_way);
}
