//! The simulated cell, measured by rapier, on the virtual clock.

use std::sync::Arc;
use std::time::Duration;

use imrs_core::time::drive;
use imrs_ports::{Clock, Instant, VirtualClock};
use imrs_sim::layout::{
    CONVEYOR_SPEED, GATE_X, LOAD_X, RELEASE_TIME, STEP, TOOL_ACCEL, TOOL_SPEED, ZONE_CENTRE,
    ZONE_HALF,
};
use imrs_sim::profile::Trapezoid;
use imrs_sim::{
    DeviceError, Fault, FaultKind, FeederId, Line, Release, RobotId, Role, Sim, SimConfig,
    SimEvent, SimEventKind, Station, Target,
};

const CHIP_A: RobotId = RobotId::new(Line::A, Role::ChipIt);
const CHIP_B: RobotId = RobotId::new(Line::B, Role::ChipIt);

fn paused_runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .start_paused(true)
        .build()
        .unwrap()
}

fn secs(seconds: f64) -> Instant {
    Instant::from_start(Duration::from_secs_f64(seconds))
}

/// A cell on a virtual clock, its stepper running, and the clock to drive it.
fn cell(stocks: Option<[u32; 4]>) -> (Sim, VirtualClock) {
    let clock = VirtualClock::new();
    let sim = Sim::new(SimConfig { seed: 3, stocks }, Arc::new(clock.clone()));
    sim.spawn();
    (sim, clock)
}

fn zone_events(events: &[SimEvent], robot: RobotId) -> Vec<(bool, Instant)> {
    events
        .iter()
        .filter_map(|event| match event.kind {
            SimEventKind::ZoneEntered { robot: r } if r == robot => Some((true, event.at)),
            SimEventKind::ZoneLeft { robot: r } if r == robot => Some((false, event.at)),
            _ => None,
        })
        .collect()
}

fn collisions(events: &[SimEvent]) -> Vec<(RobotId, RobotId)> {
    events
        .iter()
        .filter_map(|event| match event.kind {
            SimEventKind::Collision { a, b, .. } => Some((a, b)),
            _ => None,
        })
        .collect()
}

#[test]
fn a_move_takes_the_time_its_profile_says_on_the_virtual_clock() {
    paused_runtime().block_on(async {
        let (sim, clock) = cell(None);
        let robot = sim.robot(CHIP_A);
        let moving = tokio::spawn(async move {
            robot.move_to(Target::Card).await.unwrap();
            robot.now()
        });
        drive(&clock, secs(10.0)).await;
        let arrived = moving.await.unwrap();
        // From home (CHIP_X - 0.1, 0.1) to the card (CHIP_X, 0): 0.1 * sqrt(2) m. (The
        // simulation computes the distance from the two points in f32, so allow its rounding.)
        let expected = Trapezoid::new(0.1 * 2f32.sqrt(), TOOL_SPEED, TOOL_ACCEL).duration();
        let error = arrived.since_start().as_secs_f64() - expected.as_secs_f64();
        assert!(
            error.abs() < 1e-6,
            "arrived at {arrived:?}, expected {expected:?}"
        );
        assert_eq!(clock.now(), secs(10.0));
    });
}

/// The time (seconds) at which a move's tool centre, going from `from` to `to`, crosses y.
fn crossing(from: [f32; 2], to: [f32; 2], y: f32) -> f64 {
    let length = ((to[0] - from[0]).powi(2) + (to[1] - from[1]).powi(2)).sqrt();
    let profile = Trapezoid::new(length, TOOL_SPEED, TOOL_ACCEL);
    let share = (y - from[1]) / (to[1] - from[1]);
    let mut t = Duration::ZERO;
    while profile.covered(t) < share * length {
        t += Duration::from_micros(100);
    }
    t.as_secs_f64()
}

#[test]
fn entering_and_leaving_the_feeder_zone_are_measured_when_they_happen() {
    paused_runtime().block_on(async {
        let (sim, clock) = cell(None);
        let robot = sim.robot(CHIP_A);
        let trip = tokio::spawn(async move {
            robot.move_to(Target::Feeder(FeederId(1))).await.unwrap();
            let there = robot.now();
            robot.move_to(Target::Home).await.unwrap();
            (there, robot.now())
        });
        drive(&clock, secs(5.0)).await;
        let (there, back) = trip.await.unwrap();
        let zone = zone_events(&sim.log().snapshot(), CHIP_A);
        assert_eq!(zone.len(), 2, "{zone:?}");
        let ((entered, at_in), (left, at_out)) = (zone[0], zone[1]);
        assert!(entered && !left);
        // The tool's centre crosses the zone's near edge at `edge`; its capsule (and maybe
        // its elbow) gets there a little before, never after: the entry is measured at the
        // first step past that moment at the latest.
        let home = [imrs_sim::layout::CHIP_X - 0.1, 0.1];
        let feeder = [imrs_sim::layout::FEEDER_X[1], ZONE_CENTRE[1]];
        let edge = ZONE_CENTRE[1] - ZONE_HALF[1];
        let step = STEP.as_secs_f64();
        let inbound = crossing(home, feeder, edge);
        assert!(
            at_in > secs(0.0) && at_in <= secs(inbound + step),
            "entered at {at_in:?}, edge at {inbound}"
        );
        assert!(at_in < there);
        let outbound = there.since_start().as_secs_f64() + crossing(feeder, home, edge);
        assert!(
            at_out > there && at_out >= secs(outbound - 0.2) && at_out <= back,
            "left at {at_out:?}"
        );
    });
}

#[test]
fn two_robots_driven_into_the_zone_at_once_collide() {
    paused_runtime().block_on(async {
        let (sim, clock) = cell(None);
        let (a, b) = (sim.robot(CHIP_A), sim.robot(CHIP_B));
        let into_a = tokio::spawn(async move { a.move_to(Target::Feeder(FeederId(1))).await });
        let into_b = tokio::spawn(async move { b.move_to(Target::Feeder(FeederId(1))).await });
        drive(&clock, secs(3.0)).await;
        into_a.await.unwrap().unwrap();
        into_b.await.unwrap().unwrap();
        let events = sim.log().snapshot();
        assert_eq!(collisions(&events), [(CHIP_A, CHIP_B)]);
        let collision = events
            .iter()
            .find(|event| matches!(event.kind, SimEventKind::Collision { .. }))
            .unwrap();
        let SimEventKind::Collision { point, .. } = collision.kind else {
            unreachable!()
        };
        // They meet inside the zone.
        assert!(
            (point[1] - ZONE_CENTRE[1]).abs() < ZONE_HALF[1],
            "{point:?}"
        );
    });
}

#[test]
fn robots_kept_apart_never_collide() {
    paused_runtime().block_on(async {
        let (sim, clock) = cell(None);
        let (a, b) = (sim.robot(CHIP_A), sim.robot(CHIP_B));
        let work_a = tokio::spawn(async move {
            for _ in 0..3 {
                a.move_to(Target::Feeder(FeederId(0))).await?;
                a.move_to(Target::Card).await?;
            }
            Ok::<_, DeviceError>(())
        });
        let work_b = tokio::spawn(async move {
            for _ in 0..3 {
                b.move_to(Target::Card).await?;
                b.move_to(Target::Home).await?;
            }
            Ok::<_, DeviceError>(())
        });
        drive(&clock, secs(10.0)).await;
        work_a.await.unwrap().unwrap();
        work_b.await.unwrap().unwrap();
        let events = sim.log().snapshot();
        assert_eq!(collisions(&events), []);
        // A went into the zone three times; B never did.
        assert_eq!(zone_events(&events, CHIP_A).len(), 6);
        assert_eq!(zone_events(&events, CHIP_B), []);
    });
}

#[test]
fn a_released_pallet_rolls_to_the_load_station_and_is_held_there() {
    paused_runtime().block_on(async {
        let (sim, clock) = cell(None);
        let gate = sim.gate(Line::A);
        let relay = sim.relay(Line::A, Station::Load);
        let arrival = tokio::spawn(async move {
            let Release::Released(pallet) = gate.release().await else {
                panic!("an empty line is not backed up");
            };
            let held = relay.wait_in_place().await.unwrap();
            (pallet, held, relay)
        });
        drive(&clock, secs(20.0)).await;
        let (pallet, held, relay) = arrival.await.unwrap();
        assert_eq!(pallet, held);
        let in_place = sim
            .log()
            .snapshot()
            .into_iter()
            .find(|event| matches!(event.kind, SimEventKind::PalletInPlace { .. }))
            .unwrap();
        // Released after the relay's 0.3 s, then (LOAD_X - GATE_X) at the conveyor's speed,
        // measured on the step grid.
        let travel = RELEASE_TIME.as_secs_f64() + f64::from((LOAD_X - GATE_X) / CONVEYOR_SPEED);
        let at = in_place.at.since_start().as_secs_f64();
        assert!(
            (at - travel).abs() <= STEP.as_secs_f64() * 2.0,
            "in place at {at}, expected {travel}"
        );
        // It stays there, held, while the clock runs on.
        drive(&clock, secs(40.0)).await;
        let pallets = sim.pallets();
        assert_eq!(pallets.len(), 1);
        assert!((pallets[0].2[0] - LOAD_X).abs() < 1e-4, "{pallets:?}");
        assert_eq!(relay.holds(), Some(pallet));
    });
}

#[test]
fn a_robot_fault_fails_the_running_operation_at_the_fault() {
    paused_runtime().block_on(async {
        let (sim, clock) = cell(None);
        sim.inject(Fault {
            at: secs(0.1),
            kind: FaultKind::Robot(CHIP_A),
        });
        let robot = sim.robot(CHIP_A);
        let trip = tokio::spawn(async move {
            let failed = robot.move_to(Target::Feeder(FeederId(3))).await;
            let at = robot.now();
            // The fault is one-shot: after it, the robot works again.
            let again = robot.move_to(Target::Home).await;
            (failed, at, again)
        });
        drive(&clock, secs(5.0)).await;
        let (failed, at, again) = trip.await.unwrap();
        assert_eq!(failed, Err(DeviceError::RobotFault { robot: CHIP_A }));
        assert_eq!(at, secs(0.1));
        assert_eq!(again, Ok(()));
    });
}

#[test]
fn an_empty_feeder_fails_grasp_and_leaves_the_others_usable() {
    paused_runtime().block_on(async {
        let (sim, clock) = cell(Some([1, 5, 5, 5]));
        sim.inject(Fault {
            at: secs(0.0),
            kind: FaultKind::FeederEmpty(FeederId(2)),
        });
        let robot = sim.robot(CHIP_A);
        let work = tokio::spawn(async move {
            let mut outcomes = Vec::new();
            for feeder in [0, 0, 2, 3] {
                let feeder = FeederId(feeder);
                robot.move_to(Target::Feeder(feeder)).await.unwrap();
                outcomes.push(robot.grasp(feeder).await);
            }
            outcomes
        });
        drive(&clock, secs(10.0)).await;
        let outcomes = work.await.unwrap();
        assert_eq!(
            outcomes,
            [
                Ok(1),
                Err(DeviceError::EmptyFeeder {
                    feeder: FeederId(0),
                    chip: 1
                }),
                Err(DeviceError::EmptyFeeder {
                    feeder: FeederId(2),
                    chip: 7
                }),
                Ok(12),
            ]
        );
        let stocks: Vec<_> = sim
            .feeders()
            .into_iter()
            .map(|(_, _, stock)| stock)
            .collect();
        assert_eq!(stocks, [0, 5, 0, 4]);
    });
}

/// A scripted morning on both lines; returns every measured event.
fn scripted_run(seed: u64) -> Vec<SimEvent> {
    paused_runtime().block_on(async move {
        let clock = VirtualClock::new();
        let sim = Sim::new(SimConfig::seeded(seed), Arc::new(clock.clone()));
        sim.spawn();
        for line in Line::ALL {
            let gate = sim.gate(line);
            tokio::spawn(async move {
                for _ in 0..4 {
                    gate.release().await;
                    tokio::time::sleep(Duration::ZERO).await;
                }
            });
        }
        for robot in [CHIP_A, CHIP_B] {
            let robot = sim.robot(robot);
            tokio::spawn(async move {
                for feeder in [0, 1, 2, 3, 1] {
                    let _ = robot.move_to(Target::Feeder(FeederId(feeder))).await;
                    let _ = robot.grasp(FeederId(feeder)).await;
                    let _ = robot.move_to(Target::Card).await;
                }
            });
        }
        drive(&clock, secs(60.0)).await;
        sim.log().snapshot()
    })
}

#[test]
fn the_same_seed_gives_the_same_event_stream() {
    let first = scripted_run(11);
    assert!(first.len() > 20, "{} events", first.len());
    assert_eq!(first, scripted_run(11));
}

#[test]
fn a_feeder_found_empty_is_refilled_by_the_operator_later() {
    paused_runtime().block_on(async {
        let (sim, clock) = cell(Some([0, 5, 5, 5]));
        let (robot, sim_clock) = (sim.robot(CHIP_A), sim.clock().clone());
        let work = tokio::spawn(async move {
            robot.move_to(Target::Feeder(FeederId(0))).await.unwrap();
            let empty = robot.grasp(FeederId(0)).await;
            sim_clock.sleep(imrs_sim::layout::REFILL_DELAY).await;
            (empty, robot.grasp(FeederId(0)).await)
        });
        drive(&clock, secs(200.0)).await;
        let (empty, refilled) = work.await.unwrap();
        assert_eq!(
            empty,
            Err(DeviceError::EmptyFeeder {
                feeder: FeederId(0),
                chip: 1
            })
        );
        assert_eq!(refilled, Ok(1));
        let refills: Vec<_> = sim
            .log()
            .snapshot()
            .into_iter()
            .filter(|event| matches!(event.kind, SimEventKind::FeederRefilled { .. }))
            .collect();
        assert_eq!(refills.len(), 1);
    });
}

#[test]
fn an_unknown_feeder_or_a_point_that_is_no_point_is_refused() {
    paused_runtime().block_on(async {
        let (sim, clock) = cell(None);
        let robot = sim.robot(CHIP_A);
        let tries = tokio::spawn(async move {
            (
                robot.move_to(Target::Feeder(FeederId(9))).await,
                robot.grasp(FeederId(9)).await,
                robot.move_to(Target::Point([f32::NAN, 0.0])).await,
                robot.move_to(Target::Point([10.0, 10.0])).await,
            )
        });
        drive(&clock, secs(1.0)).await;
        let (moved, grasped, nan, far) = tries.await.unwrap();
        assert_eq!(
            moved,
            Err(DeviceError::UnknownFeeder {
                feeder: FeederId(9)
            })
        );
        assert_eq!(
            grasped,
            Err(DeviceError::UnknownFeeder {
                feeder: FeederId(9)
            })
        );
        assert_eq!(grasped.unwrap_err().to_string(), "there is no feeder-9");
        assert!(matches!(nan, Err(DeviceError::OutOfReach { .. })));
        assert!(matches!(
            far,
            Err(DeviceError::OutOfReach {
                target: [10000, 10000],
                ..
            })
        ));
    });
}

/// Takes a pallet of line A through the load station (a card laid and screwed) to the chip
/// station, and inserts a chip from feeder 0 at `place` on its card.
async fn chip_onto_card(sim: Sim, place: [f32; 2]) -> Result<(), DeviceError> {
    let Release::Released(_) = sim.gate(Line::A).release().await else {
        panic!("an empty line is not backed up");
    };
    let load = sim.relay(Line::A, Station::Load);
    load.wait_in_place().await?;
    let loader = sim.robot(RobotId::new(Line::A, Role::LoadCard));
    loader.move_to(Target::Magazine).await?;
    loader.pick_card().await?;
    loader.move_to(Target::Card).await?;
    loader.place_card().await?;
    loader.move_to(Target::Home).await?;
    let screwer = sim.robot(RobotId::new(Line::A, Role::ScrewInCard));
    screwer.move_to(Target::Card).await?;
    screwer.screw().await?;
    screwer.move_to(Target::Home).await?;
    load.release()?;
    sim.relay(Line::A, Station::Chip).wait_in_place().await?;
    let chipper = sim.robot(CHIP_A);
    chipper.move_to(Target::Feeder(FeederId(0))).await?;
    chipper.grasp(FeederId(0)).await?;
    chipper.move_to(Target::OnCard(place)).await?;
    chipper.insert().await.map(|_| ())
}

#[test]
fn a_chip_goes_where_the_tool_is_over_the_card_and_a_place_off_the_card_is_refused() {
    paused_runtime().block_on(async {
        let (sim, clock) = cell(None);
        let robot = sim.robot(CHIP_A);
        let refused = robot.move_to(Target::OnCard([0.09, 0.02])).await;
        assert_eq!(
            refused,
            Err(DeviceError::OffCard {
                robot: robot.id(),
                at: [90, 20]
            })
        );
        assert!(
            refused
                .unwrap_err()
                .to_string()
                .contains("(90 mm, 20 mm) on the card, which lies off the card")
        );
        let placed = Arc::new(std::sync::Mutex::new(None));
        let seen = Arc::clone(&placed);
        sim.log().subscribe(move |event| {
            if let SimEventKind::ChipInserted { on_card, .. } = event.kind {
                *seen.lock().unwrap() = Some(on_card);
            }
        });
        let driving = tokio::spawn(chip_onto_card(sim.clone(), [0.015, 0.07]));
        drive(&clock, secs(120.0)).await;
        driving.await.unwrap().unwrap();
        let on_card = placed.lock().unwrap().expect("a chip was inserted");
        assert!(
            (on_card[0] - 0.015).abs() < 1e-4 && (on_card[1] - 0.07).abs() < 1e-4,
            "{on_card:?}"
        );
    });
}

#[test]
fn watchers_see_the_scene_at_most_once_a_period_while_it_moves_and_when_it_stops() {
    paused_runtime().block_on(async {
        let clock = VirtualClock::new();
        let sim = Sim::new(SimConfig::seeded(3), Arc::new(clock.clone()));
        let seen = Arc::new(std::sync::Mutex::new(Vec::new()));
        let into = Arc::clone(&seen);
        sim.watch(Duration::from_millis(100), move |scene| {
            into.lock().unwrap().push(scene.clone());
        });
        sim.spawn();
        let robot = sim.robot(CHIP_A);
        let moving = tokio::spawn(async move { robot.move_to(Target::Feeder(FeederId(0))).await });
        drive(&clock, secs(10.0)).await;
        moving.await.unwrap().unwrap();
        let seen = seen.lock().unwrap();
        // Once at the start, then at most every 100 ms while the arm moved.
        assert!(seen.len() >= 3, "{}", seen.len());
        for pair in seen.windows(2).take(seen.len() - 2) {
            let gap = pair[1].at.saturating_duration_since(pair[0].at);
            assert!(gap >= Duration::from_millis(100), "{gap:?}");
        }
        // The last scene is the arm at rest over the feeder, as rapier has it: the tool end
        // of its second link lies over the feeder.
        let last = seen.last().unwrap();
        let arm = last.arms.iter().find(|arm| arm.robot == CHIP_A).unwrap();
        let link = arm.links[1];
        let tool = [
            link.centre[0] + link.length / 2.0 * link.yaw.cos(),
            link.centre[1] + link.length / 2.0 * link.yaw.sin(),
        ];
        let feeder = last.feeders[0].at;
        assert!(
            (tool[0] - feeder[0]).abs() < 1e-3 && (tool[1] - feeder[1]).abs() < 1e-3,
            "{tool:?} {feeder:?}"
        );
        assert!(arm.in_zone);
    });
}
