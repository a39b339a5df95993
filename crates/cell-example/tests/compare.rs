//! The feeder policies compared at once, each on a thread of its own: every run gives what it
//! gives alone, and the runs come back in the table's order.

use cell_example::{CellConfig, POLICIES, Report, compare, run};

/// A report with its wall time, which differs from run to run, left out.
fn report(record: &cell_example::RunRecord) -> Report {
    Report {
        wall: 0.0,
        ..Report::of(record)
    }
}

#[test]
fn each_policy_compared_at_once_reports_what_it_reports_alone() {
    // A fault, so that the runs take their recovering paths too.
    let config = CellConfig {
        hours: 0.1,
        seed: 3,
        faults: vec!["robot:B@2m".parse().unwrap()],
        ..CellConfig::default()
    };
    let comparison = compare(&config);
    let order: Vec<_> = comparison.runs.iter().map(|(policy, _)| *policy).collect();
    assert_eq!(order, POLICIES);
    for (policy, compared) in &comparison.runs {
        let compared = report(compared.as_ref().unwrap());
        let alone = report(
            &run(&CellConfig {
                feeder: *policy,
                ..config.clone()
            })
            .unwrap(),
        );
        assert_eq!(compared.policy, *policy);
        assert_eq!(compared, alone, "{policy:?}");
        assert_eq!(compared.to_string(), alone.to_string(), "{policy:?}");
    }
}

#[test]
fn a_recording_that_cannot_be_written_is_refused_before_any_policy_runs() {
    let config = CellConfig {
        hours: 8.0,
        record: Some("/nonexistent-directory/cell.mcap".into()),
        ..CellConfig::default()
    };
    let comparison = compare(&config);
    // Only the chosen policy's refusal: the other two never started their eight hours.
    assert_eq!(comparison.runs.len(), 1);
    let (policy, refused) = &comparison.runs[0];
    assert_eq!(*policy, config.feeder);
    let refused = refused.as_ref().unwrap_err().to_string();
    assert!(
        refused.starts_with("/nonexistent-directory/cell.mcap: cannot be written"),
        "{refused}"
    );
}
