//! Zones and tools as resources, as the coordinator of Jiménez et al. 1992 shares them: exclusive and
//! shared zones, tools, the active-zone grant, deadlocks found and resolved, and the arm's
//! pipeline stopping before a zone it may not enter.

use imrs_coord::zones::{
    Answer, Command, DeadlockKind, Pipeline, Pose, Positions, Resources, ZoneDef, ZoneError,
    ZoneKind,
};

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
                "FEEDERS",
                ZoneKind::Shared,
                [0.0, 0.5, 0.2],
                [0.1, 0.1, 0.2],
            ),
            ZoneDef::boxed("BIN", ZoneKind::Shared, [0.5, 0.5, 0.2], [0.1, 0.1, 0.2]),
        ],
        ["SCREWDRIVER", "GRIPPER"],
        ["ARM_A", "ARM_B", "ARM_C"],
    )
}

#[test]
fn an_exclusive_zone_takes_one_robot_and_wakes_the_next_when_it_leaves() -> Result<(), ZoneError> {
    let mut t = table();
    assert_eq!(t.request_move("ARM_A", "FIXTURE")?, Answer::Grant);
    assert_eq!(t.request_move("ARM_B", "FIXTURE")?, Answer::Sleep);
    assert_eq!(t.request_move("ARM_C", "FIXTURE")?, Answer::Sleep);
    assert!(
        t.stopped_inside("ARM_A", "FIXTURE")?.is_empty(),
        "still inside"
    );
    assert_eq!(t.release("ARM_A", "FIXTURE")?, ["ARM_B"]);
    // First come, first served: C may not jump the queue.
    assert_eq!(t.request_move("ARM_C", "FIXTURE")?, Answer::Sleep);
    assert_eq!(t.request_move("ARM_B", "FIXTURE")?, Answer::Grant);
    Ok(())
}

#[test]
fn a_robot_inside_asking_again_is_not_queued_behind_those_at_the_border() -> Result<(), ZoneError> {
    // A robot that stopped inside and sets off again asks for the zone again. Queued behind
    // the sleepers at the border, it would wait for them while they wait for it to leave.
    let mut t = table();
    assert_eq!(t.request_move("ARM_A", "FIXTURE")?, Answer::Grant);
    assert_eq!(t.request_move("ARM_B", "FIXTURE")?, Answer::Sleep);
    t.trajectory_end("ARM_A")?;
    assert_eq!(t.request_move("ARM_A", "FIXTURE")?, Answer::Grant);
    assert_eq!(t.release("ARM_A", "FIXTURE")?, ["ARM_B"]);
    // So with a tool: its holder asking again keeps it.
    assert_eq!(t.request_tool("ARM_A", "GRIPPER")?, Answer::Grant);
    assert_eq!(t.request_tool("ARM_C", "GRIPPER")?, Answer::Sleep);
    assert_eq!(t.request_tool("ARM_A", "GRIPPER")?, Answer::Grant);
    assert_eq!(t.deadlock(), None);
    Ok(())
}

#[test]
fn a_shared_zone_holds_several_robots_but_lets_one_move() -> Result<(), ZoneError> {
    let mut t = table();
    assert_eq!(t.request_move("ARM_A", "FEEDERS")?, Answer::Grant);
    assert_eq!(t.request_move("ARM_B", "FEEDERS")?, Answer::Sleep);
    assert_eq!(t.stopped_inside("ARM_A", "FEEDERS")?, ["ARM_B"]);
    assert_eq!(t.request_move("ARM_B", "FEEDERS")?, Answer::Grant);
    // A is still inside, stopped; to move again it waits for B to stop or leave.
    assert_eq!(t.request_move("ARM_A", "FEEDERS")?, Answer::Sleep);
    assert_eq!(t.release("ARM_B", "FEEDERS")?, ["ARM_A"]);
    assert_eq!(t.request_move("ARM_A", "FEEDERS")?, Answer::Grant);
    Ok(())
}

#[test]
fn zones_change_only_while_every_robot_is_stopped() -> Result<(), ZoneError> {
    let mut t = table();
    t.request_move("ARM_A", "TRAY")?;
    let error = t.set_active("FIXTURE", false).unwrap_err();
    assert_eq!(
        error.to_string(),
        "zones change only while every robot is stopped; moving: ARM_A"
    );
    t.trajectory_end("ARM_A")?;
    t.set_active("FIXTURE", false)?;
    // An inactive zone restricts nothing, and no point lies in it.
    assert_eq!(t.request_move("ARM_B", "FIXTURE")?, Answer::Grant);
    assert_eq!(t.request_move("ARM_C", "FIXTURE")?, Answer::Grant);
    assert!(t.zones_at([0.0, 0.0, 0.1]).is_empty());
    assert_eq!(t.zones_at([0.5, 0.0, 0.1]), ["TRAY"]);
    Ok(())
}

#[test]
fn names_it_does_not_know_are_refused_by_name() {
    let mut t = table();
    assert_eq!(
        t.request_move("ARM_A", "DOOR").unwrap_err().to_string(),
        "no zone or tool DOOR was defined before start"
    );
    assert_eq!(
        t.request_tool("ARM_Z", "GRIPPER").unwrap_err().to_string(),
        "no robot ARM_Z in the cell"
    );
    assert!(
        t.request_tool("ARM_A", "FIXTURE").is_err(),
        "a zone is not a tool"
    );
}

/// Exclusive zones meet every condition for deadlock: two robots each holding one and
/// asking for the other's. The coordinator finds the cycle, one backs off, the other goes.
#[test]
fn a_zone_deadlock_is_found_and_resolved() -> Result<(), ZoneError> {
    let mut t = table();
    t.request_move("ARM_A", "FIXTURE")?;
    t.request_move("ARM_B", "TRAY")?;
    assert_eq!(t.deadlock(), None);
    assert_eq!(t.request_move("ARM_A", "TRAY")?, Answer::Sleep);
    assert_eq!(t.request_move("ARM_B", "FIXTURE")?, Answer::Sleep);
    let deadlock = t.deadlock().expect("the cycle A → B → A");
    assert_eq!(deadlock.cycle, ["ARM_A", "ARM_B"]);
    assert_eq!(deadlock.waiting_on, ["TRAY", "FIXTURE"]);
    assert_eq!(deadlock.kind, DeadlockKind::Zone);
    assert_eq!(deadlock.victim, "ARM_B");
    // B stops waiting: the cycle is broken, but TRAY is B's until it has left it.
    assert!(t.resolve(&deadlock)?.is_empty());
    assert_eq!(t.deadlock(), None);
    assert_eq!(t.request_move("ARM_A", "TRAY")?, Answer::Sleep);
    assert_eq!(t.release("ARM_B", "TRAY")?, ["ARM_A"]);
    assert_eq!(t.request_move("ARM_A", "TRAY")?, Answer::Grant);
    Ok(())
}

#[test]
fn a_tool_deadlock_is_found_and_resolved() -> Result<(), ZoneError> {
    let mut t = table();
    t.request_tool("ARM_A", "SCREWDRIVER")?;
    t.request_tool("ARM_C", "GRIPPER")?;
    assert_eq!(t.request_tool("ARM_A", "GRIPPER")?, Answer::Sleep);
    assert_eq!(t.request_tool("ARM_C", "SCREWDRIVER")?, Answer::Sleep);
    let deadlock = t.deadlock().expect("a tool cycle");
    assert_eq!(deadlock.kind, DeadlockKind::Tool);
    assert_eq!(deadlock.waiting_on, ["GRIPPER", "SCREWDRIVER"]);
    assert_eq!(deadlock.victim, "ARM_C");
    // C stops waiting; the gripper is C's until it has put it down.
    assert!(t.resolve(&deadlock)?.is_empty());
    assert_eq!(t.request_tool("ARM_A", "GRIPPER")?, Answer::Sleep);
    assert_eq!(t.release_tool("ARM_C", "GRIPPER")?, ["ARM_A"]);
    assert_eq!(t.request_tool("ARM_A", "GRIPPER")?, Answer::Grant);
    Ok(())
}

/// A robot inside an exclusive zone asks for the tool that another holds, which asks for
/// that zone: a tool deadlock, though one of its waits is for a zone.
#[test]
fn a_cycle_through_a_zone_and_a_tool_is_a_tool_deadlock() -> Result<(), ZoneError> {
    let mut t = table();
    assert_eq!(t.request_move("ARM_A", "FIXTURE")?, Answer::Grant);
    assert_eq!(t.request_tool("ARM_B", "SCREWDRIVER")?, Answer::Grant);
    assert_eq!(t.request_tool("ARM_A", "SCREWDRIVER")?, Answer::Sleep);
    assert_eq!(t.deadlock(), None);
    assert_eq!(t.request_move("ARM_B", "FIXTURE")?, Answer::Sleep);
    let deadlock = t.deadlock().expect("A waits for B's tool, B for A's zone");
    assert_eq!(deadlock.kind, DeadlockKind::Tool);
    assert_eq!(deadlock.cycle, ["ARM_A", "ARM_B"]);
    assert_eq!(deadlock.waiting_on, ["SCREWDRIVER", "FIXTURE"]);
    Ok(())
}

/// A robot that keeps its right to move in a shared zone while it sleeps at an exclusive
/// zone's border closes a mixed cycle with the robot inside that zone, which waits to move
/// in the shared one: the wait-for graph has the movement right, so it is found. The victim
/// stops waiting and, stopped, moves nowhere.
#[test]
fn a_mixed_shared_and_exclusive_deadlock_is_found_and_resolved() -> Result<(), ZoneError> {
    let mut t = table();
    assert_eq!(t.request_move("ARM_A", "FEEDERS")?, Answer::Grant);
    assert_eq!(t.request_move("ARM_B", "FIXTURE")?, Answer::Grant);
    // A keeps moving in FEEDERS while it sleeps at FIXTURE's border.
    assert_eq!(t.request_move("ARM_A", "FIXTURE")?, Answer::Sleep);
    assert_eq!(t.deadlock(), None);
    assert_eq!(t.request_move("ARM_B", "FEEDERS")?, Answer::Sleep);
    let deadlock = t
        .deadlock()
        .expect("A waits for B's zone, B for A's movement");
    assert_eq!(deadlock.kind, DeadlockKind::Mixed);
    assert_eq!(deadlock.waiting_on, ["FIXTURE", "FEEDERS"]);
    assert_eq!(deadlock.victim, "ARM_B");
    assert!(t.resolve(&deadlock)?.is_empty());
    assert_eq!(t.deadlock(), None);
    // B leaves FIXTURE: A has it.
    assert_eq!(t.release("ARM_B", "FIXTURE")?, ["ARM_A"]);
    assert_eq!(t.request_move("ARM_A", "FIXTURE")?, Answer::Grant);
    Ok(())
}

/// In shared zones a robot refused the next zone stops at the border and gives up moving
/// in its own: nobody holds two movement resources, so no cycle can form.
#[test]
fn shared_zones_never_deadlock_because_movement_is_released_at_the_border() -> Result<(), ZoneError>
{
    let mut t = table();
    t.request_move("ARM_A", "FEEDERS")?;
    t.request_move("ARM_B", "BIN")?;
    assert_eq!(t.request_move("ARM_A", "BIN")?, Answer::Sleep);
    assert!(t.stopped_inside("ARM_A", "FEEDERS")?.is_empty());
    assert_eq!(t.request_move("ARM_B", "FEEDERS")?, Answer::Grant);
    assert_eq!(t.deadlock(), None);
    assert_eq!(t.stopped_inside("ARM_B", "BIN")?, ["ARM_A"]);
    assert_eq!(t.request_move("ARM_A", "BIN")?, Answer::Grant);
    Ok(())
}

/// A straight line through the fixture at z = 0.1, from x0 to x1, a point per centimetre.
fn line(x0: f32, x1: f32) -> Vec<[f32; 3]> {
    let n = ((x1 - x0).abs() / 0.01).round() as usize;
    (0..=n)
        .map(|i| [x0 + (x1 - x0) * i as f32 / n as f32, 0.0, 0.1])
        .collect()
}

/// Two arms cross the exclusive fixture from either side. Each checks its points `offset`
/// ahead: the one that comes second is stopped (STOP_C) while still outside, at least
/// `offset` points before the zone, and continues once the first has left. Never are both
/// inside.
#[test]
fn the_pipeline_stops_an_arm_before_a_zone_it_may_not_enter() -> Result<(), ZoneError> {
    let mut t = table();
    let fixture = ZoneDef::boxed(
        "FIXTURE",
        ZoneKind::Exclusive,
        [0.0, 0.0, 0.2],
        [0.1, 0.1, 0.2],
    );
    // 0.5 m/s, 2.5 m/s²: 5 cm to stop, five points.
    let mut arms = [
        Pipeline::new("ARM_A", line(-0.3, 0.3), 0.5, 2.5, 0.01),
        Pipeline::new("ARM_B", line(0.25, -0.3), 0.5, 2.5, 0.01),
    ];
    assert_eq!((arms[0].offset(), arms[0].capacity()), (5, 7));
    let mut at: [Option<[f32; 3]>; 2] = [None, None];
    let mut done = [false, false];
    let mut stops = [0, 0];
    for _ in 0..400 {
        for (i, arm) in arms.iter_mut().enumerate() {
            if done[i] {
                continue;
            }
            match arm.step(&mut t)?.0 {
                Command::Continue(p) => at[i] = Some(p),
                Command::StopC(zone) => {
                    assert_eq!(zone, "FIXTURE");
                    stops[i] += 1;
                    let here = at[i].expect("stopped before it started");
                    assert!(!fixture.contains(here), "arm {i} was stopped inside");
                    // At least `offset` points (1 cm each) from the zone's nearer face.
                    let gap = here[0].abs() - 0.1;
                    assert!(
                        gap >= 0.05 - 1e-4,
                        "arm {i} stopped {gap} m short of the zone"
                    );
                }
                Command::TrajectoryEnd => done[i] = true,
            }
        }
        let inside = at
            .iter()
            .filter(|p| p.is_some_and(|p| fixture.contains(p)))
            .count();
        assert!(inside < 2, "both arms in the exclusive zone");
        if done == [true, true] {
            break;
        }
    }
    assert_eq!(done, [true, true], "an arm never finished");
    assert_eq!(
        stops.iter().filter(|&&n| n > 0).count(),
        1,
        "stops: {stops:?}"
    );
    Ok(())
}

/// A stopped arm lies across the way: the trajectory is blocked, the alternative goes round
/// it from the same start to the same end and keeps its margin everywhere (checked here by
/// sampling the path, apart from the search that found it).
#[test]
fn a_geometric_deadlock_is_resolved_by_an_alternative_trajectory() {
    use imrs_coord::zones::{Obstacle, detour, first_blocked};
    let z = 0.3;
    let stopped = Obstacle::links(
        &[
            ([-0.3, 0.0, z], [0.05, 0.0, z]),
            ([0.05, 0.0, z], [0.05, 0.2, z]),
        ],
        0.035,
    );
    let path: Vec<[f32; 3]> = (0..=10).map(|i| [0.0, -0.5 + 0.1 * i as f32, z]).collect();
    let (radius, margin) = (0.02, 0.01);
    assert_eq!(
        first_blocked(&path, radius, std::slice::from_ref(&stopped), margin),
        Some(4)
    );
    let around =
        detour(&path, radius, std::slice::from_ref(&stopped), margin, 0.6).expect("a way round");
    assert_eq!(around.first(), path.first());
    assert_eq!(around.last(), path.last());
    for pair in around.windows(2) {
        for k in 0..=20 {
            let t = k as f32 / 20.0;
            let p = [0, 1, 2].map(|i| pair[0][i] + (pair[1][i] - pair[0][i]) * t);
            assert!(
                stopped.distance(p, p, radius) >= margin,
                "the detour touches at {p:?}"
            );
        }
    }
    let length = |p: &[[f32; 3]]| -> f32 {
        p.windows(2)
            .map(|s| ((s[1][0] - s[0][0]).powi(2) + (s[1][1] - s[0][1]).powi(2)).sqrt())
            .sum()
    };
    assert!(
        length(&around) < 2.5 * length(&path),
        "a detour of {} m",
        length(&around)
    );
    // Nothing in the way: the trajectory stands.
    let clear = Obstacle::links(&[([1.0, 1.0, z], [1.2, 1.0, z])], 0.035);
    assert_eq!(
        detour(&path, radius, &[clear], margin, 0.6),
        Some(path.clone())
    );
    // A robot stopped on the end point: no alternative; only it moving can free the way.
    let on_goal = Obstacle::links(&[([-0.2, 0.5, z], [0.2, 0.5, z])], 0.035);
    assert_eq!(detour(&path, radius, &[on_goal], margin, 0.6), None);
}

/// An arm from (0, 0) reaching straight out to x = 0.7 at height `y`.
fn reach(y: f32) -> imrs_coord::zones::Sweep {
    (0..=5)
        .map(|i| {
            let x = 0.7 * i as f32 / 5.0;
            [[0.0, y], [x / 2.0, y], [x, y]]
        })
        .collect()
}

/// Zones that follow the trajectories: sweeps that keep clear are held at once, one that
/// meets a held sweep waits for its release, and a later request never jumps an earlier
/// one it would block.
#[test]
fn reservations_grant_sweeps_that_keep_clear_and_queue_the_others() {
    use imrs_coord::zones::Reservations;
    // An arm from (0, 0) reaching straight out to x = 0.7 at height y.
    let mut space = Reservations::new(0.035, 0.03);
    assert!(space.request("ARM_A", &reach(0.0)));
    assert!(space.request("ARM_B", &reach(0.2)), "20 cm apart: clear");
    assert!(
        !space.request("ARM_C", &reach(0.05)),
        "5 cm from A's: must wait"
    );
    // D is clear of A and B but would block C, which asked first: it waits its turn.
    assert!(!space.request("ARM_D", &reach(0.1)));
    assert_eq!(space.release("ARM_B"), Vec::<imrs_ports::Name>::new());
    assert_eq!(space.release("ARM_A"), ["ARM_C"]);
    assert_eq!(space.release("ARM_C"), ["ARM_D"]);
    assert_eq!(space.holders(), ["ARM_D"]);
}

/// A robot that is gone lets go of what it held and of what it asked for: a request of its
/// that waited is never granted, and those behind it are.
#[test]
fn a_withdrawn_robot_leaves_no_reservation_held_or_waiting() {
    use imrs_coord::zones::Reservations;
    let mut space = Reservations::new(0.035, 0.03);
    assert!(space.request("ARM_A", &reach(0.0)));
    assert!(
        !space.request("ARM_B", &reach(0.05)),
        "5 cm from A's: waits"
    );
    assert!(!space.request("ARM_C", &reach(0.1)), "behind B's request");
    // B is gone while it waits: C, clear of A, is granted at once.
    assert_eq!(space.withdraw("ARM_B"), ["ARM_C"]);
    // A is gone while it holds: nothing waits.
    assert_eq!(space.withdraw("ARM_A"), Vec::<imrs_ports::Name>::new());
    assert_eq!(space.holders(), ["ARM_C"]);
    // B, back, is granted where A was.
    assert!(space.request("ARM_B", &reach(0.0)));
}

/// Two cycles at once: one whose victim was woken and is on its way to ask again (not
/// asleep), one of robots all asleep. Looking only among the robots asleep finds the
/// second, so it is not left waiting behind the first.
#[test]
fn a_cycle_among_robots_asleep_is_found_beside_one_whose_victim_is_awake() -> Result<(), ZoneError>
{
    let mut t = table();
    // ARM_A and ARM_B each hold a zone and want the other's.
    t.request_move("ARM_A", "FIXTURE")?;
    t.request_move("ARM_B", "TRAY")?;
    t.request_move("ARM_A", "TRAY")?;
    t.request_move("ARM_B", "FIXTURE")?;
    // ARM_A and ARM_C each hold a tool and want the other's.
    t.request_tool("ARM_C", "SCREWDRIVER")?;
    t.request_tool("ARM_A", "GRIPPER")?;
    t.request_tool("ARM_C", "GRIPPER")?;
    t.request_tool("ARM_A", "SCREWDRIVER")?;
    // Over every sleeper, the tools' cycle comes first; its victim is ARM_C.
    assert_eq!(t.deadlock().map(|d| d.victim), Some("ARM_C".into()));
    // ARM_C was woken: among the robots asleep, the zones' cycle is found, where looking
    // at the first cycle only would have found ARM_C's again and left this one waiting.
    let found = t
        .deadlock_among(|r| *r != "ARM_C")
        .expect("ARM_A and ARM_B wait for each other");
    assert_eq!(found.victim, "ARM_B");
    assert!(!found.cycle.contains(&"ARM_C".into()));
    Ok(())
}

/// What a sleeper waits on through a chain of sleepers: the highest kind of wait on the
/// way, in the order zone < tool < right to move.
#[test]
fn a_wait_through_the_tool_and_a_zone_is_of_the_tool() -> Result<(), ZoneError> {
    let mut table = table();
    // A waits for the screwdriver C holds; C waits for FIXTURE, where B is.
    assert_eq!(table.request_move("ARM_B", "FIXTURE")?, Answer::Grant);
    assert_eq!(table.request_tool("ARM_C", "SCREWDRIVER")?, Answer::Grant);
    assert_eq!(table.request_tool("ARM_A", "SCREWDRIVER")?, Answer::Sleep);
    assert_eq!(table.request_move("ARM_C", "FIXTURE")?, Answer::Sleep);
    let asleep = |r: &imrs_ports::Name| *r != "ARM_B";
    assert_eq!(
        table.waits_on("ARM_A", "ARM_B", asleep),
        Some(DeadlockKind::Tool)
    );
    assert_eq!(
        table.waits_on("ARM_C", "ARM_B", asleep),
        Some(DeadlockKind::Zone)
    );
    // Not through a robot that is awake.
    assert_eq!(table.waits_on("ARM_A", "ARM_B", |r| *r == "ARM_A"), None);
    Ok(())
}

#[test]
fn a_robot_that_stops_sleeping_leaves_its_queues_and_keeps_its_right_to_move()
-> Result<(), ZoneError> {
    let mut table = table();
    // B is in FIXTURE; A moves in FEEDERS and sleeps on FIXTURE, C behind it.
    assert_eq!(table.request_move("ARM_B", "FIXTURE")?, Answer::Grant);
    assert_eq!(table.request_move("ARM_A", "FEEDERS")?, Answer::Grant);
    assert_eq!(table.request_move("ARM_A", "FIXTURE")?, Answer::Sleep);
    assert_eq!(table.request_move("ARM_C", "FIXTURE")?, Answer::Sleep);
    // A waits on B: told to back off, it leaves the queue, and C heads it.
    assert_eq!(
        table.waits_on("ARM_A", "ARM_B", |_| true),
        Some(DeadlockKind::Zone)
    );
    assert_eq!(table.waits_on("ARM_B", "ARM_A", |_| true), None);
    table.stop_sleeping("ARM_A")?;
    assert_eq!(table.waits_on("ARM_A", "ARM_B", |_| true), None);
    assert_eq!(table.release("ARM_B", "FIXTURE")?, ["ARM_C"]);
    // It still moves in FEEDERS: nobody else may, until it stops there.
    assert_eq!(table.request_move("ARM_B", "FEEDERS")?, Answer::Sleep);
    assert_eq!(table.stopped_inside("ARM_A", "FEEDERS")?, ["ARM_B"]);
    Ok(())
}

/// An arm along the x axis at height `y`, 50 cm long.
fn along_x(y: f32) -> Pose {
    [[0.0, y], [0.25, y], [0.5, y]]
}

/// The parting rule (`zones::PARTING`): two robots already nearer than the margin, where they
/// told the coordinator they are, may part, and come no nearer than the rule allows.
#[test]
fn robots_already_within_the_margin_may_part_but_not_come_nearer() {
    let mut positions = Positions::new(["A", "B"], 0.035, 0.03);
    positions.tell("A", along_x(0.0)).unwrap();
    // B's links 2 cm from A's (9 cm between the axes, 3.5 cm radius each).
    positions.tell("B", along_x(0.09)).unwrap();
    // Away from A: clear, though B is within the margin now.
    assert!(
        positions
            .blockers("B", &vec![along_x(0.1)])
            .unwrap()
            .is_empty()
    );
    // As near as now: clear.
    assert!(
        positions
            .blockers("B", &vec![along_x(0.09)])
            .unwrap()
            .is_empty()
    );
    // 5 mm nearer, or down to 2 mm: blocked, at any nearness.
    assert_eq!(
        positions.blockers("B", &vec![along_x(0.085)]).unwrap(),
        ["A"]
    );
    assert_eq!(
        positions.blockers("B", &vec![along_x(0.072)]).unwrap(),
        ["A"]
    );
    // Through A: blocked.
    assert_eq!(positions.blockers("B", &vec![along_x(0.0)]).unwrap(), ["A"]);
    // At 1.5 cm (half the margin), a way 0.5 mm nearer is blocked: the tolerance stops
    // there.
    positions.tell("B", along_x(0.085)).unwrap();
    assert_eq!(
        positions.blockers("B", &vec![along_x(0.0845)]).unwrap(),
        ["A"]
    );
    // B told it is 1 mm from A: it may part, and not come nearer at all.
    positions.tell("B", along_x(0.071)).unwrap();
    assert!(
        positions
            .blockers("B", &vec![along_x(0.08)])
            .unwrap()
            .is_empty()
    );
    assert!(
        positions
            .blockers("B", &vec![along_x(0.071)])
            .unwrap()
            .is_empty()
    );
    assert_eq!(
        positions.blockers("B", &vec![along_x(0.0709)]).unwrap(),
        ["A"]
    );
}
