//! The simulated table measures what coordination must guarantee, from rapier: these tests
//! make each thing happen on purpose and check that it is seen — arms that collide, two
//! grippers in an exclusive zone, two moving in a shared one, a grasp of a tool another arm
//! holds — and that what is refused is refused by name.

use std::sync::Arc;
use std::time::Duration;

use imrs_ports::{Instant, VirtualClock};
use imrs_sim::scara::{Elbow, Scara};
use imrs_sim::table::{ArmSpec, Table, TableArm, TableError, TableLayout, ZoneSpec, ZoneUse};
use nalgebra::{Point2, Point3};

fn arm(name: &str, base: [f32; 2], home: [f32; 2]) -> ArmSpec {
    ArmSpec {
        name: name.into(),
        arm: Scara {
            base: base.into(),
            upper: 0.4,
            fore: 0.35,
            side: Elbow::Right,
        },
        home: home.into(),
        speed: 0.5,
        acceleration: 2.5,
    }
}

/// Two arms facing each other across a table, a zone between them of the given use.
fn layout(usage: ZoneUse) -> TableLayout {
    TableLayout {
        arms: vec![
            arm("LEFT", [-0.6, 0.0], [-0.3, 0.0]),
            arm("RIGHT", [0.6, 0.0], [0.3, 0.0]),
        ],
        zones: vec![ZoneSpec {
            name: "MIDDLE".into(),
            usage,
            centre: Point3::new(0.0, 0.0, 0.3),
            half: [0.15, 0.15, 0.3],
        }],
        tool: Point2::new(-0.3, 0.2),
    }
}

fn runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .start_paused(true)
        .build()
        .unwrap()
}

/// The table of `layout(usage)` on a new virtual clock, stepping; its two arms.
fn start(usage: ZoneUse) -> (VirtualClock, Table, TableArm, TableArm) {
    let clock = VirtualClock::new();
    let table = Table::new(layout(usage), Arc::new(clock.clone())).unwrap();
    table.spawn();
    let (left, right) = (table.arm("LEFT").unwrap(), table.arm("RIGHT").unwrap());
    (clock, table, left, right)
}

async fn until(clock: &VirtualClock, seconds: u64) {
    imrs_core::time::drive(clock, Instant::from_start(Duration::from_secs(seconds))).await;
}

#[test]
fn arms_driven_into_each_other_are_a_collision_rapier_sees() {
    runtime().block_on(async {
        let (clock, table, left, right) = start(ZoneUse::Shared);
        let a = tokio::spawn(async move { left.move_to(Point2::new(0.02, 0.0)).await });
        let b = tokio::spawn(async move { right.move_to(Point2::new(-0.02, 0.0)).await });
        until(&clock, 3).await;
        a.await.unwrap().unwrap();
        b.await.unwrap().unwrap();
        let measured = table.measured();
        assert_eq!(measured.collisions.len(), 1, "{measured:?}");
        let (a, b, _) = &measured.collisions[0];
        assert_eq!((a.as_str(), b.as_str()), ("LEFT", "RIGHT"));
        assert_eq!(measured.closest, Some(0.0));
        // Both moved in the shared zone at once: a conflict, seen too.
        assert_eq!(measured.zone_conflicts.len(), 1, "{measured:?}");
    });
}

#[test]
fn apart_arms_are_no_collision_and_the_closest_approach_is_measured() {
    runtime().block_on(async {
        let (clock, table, left, _) = start(ZoneUse::Shared);
        let moving = tokio::spawn(async move { left.move_to(Point2::new(-0.1, 0.0)).await });
        until(&clock, 3).await;
        moving.await.unwrap().unwrap();
        let measured = table.measured();
        assert!(measured.collisions.is_empty(), "{measured:?}");
        let closest = measured.closest.unwrap();
        assert!(closest > 0.05 && closest < 0.5, "{closest}");
        assert!(measured.zone_conflicts.is_empty(), "{measured:?}");
        assert!(measured.zone_time[0].1 > Duration::ZERO);
    });
}

#[test]
fn two_grippers_in_an_exclusive_zone_are_a_conflict_even_when_still() {
    runtime().block_on(async {
        let (clock, table, left, right) = start(ZoneUse::Exclusive);
        let driving = tokio::spawn(async move {
            left.move_to(Point2::new(-0.12, 0.0)).await?;
            right.move_to(Point2::new(0.12, 0.0)).await
        });
        until(&clock, 5).await;
        driving.await.unwrap().unwrap();
        let measured = table.measured();
        assert!(measured.collisions.is_empty(), "{measured:?}");
        assert_eq!(measured.zone_conflicts.len(), 1, "{measured:?}");
        let (zone, _, arms) = &measured.zone_conflicts[0];
        assert_eq!(zone.as_str(), "MIDDLE");
        assert_eq!(arms.len(), 2);
    });
}

#[test]
fn in_a_shared_zone_two_inside_one_moving_is_no_conflict() {
    runtime().block_on(async {
        let (clock, table, left, right) = start(ZoneUse::Shared);
        let driving = tokio::spawn(async move {
            left.move_to(Point2::new(-0.12, 0.0)).await?;
            right.move_to(Point2::new(0.12, 0.0)).await?;
            // The left arm moves again, inside, while the right one stays still.
            left.move_to(Point2::new(-0.12, 0.1)).await
        });
        until(&clock, 5).await;
        driving.await.unwrap().unwrap();
        let measured = table.measured();
        assert!(measured.zone_conflicts.is_empty(), "{measured:?}");
    });
}

#[test]
fn a_tool_another_arm_holds_cannot_be_grasped_and_the_attempt_is_counted() {
    runtime().block_on(async {
        let (clock, table, left, right) = start(ZoneUse::Shared);
        let driving = tokio::spawn(async move {
            // Too far from the tool: refused.
            let far = left.grasp_tool();
            left.move_to(Point2::new(-0.3, 0.2)).await?;
            left.grasp_tool()?;
            left.move_to(Point2::new(-0.1, 0.1)).await?;
            // The tool went with the gripper.
            let carried = left.tool_position();
            right.move_to(Point2::new(0.3, 0.2)).await?;
            let taken = right.grasp_tool();
            Ok::<_, TableError>((far, carried, taken))
        });
        until(&clock, 5).await;
        let (far, carried, taken) = driving.await.unwrap().unwrap();
        assert!(matches!(far, Err(TableError::ToolNotThere { ref arm, .. }) if arm == "LEFT"));
        assert!(
            (carried - Point2::new(-0.1, 0.1)).norm() < 0.03,
            "{carried}"
        );
        let error = taken.unwrap_err();
        assert!(error.to_string().contains("RIGHT"), "{error}");
        assert_eq!(table.measured().tool_conflicts.len(), 2);
    });
}

#[test]
fn what_cannot_be_is_refused_by_name() {
    let clock: imrs_ports::SharedClock = Arc::new(VirtualClock::new());
    let mut twins = layout(ZoneUse::Shared);
    twins.arms[1].name = "LEFT".into();
    let error = Table::new(twins, Arc::clone(&clock)).err().unwrap();
    assert!(
        error.to_string().contains("two arms are named LEFT"),
        "{error}"
    );

    let mut far = layout(ZoneUse::Shared);
    far.arms[0].home = Point2::new(0.5, 0.0);
    let error = Table::new(far, Arc::clone(&clock)).err().unwrap();
    assert!(error.to_string().contains("LEFT's home"), "{error}");

    let mut stuck = layout(ZoneUse::Shared);
    stuck.arms[1].speed = f32::NAN;
    let error = Table::new(stuck, Arc::clone(&clock)).err().unwrap();
    assert!(error.to_string().contains("RIGHT's speed"), "{error}");

    let mut limp = layout(ZoneUse::Shared);
    limp.arms[0].acceleration = 0.0;
    let error = Table::new(limp, Arc::clone(&clock)).err().unwrap();
    assert!(error.to_string().contains("LEFT's acceleration"), "{error}");

    let table = Table::new(layout(ZoneUse::Shared), clock).unwrap();
    assert!(matches!(table.arm("NOBODY"), Err(TableError::UnknownArm(name)) if name == "NOBODY"));
    runtime().block_on(async {
        let left = table.arm("LEFT").unwrap();
        // A point allowed before any leg was started would never move the arm.
        let error = left.allow(Point2::new(-0.3, 0.1)).unwrap_err();
        assert!(
            matches!(&error, TableError::NoLeg { arm } if arm == "LEFT"),
            "{error}"
        );
        let error = left.move_to(Point2::new(0.5, 0.0)).await.unwrap_err();
        assert!(error.to_string().contains("LEFT cannot reach"), "{error}");
        assert!(matches!(
            left.put_tool(),
            Err(TableError::NotHolding { .. })
        ));
    });
}

/// Rapier's view of one arm driven towards the middle zone (its border at x = −0.15 m, the
/// gripper touching it from x = −0.17 m) and allowed only as far as `allowed`: how long its
/// gripper was in the zone, and where it stopped.
fn drive_towards_the_zone(allowed: f32) -> (Duration, Point2<f32>) {
    runtime().block_on(async {
        let (clock, table, left, _) = start(ZoneUse::Exclusive);
        let arm = left.clone();
        let driving = tokio::spawn(async move {
            arm.start_leg(Point2::new(0.0, 0.0))?;
            arm.allow(Point2::new(allowed, 0.0))?;
            while !arm.step().await.at_rest() {}
            Ok::<_, TableError>(())
        });
        until(&clock, 3).await;
        driving.await.unwrap().unwrap();
        (table.measured().zone_time[0].1, left.at())
    })
}

#[test]
fn an_arm_cannot_stop_at_once_beyond_the_last_point_allowed_it_goes_on_by_its_stopping_distance() {
    // At 0.5 m/s braking at 2.5 m/s² it needs 5 cm to stop.
    let (inside, stopped) = drive_towards_the_zone(-0.19);
    assert!(
        inside > Duration::ZERO,
        "allowed 2 cm short of the zone, it stopped at {stopped} and rapier saw it out"
    );
    assert!((stopped.x - -0.14).abs() < 0.01, "{stopped}");
    // Allowed its stopping distance short of the zone, it stays out.
    let (inside, stopped) = drive_towards_the_zone(-0.25);
    assert_eq!(inside, Duration::ZERO, "stopped at {stopped}");
}

#[test]
fn a_halted_arm_brakes_and_a_leg_starts_only_from_rest() {
    runtime().block_on(async {
        let (clock, _table, left, _) = start(ZoneUse::Shared);
        let arm = left.clone();
        let driving = tokio::spawn(async move {
            arm.start_leg(Point2::new(-0.1, 0.0))?;
            arm.allow(Point2::new(-0.1, 0.0))?;
            let mut progress = arm.step().await;
            while progress.speed < 0.4 {
                progress = arm.step().await;
            }
            let moving = arm.start_leg(Point2::new(-0.3, 0.1));
            arm.halt();
            let at = progress.along;
            while !progress.at_rest() {
                progress = arm.step().await;
            }
            let braked = progress.along - at;
            // Allowed again, it goes on to the end.
            arm.allow(Point2::new(-0.1, 0.0))?;
            while !arm.step().await.arrived() {}
            Ok::<_, TableError>((moving, braked, arm.at()))
        });
        until(&clock, 3).await;
        let (moving, braked, end) = driving.await.unwrap().unwrap();
        let error = moving.unwrap_err();
        assert!(
            matches!(&error, TableError::Moving { arm, .. } if arm == "LEFT"),
            "{error}"
        );
        assert!(error.to_string().contains("LEFT still moves"), "{error}");
        assert!(braked > 0.02 && braked < 0.06, "{braked}");
        assert!((end - Point2::new(-0.1, 0.0)).norm() < 1e-4, "{end}");
    });
}
