//! The chip cell end to end: its report, its invariants under faults, and the deadlock the
//! Appendix predicts.

use std::time::Duration;

use cell_example::{CellConfig, CellFault, CellFaultKind, FeederPolicy, Report, run};
use imrs_sim::imrs_core::EventKind;
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
    // What the fold keeps per pallet is dropped when the pallet leaves the line.
    assert!(full.tally.in_flight() <= 2 * full.pallets_left.len());
}
