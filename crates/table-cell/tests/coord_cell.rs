//! The coordinated table cell, run as the example runs it: ten seeds of a simulated hour
//! each with neither a collision nor a zone or tool conflict measured by rapier, while the
//! zones, the tool and the arms' space are really contested; the same seed, the same run;
//! the run-time scheduler against a static assignment on the same arrivals.

use table_cell::{Assignment, CellConfig, CellError, Report, Travel, run};

fn config(seed: u64, hours: f64, assignment: Assignment) -> CellConfig {
    CellConfig {
        assignment,
        ..CellConfig::new(seed, hours)
    }
}

/// Runs `configs`, one run on each core.
fn runs(configs: Vec<CellConfig>) -> Vec<Report> {
    table_cell::run_all(&configs).expect("the cell runs")
}

#[test]
fn ten_seeds_of_an_hour_each_with_no_collision_and_no_conflict() {
    let reports = runs(
        (1..=10)
            .map(|seed| config(seed, 1.0, Assignment::RunTime))
            .collect(),
    );
    for report in &reports {
        let measured = &report.measured;
        assert!(measured.collisions.is_empty(), "{report}");
        assert!(measured.zone_conflicts.is_empty(), "{report}");
        assert!(measured.tool_conflicts.is_empty(), "{report}");
        assert!(report.stats.failures.is_empty(), "{report}");
        // The links of two arms never touched: rapier's closest approach is positive.
        assert!(measured.closest.is_some_and(|c| c > 0.0), "{report}");
        // Not a cell that is clean because nothing happened: units were made by every arm,
        // both zones were used, and the arms met at their borders and in each other's way.
        assert!(report.units >= 150, "{report}");
        assert!(report.stats.jobs.iter().all(|&jobs| jobs > 50), "{report}");
        assert!(
            measured
                .zone_time
                .iter()
                .all(|(_, time)| time.as_secs() > 600),
            "{report}"
        );
        assert!(report.coordinator.slept > 100, "{report}");
        assert!(report.stats.geometric_blocks > 100, "{report}");
        // Two arms in each other's way: one backed off, and the work went on.
        assert!(report.stats.back_offs > 0, "{report}");
        // A stopped arm in the way: gone round on the alternative trajectory.
        assert!(report.stats.detours > 0, "{report}");
        // The coordinator did the geometric work, from the positions the arms told it:
        // every step's way ahead checked, and blocks found.
        let log = &report.coordinator;
        assert!(log.checked > 10_000 && log.blocked > 100, "{report}");
        // Every victim of a deadlock the coordinator found, of zones or of space and
        // zones, got out of the way, and the work went on.
        assert_eq!(report.stats.victims as usize, log.resolved(), "{report}");
        // Going home between jobs, an arm holds nothing while it waits for the tool: no
        // cycle of zones and the tool forms.
        assert!(log.deadlocks.is_empty(), "{report}");
        // The cell on the paper's bus: every port between the coordinator, the scheduler
        // and the arms crosses stations and has its worst case.
        let crossing = report.network.iter().filter(|b| b.stations.len() > 1);
        assert!(crossing.clone().count() >= 9, "{report}");
        assert!(
            crossing.clone().all(|b| !b.round_trip.is_zero()),
            "{report}"
        );
    }
    let per_hour: Vec<f64> = reports.iter().map(Report::per_hour).collect();
    println!("units per hour over ten seeds: {per_hour:?}");
}

/// Arms that go straight on to their next job ask for the fixture from inside the tray, in
/// which they move: refused at the border, each stops and gives up its right to move
/// there, and another moves in the tray meanwhile. An arm stopped at a border is at times
/// in the way of the arm it waits for; the coordinator finds that deadlock. Rapier sees no
/// collision and no conflict, and every victim of a deadlock got out of the way.
#[test]
fn arms_going_straight_on_give_up_their_right_to_move_in_the_tray_at_the_fixture() {
    let reports = runs(
        (1..=4)
            .map(|seed| CellConfig {
                travel: Travel::Straight,
                ..CellConfig::new(seed, 0.5)
            })
            .collect(),
    );
    for report in &reports {
        assert!(report.is_clean(), "{report}");
        assert!(report.measured.closest.is_some_and(|c| c > 0.0), "{report}");
        assert!(report.units >= 60, "{report}");
        let log = &report.coordinator;
        assert_eq!(report.stats.victims as usize, log.resolved(), "{report}");
    }
    let given_up: u32 = reports.iter().map(|r| r.stats.rights_given_up).sum();
    assert!(given_up > 0, "no right to move given up at a border");
    println!("rights to move given up at a border over four half hours: {given_up}");
    // An arm stopped at a border in the way of the one it waits for: the deadlock of space
    // and zones happens, and is resolved.
    let in_the_way: usize = reports.iter().map(|r| r.coordinator.in_the_way.len()).sum();
    assert!(
        in_the_way > 0,
        "no deadlock of space and zones in two hours"
    );
    println!("deadlocks of space and zones over four half hours: {in_the_way}");
}

#[test]
fn the_same_seed_gives_the_same_run() {
    let reports = runs(vec![
        config(7, 0.1, Assignment::RunTime),
        config(7, 0.1, Assignment::RunTime),
    ]);
    let strip = |report: &Report| Report {
        wall: std::time::Duration::ZERO,
        ..report.clone()
    };
    assert_eq!(strip(&reports[0]), strip(&reports[1]));
    assert!(reports[0].units > 0);
}

/// The run-time scheduler makes strictly more units per hour than a static assignment, each
/// arm's fixed program or the same assignment dispatched, on every seed of the same
/// arrivals, over an hour. Over half an hour the count is still the cell's filling: the
/// run-time scheduler starts more units at once, and they end later, so that half-hour
/// counts tie. The goal of 15 % more is not met by arms that speed up and brake at their
/// limit: they spend more of each job on the way and stopped in each other's way, which no
/// assignment changes, and the gain measured here is 12.3 to 14.2 % over the programs and
/// 7.3 to 14.2 % over the same assignment dispatched. The figures are printed.
#[test]
fn the_run_time_scheduler_makes_more_than_a_static_assignment_on_the_same_arrivals() {
    let configs = (1..=6)
        .flat_map(|seed| {
            [
                Assignment::RunTime,
                Assignment::Programs,
                Assignment::Dispatching,
            ]
            .map(|assignment| config(seed, 1.0, assignment))
        })
        .collect();
    let reports = runs(configs);
    for runs in reports.chunks(3) {
        let [run_time, programs, dispatching] = [&runs[0], &runs[1], &runs[2]];
        for report in runs {
            assert!(report.is_clean(), "{report}");
        }
        assert!(
            run_time.per_hour() > programs.per_hour(),
            "{run_time}\n{programs}"
        );
        assert!(
            run_time.per_hour() > dispatching.per_hour(),
            "{run_time}\n{dispatching}"
        );
        let gain = |other: &Report| 100.0 * (run_time.per_hour() / other.per_hour() - 1.0);
        println!(
            "seed {}: run-time {:.0}/h, static programs {:.0}/h ({:+.1} %), dispatched {:.0}/h ({:+.1} %)",
            run_time.config.seed,
            run_time.per_hour(),
            programs.per_hour(),
            gain(programs),
            dispatching.per_hour(),
            gain(dispatching),
        );
    }
}

#[test]
fn a_run_of_no_length_is_refused_by_its_value() {
    for hours in [0.0, -1.0, f64::NAN, 100.0] {
        let error = run(&config(1, hours, Assignment::RunTime)).unwrap_err();
        assert!(matches!(error, CellError::Hours(h) if h.to_bits() == hours.to_bits()));
        assert!(error.to_string().contains("hours"), "{error}");
    }
}
