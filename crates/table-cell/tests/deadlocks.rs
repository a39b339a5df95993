//! Deadlocks of each kind the seed names, made to happen in the running cell: the arms go
//! straight on to their next job, and the cell is changed in one thing for each kind. Each
//! deadlock is found by the coordinator and resolved, its victim gets out of the way, the
//! work goes on, and rapier measures no collision and no conflict.

use imrs_coord::zones::DeadlockKind::{Mixed, Tool, Zone};
use table_cell::{Assignment, CellConfig, CellError, Report, Travel, Variant, run, run_all};

/// Seeds `seeds` of an hour for `variant`, arms going straight on, one run on each core.
fn run_variant(variant: Variant, seeds: std::ops::RangeInclusive<u64>) -> Vec<Report> {
    let configs: Vec<CellConfig> = seeds
        .map(|seed| CellConfig {
            travel: Travel::Straight,
            variant,
            ..CellConfig::new(seed, 1.0)
        })
        .collect();
    run_all(&configs).expect("the cell runs")
}

/// Every run clean, every victim out of the way, and units made.
fn assert_resolved(reports: &[Report]) {
    for report in reports {
        assert!(report.is_clean(), "{report}");
        assert!(report.measured.closest.is_some_and(|c| c > 0.0), "{report}");
        assert!(report.units >= 100, "{report}");
        assert_eq!(
            report.stats.victims as usize,
            report.coordinator.resolved(),
            "{report}"
        );
    }
}

fn total(reports: &[Report], count: impl Fn(&Report) -> usize) -> usize {
    reports.iter().map(count).sum()
}

#[test]
fn deadlocks_of_each_kind_happen_in_the_running_cell_and_are_resolved() {
    let seed = run_variant(Variant::AsLaidOut, 1..=2);
    let exclusive_tray = run_variant(Variant::ExclusiveTray, 1..=2);
    let screwed_base = run_variant(Variant::ScrewedBase, 1..=2);
    // Mixed cycles are rare (two over the example's ten hours): all ten seeds.
    let rights_kept = run_variant(Variant::RightsKept, 1..=10);
    for reports in [&seed, &exclusive_tray, &screwed_base, &rights_kept] {
        assert_resolved(reports);
    }

    // As laid out, an arm refused at the fixture's border gives up its right to move in
    // the tray, as the seed's robots do: no cycle runs through the tray.
    assert!(total(&seed, |r| r.stats.rights_given_up as usize) > 0);
    assert_eq!(
        total(&seed, |r| r.deadlocks(Mixed) + r.in_the_way(Mixed)),
        0
    );

    // The tray exclusive: an arm in it asks for the fixture, one in the fixture for the
    // tray. The two meet in the gap between the zones before the second has asked, so the
    // cycle closes through the space of one and the zone of the other, and it happens far
    // more often than the fixture alone makes it happen.
    let zone = |r: &Report| r.deadlocks(Zone) + r.in_the_way(Zone);
    let (tray, fixture) = (total(&exclusive_tray, zone), total(&seed, zone));
    println!("zone deadlocks over two hours: {tray} with the tray exclusive, {fixture} without");
    assert!(tray > 2 * fixture.max(1), "{tray} against {fixture}");

    // The base screwed down: an arm that placed it asks for the screwdriver from inside the
    // fixture, while the screwdriver's holder asks for the fixture. A cycle in the books
    // alone, of the tool.
    let tool = total(&screwed_base, |r| r.deadlocks(Tool));
    println!("tool deadlocks over two hours, in the books alone: {tool}");
    assert!(tool > 0);

    // Against the seed's rule, an arm asleep at the fixture's border keeps moving in the
    // tray: one in the fixture that asks to move there closes a mixed cycle.
    let mixed = total(&rights_kept, |r| r.deadlocks(Mixed));
    println!("mixed deadlocks over ten hours, rights kept at a border: {mixed}");
    assert!(mixed > 0);
}

/// The base screwed down adds a task that tasks listed before it wait for: every way of
/// assigning the work still makes units, each arm's fixed program included.
#[test]
fn the_cell_with_the_base_screwed_down_makes_units_under_every_assignment() {
    let assignments = [
        Assignment::RunTime,
        Assignment::Programs,
        Assignment::Dispatching,
        Assignment::PartDriven,
    ];
    for assignment in assignments {
        let report = run(&CellConfig {
            assignment,
            travel: Travel::Straight,
            variant: Variant::ScrewedBase,
            ..CellConfig::new(1, 0.2)
        })
        .expect("the cell runs");
        assert!(report.is_clean(), "{report}");
        assert!(report.units > 0, "{report}");
    }
}

/// A variant made to provoke deadlocks, with arms that go home between jobs, would provoke
/// none: the run is refused, naming the variant.
#[test]
fn a_variant_with_arms_going_home_is_refused_by_name() {
    for variant in Variant::ALL {
        let config = CellConfig {
            variant,
            ..CellConfig::new(1, 0.01)
        };
        let refused = run(&config);
        if variant == Variant::AsLaidOut {
            assert!(refused.is_ok());
            continue;
        }
        let error = refused.expect_err("a variant going home");
        assert!(matches!(error, CellError::Variant(v) if v == variant));
        assert!(error.to_string().contains(variant.flag()), "{error}");
    }
    // A flag that names no variant is refused, naming it and every variant.
    let error = "rights-keep".parse::<Variant>().unwrap_err();
    assert!(error.to_string().contains("rights-keep"), "{error}");
    assert!(error.to_string().contains("rights-kept"), "{error}");
}
