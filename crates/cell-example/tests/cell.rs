//! The chip cell end to end: its report, its invariants under faults, and the deadlock the
//! Appendix predicts.

use std::time::Duration;

use cell_example::{
    CellConfig, CellFault, CellFaultKind, FeederPolicy, Report, keeping_up_line, run,
};
use imrs_core::EventKind;
use imrs_sim::{FeederId, Line, SimEventKind};

fn config(hours: f64, seed: u64, feeder: FeederPolicy) -> CellConfig {
    CellConfig {
        hours,
        seed,
        feeder,
        ..CellConfig::default()
    }
}

/// The report of a short run with a fixed seed, compared with the one saved beside this
/// test. `UPDATE_EXPECT=1 cargo test -p cell-example` rewrites it after a deliberate change.
#[test]
fn the_report_of_a_fixed_seed_run_is_as_saved() {
    let report = Report::of(&run(&config(0.1, 1985, FeederPolicy::Arbiter)).unwrap()).to_string();
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/expected/report_seed1985_0.1h.txt"
    );
    if std::env::var_os("UPDATE_EXPECT").is_some() {
        std::fs::write(path, &report).unwrap();
    }
    let expected = std::fs::read_to_string(path).unwrap();
    assert_eq!(report, expected);
}

#[test]
fn the_same_seed_and_flags_give_the_same_report() {
    let faults = vec!["robot:A@90".parse().unwrap(), "jam:B@120".parse().unwrap()];
    let config = CellConfig {
        faults,
        ..config(0.05, 7, FeederPolicy::Appendix)
    };
    let first = Report::of(&run(&config).unwrap());
    let second = Report::of(&run(&config).unwrap());
    assert_eq!(first.to_string(), second.to_string());
}

#[test]
fn the_invariants_hold_under_every_fault_over_several_seeds() {
    let kinds = [
        CellFaultKind::ReleaseDies(Line::A),
        CellFaultKind::RobotFault(Line::B),
        CellFaultKind::FeederEmpty(FeederId(2)),
        CellFaultKind::PalletJam(Line::A),
    ];
    for seed in [1, 2, 3] {
        for kind in kinds {
            let fault = CellFault {
                kind,
                at: Duration::from_secs(60 + 20 * seed),
            };
            let config = CellConfig {
                faults: vec![fault],
                ..config(0.1, seed, FeederPolicy::Arbiter)
            };
            let record = run(&config).unwrap();
            let report = Report::of(&record);
            assert!(report.all_held(), "seed {seed}, {fault}:\n{report}");
            assert!(
                report.lines.iter().all(|line| line.completed > 0),
                "seed {seed}, {fault}: the cell went on working\n{report}"
            );
            // Each fault is seen, and met as the Appendix would have it.
            let cell = &record.cell_events;
            match kind {
                CellFaultKind::ReleaseDies(_) => {
                    assert!(
                        report.timeouts.get("LET_1_GO").is_some_and(|&n| n >= 1),
                        "{report}"
                    );
                    assert!(cell.iter().any(|e| matches!(
                        &e.kind,
                        EventKind::TaskRestarted { .. }
                    )
                        && e.task.as_ref().is_some_and(|t| t == "RELEASE")));
                }
                CellFaultKind::RobotFault(_) => {
                    assert!(cell.iter().any(|e| matches!(&e.kind, EventKind::Alarm { message } if message.contains("faulted"))));
                }
                CellFaultKind::FeederEmpty(_) => {
                    assert!(cell.iter().any(|e| matches!(&e.kind, EventKind::StepFailed { error, .. } if error.contains("empty"))));
                }
                CellFaultKind::PalletJam(_) => {
                    assert_eq!(report.lines[0].scrapped, 1, "{report}");
                    assert!(
                        record
                            .sim_events
                            .iter()
                            .any(|e| matches!(e.kind, SimEventKind::PalletScrapped { .. }))
                    );
                }
            }
        }
    }
}

#[test]
fn the_appendix_policy_deadlocks_as_the_paper_predicts_and_the_timeouts_break_it() {
    let record = run(&config(0.1, 1985, FeederPolicy::Appendix)).unwrap();
    let report = Report::of(&record);
    // Both chip robots query each other the first time through: the cycle of note 6.
    let first = record
        .cell_events
        .iter()
        .find_map(|event| match &event.kind {
            EventKind::Deadlock { cycle } => Some(cycle.clone()),
            _ => None,
        })
        .expect("the deadlock appears");
    let mut ports: Vec<_> = first.iter().map(|(_, port)| port.to_string()).collect();
    ports.sort();
    assert_eq!(ports, ["SHARE_FEEDER", "SHARE_FEEDER1"]);
    // The asymmetric timeout handlers break it: both lines go on inserting chips.
    assert!(
        report.timeouts.get("SHARE_FEEDER").is_some_and(|&n| n >= 1),
        "{report}"
    );
    assert!(report.deadlocks_broken, "{report}");
    assert!(
        report.lines.iter().all(|line| line.completed > 0),
        "{report}"
    );
    assert!(report.all_held(), "{report}");
}

#[test]
fn hours_out_of_range_are_refused_not_panicked_on() {
    for hours in [0.0, -1.0, f64::NAN, 1e300] {
        let refused = run(&config(hours, 1, FeederPolicy::Arbiter)).unwrap_err();
        assert!(
            matches!(refused, cell_example::RunError::Hours(_)),
            "{refused}"
        );
        assert!(
            refused
                .to_string()
                .contains("expected a number of hours above 0"),
            "{refused}"
        );
    }
}

#[test]
fn the_report_is_folded_from_every_event_whatever_the_logs_keep() {
    let everything = config(0.3, 3, FeederPolicy::Arbiter);
    let little = CellConfig {
        kept_events: 100,
        ..everything.clone()
    };
    let full = run(&everything).unwrap();
    let kept_little = run(&little).unwrap();
    assert!(kept_little.cell_events.len() <= 100 && kept_little.sim_events.len() <= 100);
    assert!(full.cell_events.len() > 100, "the full run kept more");
    let report = |record| Report {
        wall: 0.0,
        ..Report::of(record)
    };
    assert_eq!(report(&kept_little), report(&full));
    // One process, on virtual time: no wall clock to keep up with, and no line about it.
    assert_eq!(keeping_up_line(&Report::of(&full)), None);
    // What the fold keeps per pallet is dropped when the pallet leaves the line.
    assert!(full.tally.in_flight() <= 2 * full.pallets_left.len());
}

#[test]
fn an_empty_feeder_leaves_short_cards_reported_apart_from_the_good_ones() {
    let config = CellConfig {
        faults: vec!["feeder:1@60".parse().unwrap()],
        ..config(0.1, 1985, FeederPolicy::Arbiter)
    };
    let record = run(&config).unwrap();
    let report = Report::of(&record);
    for line in &report.lines {
        assert!(line.short > 0, "a chip was skipped on every line\n{report}");
        assert_eq!(line.good + line.short, line.completed, "{report}");
        // Good cards carry all four chips; the short ones fewer.
        assert!(line.chips < 4 * line.completed, "{report}");
        assert!(line.chips >= 4 * line.good, "{report}");
    }
    let feeder = &report.feeders[1];
    assert_eq!((feeder.empties, feeder.refills), (1, 1), "{report}");
    assert!(
        report
            .alarm_kinds
            .iter()
            .any(|(kind, n)| kind == "empty feeder" && *n > 0),
        "{report}"
    );
    let text = report.to_string();
    assert!(text.contains("cards short (a chip missing)"), "{text}");
    assert!(text.contains("feeder-1 (chip  4)"), "{text}");
}

#[test]
fn every_chip_lies_at_its_work_schedule_place_as_rapier_measured_it() {
    let record = run(&config(0.1, 3, FeederPolicy::Arbiter)).unwrap();
    let mut places = Vec::new();
    for event in &record.sim_events {
        if let SimEventKind::ChipInserted { chip, on_card, .. } = event.kind {
            let place = cell_example::chip::place_of_chip(chip).expect("a chip of the schedule");
            let off = ((on_card[0] - place[0]).powi(2) + (on_card[1] - place[1]).powi(2)).sqrt();
            assert!(off <= 0.001, "chip {chip} at {on_card:?}, not {place:?}");
            if !places.contains(&place) {
                places.push(place);
            }
        }
    }
    // The four steps put their chips in four places, not one.
    assert_eq!(places.len(), 4, "{places:?}");
    let report = Report::of(&record);
    let rule = report
        .invariants
        .iter()
        .find(|invariant| {
            invariant
                .rule
                .starts_with("every chip lies at its work-schedule place")
        })
        .expect("the chip places are checked");
    assert!(rule.held && rule.required, "{report}");
    assert!(report.chip_places.0 >= 4 * report.lines[0].completed);
}

#[test]
fn the_zone_invariant_is_checked_under_every_policy() {
    for feeder in [FeederPolicy::Arbiter, FeederPolicy::Appendix] {
        let report = Report::of(&run(&config(0.05, 5, feeder)).unwrap());
        let zone = report
            .invariants
            .iter()
            .find(|invariant| {
                invariant
                    .rule
                    .starts_with("no two robots in the feeder zone")
            })
            .unwrap_or_else(|| panic!("checked under {feeder:?}\n{report}"));
        // It is the arbiter's promise; under the Appendix's scheme a violation is a finding.
        assert_eq!(zone.required, feeder == FeederPolicy::Arbiter);
        assert_eq!(zone.held, report.zone_conflicts == 0, "{report}");
        if feeder == FeederPolicy::Arbiter {
            assert!(zone.held, "{report}");
        }
    }
}

#[test]
fn the_report_says_how_robots_spent_the_run_and_what_the_deadlocks_cost() {
    let appendix = Report::of(&run(&config(0.1, 1985, FeederPolicy::Appendix)).unwrap());
    for robot in &appendix.robots {
        let total = robot.moving + robot.working + robot.waiting + robot.idle;
        assert!((total - appendix.simulated).abs() < 1e-6, "{robot:?}");
        assert!(robot.moving > 0.0 && robot.working > 0.0, "{robot:?}");
    }
    assert!(
        appendix.deadlocks > 0 && appendix.deadlock_lost > 0.0,
        "{appendix}"
    );
    let arbiter = Report::of(&run(&config(0.1, 1985, FeederPolicy::Arbiter)).unwrap());
    assert_eq!((arbiter.deadlocks, arbiter.deadlock_lost), (0, 0.0));
    // GATE follows the cycle times the workcells report.
    for history in &arbiter.cycle_times {
        assert_eq!(history.first, Some(10.0));
        assert!(history.changes > 0, "{history:?}");
    }
    // Both stations of both lines held pallets in turn.
    assert!(
        arbiter.stations.iter().flatten().all(Option::is_some),
        "{arbiter}"
    );
}
