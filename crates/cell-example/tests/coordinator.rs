//! The chip cell under the seed-003 coordinator: both chip arms reserve the space their
//! trajectories sweep, and go into the feeder zone together where those do not meet. Over
//! ten seeds of an hour each: no two arms ever touch or come within the coordinator's 3 cm
//! margin (measured by rapier), and more cards per hour than under the arbiter, which holds
//! the whole zone for one arm's round trip, and than under the Appendix's scheme.

use cell_example::{CellConfig, FeederPolicy, Report, run};

fn report(seed: u64, feeder: FeederPolicy) -> Report {
    let config = CellConfig {
        hours: 1.0,
        seed,
        feeder,
        ..CellConfig::default()
    };
    Report::of(&run(&config).unwrap())
}

fn cards_per_hour(report: &Report) -> f64 {
    report.cards_per_hour(0) + report.cards_per_hour(1)
}

#[test]
fn the_coordinator_lets_both_arms_work_without_a_collision_and_beats_the_other_policies() {
    // One thread per seed: each run has its own runtime and world.
    std::thread::scope(|scope| {
        for seed in 1..=10 {
            scope.spawn(move || check(seed));
        }
    });
}

fn check(seed: u64) {
    {
        let coordinator = report(seed, FeederPolicy::Coordinator);
        assert_eq!(coordinator.collisions, 0, "seed {seed}: arms touched");
        // The coordinator keeps reservations 3 cm apart; rapier measures how close the links
        // really came while both were in the zone.
        let closest = coordinator
            .closest_in_zone
            .expect("the arms never shared the zone");
        assert!(
            closest >= 0.03,
            "seed {seed}: the arms came within {closest} m"
        );
        assert!(coordinator.all_held(), "seed {seed}:\n{coordinator}");
        assert!(
            coordinator.zone_shared_seconds > 0.0,
            "seed {seed}: the arms never shared the zone: the test proves nothing"
        );
        for other in [FeederPolicy::Arbiter, FeederPolicy::Appendix] {
            let other = report(seed, other);
            assert!(
                cards_per_hour(&coordinator) > cards_per_hour(&other),
                "seed {seed}: {:.1} cards per hour under the coordinator, {:.1} under {:?}",
                cards_per_hour(&coordinator),
                cards_per_hour(&other),
                other.policy
            );
        }
    }
}
