//! The run-time task scheduler against a static assignment on the same random arrivals, and
//! the rules both must keep.

use imrs_coord::scheduler::{Arrivals, Policy, RunTime, State, Static, Workcell, simulate};

/// The goal: at least 15 % more units per hour than the robots' static programs, on every
/// one of ten seeds of random arrivals.
#[test]
fn the_run_time_scheduler_beats_static_programs_by_15_percent() {
    let cell = Workcell::assembly();
    for seed in 1..=10 {
        let arrivals = Arrivals::random(&cell, 200, seed);
        let fixed = simulate(&cell, &arrivals, &mut Static::programs(&cell));
        let run_time = simulate(&cell, &arrivals, &mut RunTime::default());
        assert_eq!((fixed.units, run_time.units), (200, 200), "seed {seed}");
        assert_eq!((fixed.refused, run_time.refused), (0, 0));
        let gain = run_time.per_hour() / fixed.per_hour() - 1.0;
        assert!(gain >= 0.15, "seed {seed}: only {:+.1} %", gain * 100.0);
    }
}

/// Pruning the search never changes a choice: the same runs, pruned or not.
#[test]
fn pruning_finds_the_same_choices() {
    for cell in [Workcell::assembly(), Workcell::zone_bound()] {
        for seed in 1..=5 {
            let arrivals = Arrivals::random(&cell, 60, seed);
            let pruned = simulate(&cell, &arrivals, &mut RunTime::default());
            let full = RunTime {
                prune: false,
                ..RunTime::default()
            };
            assert_eq!(pruned, simulate(&cell, &arrivals, &mut full.clone()));
        }
    }
}

#[test]
fn the_same_arrivals_give_the_same_run() {
    let cell = Workcell::assembly();
    let arrivals = Arrivals::random(&cell, 50, 3);
    assert_eq!(arrivals, Arrivals::random(&cell, 50, 3));
    assert_ne!(arrivals, Arrivals::random(&cell, 50, 4));
    let a = simulate(&cell, &arrivals, &mut RunTime::default());
    let b = simulate(&cell, &arrivals, &mut RunTime::default());
    assert_eq!(a, b);
}

/// A policy that wants a task before its parts came, or one beyond the robot's skills, is
/// refused each time, and the cell goes on.
#[test]
fn a_choice_the_cell_cannot_carry_out_is_refused() {
    struct Careless;
    impl Policy for Careless {
        fn choose(&mut self, robot: usize, state: &State<'_>) -> Option<(usize, usize)> {
            // "screw cover" of the last unit: its prerequisites are never done first.
            Some((state.units() - 1, robot.min(5)))
        }
    }
    let cell = Workcell::assembly();
    let arrivals = Arrivals::random(&cell, 3, 1);
    let outcome = simulate(&cell, &arrivals, &mut Careless);
    assert!(outcome.refused > 0);
    assert!(outcome.units < 3);
}

/// Parts in random order: every task waits for its parts and prerequisites under either
/// policy — checked by a policy wrapper that looks at each choice.
#[test]
fn no_task_starts_before_its_parts_and_prerequisites() {
    struct Checked<P>(P, usize);
    impl<P: Policy> Policy for Checked<P> {
        fn choose(&mut self, robot: usize, state: &State<'_>) -> Option<(usize, usize)> {
            let choice = self.0.choose(robot, state);
            if let Some((unit, task)) = choice {
                assert!(state.ready(unit, task), "unit {unit} task {task} not ready");
                assert!(state.can(robot, task));
                self.1 += 1;
            }
            choice
        }
    }
    let cell = Workcell::assembly();
    let arrivals = Arrivals::random(&cell, 30, 11);
    let mut run_time = Checked(RunTime::default(), 0);
    assert_eq!(simulate(&cell, &arrivals, &mut run_time).units, 30);
    let mut fixed = Checked(Static::programs(&cell), 0);
    assert_eq!(simulate(&cell, &arrivals, &mut fixed).units, 30);
    let mut dispatching = Checked(Static::dispatching(&cell), 0);
    assert_eq!(simulate(&cell, &arrivals, &mut dispatching).units, 30);
    assert_eq!((run_time.1, fixed.1, dispatching.1), (180, 180, 180));
}
