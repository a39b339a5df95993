//! The deadlock of the Appendix's note 6: CHIP_IT and CHIP_IT2 query each other from their
//! background code. It is reported by module and port names, and broken by asymmetric
//! timeouts.

mod common;

use common::{at, paused_runtime, secs};

use std::sync::{Arc, Mutex};

use imrs_core::prelude::*;
use imrs_core::time::drive;

type Log = Arc<Mutex<Vec<(String, u64)>>>;

/// A chip robot: asks its twin for the feeders on `asks` (timeout `patience`), answers the
/// twin's CRIT_SECTION on `answers`. After a timeout it runs a section ranked below
/// CRIT_SECTION for a moment, so that the twin's pending query gets through (the seed's
/// remedy), then asks again.
fn chip_robot(
    name: &str,
    asks: Port<(), i32, usage::Query>,
    answers: &Port<(), i32, usage::Query>,
    log: Log,
) -> ModuleSpec<()> {
    let asks_name = asks.name().to_string();
    let answers_name = answers.name().to_string();
    let crit_section = format!("{answers_name}.CRIT_SECTION");
    let robot = name.to_string();
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
            let (asks, log, robot) = (asks.clone(), Arc::clone(&log), robot.clone());
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
                log.lock()
                    .unwrap()
                    .push((robot.clone(), ctx.now().since_start().as_secs()));
                ctx.section(&Section::new("GRASP"), ctx.delay(secs(2)))
                    .await;
                ctx.section(&Section::new("INSERT"), ctx.delay(secs(5)))
                    .await;
                Ok(())
            }
        })
}

#[test]
fn the_chip_robots_deadlock_is_reported_and_broken_by_asymmetric_timeouts() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        // SHARE_FEEDER (CHIP_IT's, TIMEOUT=3 SEC) and SHARE_FEEDER1 (CHIP_IT2's, 5 s): the
        // asymmetry decides who gives way.
        let share_feeder: Port<(), i32, usage::Query> = cell.port(
            PortSpec::new("SHARE_FEEDER", "CHIP_IT")
                .user_list(["CHIP_IT2"])
                .owner_timeout(secs(3)),
        ).unwrap();
        let share_feeder1: Port<(), i32, usage::Query> = cell.port(
            PortSpec::new("SHARE_FEEDER1", "CHIP_IT2")
                .user_list(["CHIP_IT"])
                .owner_timeout(secs(5)),
        ).unwrap();
        let log: Log = Arc::default();
        let chip_it = chip_robot("CHIP_IT", share_feeder.clone(), &share_feeder1, Arc::clone(&log));
        let chip_it2 = chip_robot("CHIP_IT2", share_feeder1, &share_feeder, Arc::clone(&log));
        let mut handles = [cell.start(chip_it).unwrap(), cell.start(chip_it2).unwrap()];
        drive(&clock, at(40)).await;
        for handle in &mut handles {
            assert_eq!(handle.finished().await, ModuleOutcome::Finished);
        }

        let events = cell.events().snapshot();
        let deadlocks: Vec<_> = events
            .iter()
            .filter_map(|event| match &event.kind {
                EventKind::Deadlock { cycle } => Some((event.at, cycle.clone())),
                _ => None,
            })
            .collect();
        // Both query at once, from their background code: the cycle closes at 0 s.
        assert_eq!(
            deadlocks.first(),
            Some(&(
                at(0),
                vec![
                    (Name::from("CHIP_IT2"), Name::from("SHARE_FEEDER1")),
                    (Name::from("CHIP_IT"), Name::from("SHARE_FEEDER")),
                ]
            ))
        );
        let line = events
            .iter()
            .find(|event| matches!(event.kind, EventKind::Deadlock { .. }))
            .unwrap()
            .to_string();
        assert_eq!(
            line,
            "[0.000s] CHIP_IT2/CHIP_IT2: deadlock: CHIP_IT2 -[SHARE_FEEDER1]-> CHIP_IT -[SHARE_FEEDER]-> CHIP_IT2"
        );
        // CHIP_IT times out first (3 s) and backs off below CRIT_SECTION, so CHIP_IT2's
        // query is answered at 3 s; CHIP_IT gets its turn once CHIP_IT2 is in INSERT (5 s).
        let turns = log.lock().unwrap().clone();
        assert_eq!(turns, [("CHIP_IT2".to_string(), 3), ("CHIP_IT".to_string(), 5)]);
    });
}

/// A clock that runs on virtual time but does not say so, as a clock of a user's own would:
/// the cell then finds cycles with its watchdog, as on the real clock, not at each move.
#[derive(Debug)]
struct OwnClock(imrs_ports::VirtualClock);

impl Clock for OwnClock {
    fn now(&self) -> Instant {
        self.0.now()
    }

    fn sleep_until(&self, deadline: Instant) -> imrs_ports::clock::Sleep {
        self.0.sleep_until(deadline)
    }
}

/// CHIP_IT and CHIP_IT2 of `chip_robot` on ports without timeouts: once both ask, nothing
/// breaks the cycle. With the log of their turns (which stays empty).
fn unguarded_robots(cell: &Cell) -> (ModuleSpec<()>, ModuleSpec<()>, Log) {
    let port = |name: &str, owner: &str, user: &str| -> Port<(), i32, usage::Query> {
        cell.port(PortSpec::new(name, owner).user_list([user]))
            .unwrap()
    };
    let share_feeder = port("SHARE_FEEDER", "CHIP_IT", "CHIP_IT2");
    let share_feeder1 = port("SHARE_FEEDER1", "CHIP_IT2", "CHIP_IT");
    let log: Log = Arc::default();
    let chip_it = chip_robot(
        "CHIP_IT",
        share_feeder.clone(),
        &share_feeder1,
        Arc::clone(&log),
    );
    let chip_it2 = chip_robot("CHIP_IT2", share_feeder1, &share_feeder, Arc::clone(&log));
    (chip_it, chip_it2, log)
}

fn deadlocks(cell: &Cell) -> Vec<Event> {
    let events = cell.events().snapshot();
    let deadlock = |event: &Event| matches!(event.kind, EventKind::Deadlock { .. });
    events.into_iter().filter(deadlock).collect()
}

#[test]
fn on_a_clock_of_its_own_the_watchdog_names_the_cycle_within_its_bound() {
    paused_runtime().block_on(async {
        let virtual_time = imrs_ports::VirtualClock::new();
        let cell = Cell::new(Arc::new(OwnClock(virtual_time.clone())));
        let (chip_it, chip_it2, log) = unguarded_robots(&cell);
        let chip_it = cell.start(chip_it).unwrap();
        drive(&virtual_time, at(2)).await;
        // The cycle closes at 2 s.
        let chip_it2 = cell.start(chip_it2).unwrap();
        drive(&virtual_time, at(10)).await;

        let found = deadlocks(&cell);
        assert_eq!(found.len(), 1, "a standing cycle is named once: {found:?}");
        let closed = at(2);
        assert!(
            found[0].at > closed && found[0].at <= closed + Cell::DEADLOCK_BOUND,
            "named at {:?}, the cycle closed at 2 s",
            found[0].at
        );
        assert_eq!(
            found[0].to_string().split_once("] ").map(|(_, rest)| rest),
            Some(
                "CHIP_IT2/CHIP_IT2: deadlock: CHIP_IT2 -[SHARE_FEEDER1]-> CHIP_IT -[SHARE_FEEDER]-> CHIP_IT2"
            )
        );
        assert!(log.lock().unwrap().is_empty(), "neither got its answer");
        chip_it.stop();
        chip_it2.stop();
    });
}

#[test]
fn a_cycle_that_closes_later_is_named_at_the_instant_it_closed() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let (chip_it, chip_it2, _) = unguarded_robots(&cell);
        let chip_it = cell.start(chip_it).unwrap();
        // CHIP_IT waits alone for 7 s: a wait that lasts is no cycle.
        drive(&clock, at(7)).await;
        assert_eq!(deadlocks(&cell), [], "one module waiting is no deadlock");
        let chip_it2 = cell.start(chip_it2).unwrap();
        drive(&clock, at(20)).await;
        let found: Vec<_> = deadlocks(&cell)
            .into_iter()
            .map(|event| (event.at, event.module))
            .collect();
        assert_eq!(found, [(at(7), Name::from("CHIP_IT2"))]);
        chip_it.stop();
        chip_it2.stop();
    });
}
