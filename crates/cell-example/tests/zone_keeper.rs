//! FEEDER_COORDINATOR when a line's process dies: told on LINE_DOWN, it lets go of what the
//! dead run's chip robot held or asked for, so that the other line is granted at once, and
//! it heeds no word of the dead run after. It weighs only the cell's chip robots, on their
//! own lines. Driven through its ports, as the chip robots and the world's supervision
//! are; on tokio's paused clock, so that "still waiting" means every task has gone idle.

use std::pin::pin;
use std::time::Duration;

use cell_example::FeederPolicy;
use cell_example::chip::feeder_coordinator;
use cell_example::devices::Pose;
use cell_example::ports::CellPorts;
use cell_example::reservation::Reservation;
use cell_example::zone_asker::ZoneAsker;
use imrs_core::prelude::*;
use imrs_ports::Name;
use imrs_sim::Line;

/// An arm from (0, 0) reaching straight out to x = 0.7 at height `y`.
fn reach(y: f32) -> Vec<Pose> {
    (0..=5)
        .map(|i| {
            let x = 0.7 * i as f32 / 5.0;
            [[0.0, y], [x / 2.0, y], [x, y]]
        })
        .collect()
}

fn reservation(robot: &str, line: Line, run: u32, y: f32) -> Reservation {
    Reservation::new(ZoneAsker::new(robot, line, run), &reach(y)).unwrap()
}

/// Long enough for any answer the coordinator will give: the clock is paused, so it
/// passes only once every task waits.
const IDLE: Duration = Duration::from_secs(60);

#[tokio::test(flavor = "current_thread", start_paused = true)]
async fn a_dead_lines_reservation_is_let_go_and_its_dead_runs_words_are_not_heeded() {
    let (cell, _clock) = Cell::virtual_clock();
    let ports = CellPorts::declare(&cell, FeederPolicy::Coordinator).unwrap();
    cell.start(feeder_coordinator(&ports)).unwrap();
    let reserve = ports.zone_reserve.here().unwrap();
    let free = ports.zone_free.here().unwrap();
    let (mut reserve_a, mut reserve_b) = (
        reserve.user_named("CHIP_IT").unwrap(),
        reserve.user_named("CHIP_IT2").unwrap(),
    );
    let (mut free_a, mut free_b) = (
        free.user_named("CHIP_IT").unwrap(),
        free.user_named("CHIP_IT2").unwrap(),
    );
    let mut line_down = ports
        .coordinator_down
        .user_named("LINE_SUPERVISOR")
        .unwrap();

    // Line A's chip robot holds the space; B's, 5 cm from it, waits.
    reserve_a
        .send(reservation("CHIP_IT", Line::A, 0, 0.0))
        .await
        .unwrap();
    let mut b_granted = pin!(reserve_b.send(reservation("CHIP_IT2", Line::B, 0, 0.05)));
    assert!(
        tokio::time::timeout(IDLE, &mut b_granted).await.is_err(),
        "B was granted space A holds"
    );

    // Line A's process dies: the world says so, and B is granted at once.
    line_down.send((Line::A, 1)).await.unwrap();
    tokio::time::timeout(IDLE, &mut b_granted)
        .await
        .expect("B still waits for a dead line's space")
        .unwrap();

    // A word of A's dead run is not heeded: a reservation is not answered (its sender
    // fails), a free changes nothing.
    assert!(
        reserve_a
            .send(reservation("CHIP_IT", Line::A, 0, 0.5))
            .await
            .is_err()
    );
    // A's next run asks where B holds: it waits, and a free of the dead run does not let
    // B's space go to it.
    let mut a_granted = pin!(reserve_a.send(reservation("CHIP_IT", Line::A, 1, 0.05)));
    assert!(tokio::time::timeout(IDLE, &mut a_granted).await.is_err());
    free_a
        .send(ZoneAsker::new("CHIP_IT2", Line::B, 7))
        .await
        .unwrap();
    assert!(
        tokio::time::timeout(IDLE, &mut a_granted).await.is_err(),
        "a dead run's free let B's space go"
    );
    // B frees it: A's next run is granted.
    free_b
        .send(ZoneAsker::new("CHIP_IT2", Line::B, 0))
        .await
        .unwrap();
    tokio::time::timeout(IDLE, &mut a_granted)
        .await
        .expect("A's next run was not granted the space B freed")
        .unwrap();
}

#[tokio::test(flavor = "current_thread", start_paused = true)]
async fn a_reservation_that_names_no_chip_robot_is_not_answered_nor_its_name_kept() {
    let (cell, _clock) = Cell::virtual_clock();
    let ports = CellPorts::declare(&cell, FeederPolicy::Coordinator).unwrap();
    cell.start(feeder_coordinator(&ports)).unwrap();
    let mut asker = ports
        .zone_reserve
        .here()
        .unwrap()
        .user_named("CHIP_IT")
        .unwrap();
    let made_up = format!("ROBOT_{}", std::process::id());
    for (robot, line) in [(made_up.as_str(), Line::A), ("CHIP_IT2", Line::A)] {
        let refused = tokio::time::timeout(IDLE, asker.send(reservation(robot, line, 0, 0.0)))
            .await
            .expect("a refused reservation is answered at once, by its sender's failure");
        assert!(refused.is_err(), "{robot} of line {line:?} was granted");
    }
    assert_eq!(Name::known(&made_up), None, "{made_up} was kept");
    // The robot the record names on its own line is granted.
    asker
        .send(reservation("CHIP_IT", Line::A, 0, 0.0))
        .await
        .unwrap();
}
