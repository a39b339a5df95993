//! The run-time task scheduler against a static assignment on the same random arrivals, and
//! the rules both must keep.

use imrs_coord::scheduler::{
    Arrivals, Dispatch, PartDriven, Policy, Robot, RunTime, Skill, State, Static, TaskSpec,
    Workcell, Zone, simulate,
};

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

/// A task listed after a task that waits for it: the robot's program still does it first,
/// and every unit is completed (in the order listed, the robot would wait for ever).
#[test]
fn a_program_does_a_prerequisite_listed_last_before_what_waits_for_it() {
    // One robot that can do everything: its program holds every task.
    let mut cell = Workcell::assembly();
    cell.robots.truncate(1);
    cell.robots[0].skills = vec![Skill::Place, Skill::Insert, Skill::Screw];
    cell.robots[0].reach = ([0.0, 0.0], 10.0);
    let first = cell.tasks[0].clone();
    let mut extra = TaskSpec::new("check base", first.skill, 1.0, first.at, &[0], &[]);
    extra.parts.clear();
    cell.tasks.push(extra);
    let last = cell.tasks.len() - 1;
    for task in 1..last {
        if cell.tasks[task].after.contains(&0) {
            cell.tasks[task].after.push(last);
        }
    }
    let arrivals = Arrivals::random(&cell, 20, 1);
    let outcome = simulate(&cell, &arrivals, &mut Static::programs(&cell));
    assert_eq!((outcome.units, outcome.refused), (20, 0));
}

/// Pruning the search never changes a choice: the same runs, pruned or not, also where the
/// score counts the robots in the way.
#[test]
fn pruning_finds_the_same_choices() {
    // The last cell counts robots at work in the way and speeds up at a finite rate.
    let in_the_way = Workcell {
        acceleration: 2.5,
        ..across(0.1)
    };
    for cell in [Workcell::assembly(), Workcell::zone_bound(), in_the_way] {
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
    let mut part_driven = Checked(PartDriven, 0);
    assert_eq!(simulate(&cell, &arrivals, &mut part_driven).units, 30);
    assert_eq!(
        (run_time.1, fixed.1, dispatching.1, part_driven.1),
        (180, 180, 180, 180)
    );
}

/// Two robots either side of a zone: the right one works in it; the left one's way to a
/// task beyond it crosses the zone, and passes the working robot's tool.
fn across(clearance: f64) -> Workcell {
    let robot = |name: &str, home| Robot {
        name: name.into(),
        skills: vec![Skill::Place],
        speed: 1.0,
        home,
        reach: (home, f64::INFINITY),
    };
    Workcell {
        robots: vec![robot("LEFT", [-0.5, 0.0]), robot("RIGHT", [0.5, 0.3])],
        tasks: vec![
            TaskSpec::new("in the zone", Skill::Place, 10.0, [0.0, 0.0], &[], &[0]),
            TaskSpec::new("beyond it", Skill::Place, 1.0, [0.5, 0.0], &[], &[0]),
        ],
        parts: vec!["part"],
        zones: vec![Zone {
            centre: [0.0, 0.0],
            radius: 0.1,
        }],
        travel: 0.5,
        acceleration: f64::INFINITY,
        clearance,
    }
}

/// Its first choice: "in the zone" of unit 0; nothing after.
struct InTheZone(bool);
impl Policy for InTheZone {
    fn choose(&mut self, _: usize, _: &State<'_>) -> Option<(usize, usize)> {
        (!std::mem::replace(&mut self.0, true)).then_some((0, 0))
    }
}

#[test]
fn an_estimate_counts_the_zones_on_the_way_and_the_robots_at_work_it_must_go_round() {
    let arrivals = Arrivals {
        at: vec![vec![0.0]],
    };
    let mut dispatch = Dispatch::new(across(0.1), arrivals.clone());
    // RIGHT takes the task in the zone: 10 s of work there once it has come.
    let (_, _, busy) = dispatch
        .next(1, 0.0, &mut InTheZone(false))
        .unwrap()
        .unwrap();
    let left = dispatch.state().estimate(0, 1);
    // LEFT enters the zone 0.4 m on, at 0.8 s, and waits there until RIGHT is done.
    assert_eq!(left.zones_crossed, 1);
    assert!(
        (left.zone_wait - (busy.finish - 0.8)).abs() < 1e-9,
        "{left:?}"
    );
    // By the time it passes RIGHT's tool, RIGHT is done: nobody to go round.
    assert_eq!((left.in_the_way, left.detour), (0, 0.0));

    // With no zone to wait at, it passes while RIGHT works: round it, half a circle of
    // 0.1 m instead of its diameter.
    let open = Workcell {
        zones: Vec::new(),
        ..across(0.1)
    };
    let mut dispatch = Dispatch::new(open.clone(), arrivals.clone());
    dispatch.next(1, 0.0, &mut InTheZone(false)).unwrap();
    let left = dispatch.state().estimate(0, 1);
    let round = std::f64::consts::PI * 0.1 - 0.2;
    assert_eq!((left.zones_crossed, left.in_the_way), (0, 1));
    assert!((left.detour - round).abs() < 1e-9, "{left:?}");
    assert!(
        (left.finish - (1.0 + round) / 0.5 - 1.0).abs() < 1e-9,
        "{left:?}"
    );
    // Told LEFT stands beyond RIGHT already, its way no longer passes it.
    dispatch.moved(0, [0.6, 0.0]);
    assert_eq!(dispatch.state().estimate(0, 1).in_the_way, 0);

    // With no clearance kept, robots never meet.
    let mut dispatch = Dispatch::new(
        Workcell {
            clearance: 0.0,
            ..open
        },
        arrivals,
    );
    dispatch.next(1, 0.0, &mut InTheZone(false)).unwrap();
    assert_eq!(dispatch.state().estimate(0, 1).in_the_way, 0);
}

/// The part-driven variant takes tasks in the order their parts came; the run-time
/// scheduler, looking ahead, makes more on every seed.
#[test]
fn the_part_driven_variant_follows_the_parts_and_the_run_time_scheduler_makes_more() {
    let cell = Workcell::assembly();
    for seed in 1..=5 {
        let arrivals = Arrivals::random(&cell, 100, seed);
        let part_driven = simulate(&cell, &arrivals, &mut PartDriven);
        let run_time = simulate(&cell, &arrivals, &mut RunTime::default());
        assert_eq!((part_driven.units, part_driven.refused), (100, 0));
        assert!(
            run_time.per_hour() > part_driven.per_hour(),
            "seed {seed}: {run_time:?} against {part_driven:?}"
        );
        println!(
            "seed {seed}: run-time {:.0}/h, part-driven {:.0}/h",
            run_time.per_hour(),
            part_driven.per_hour()
        );
    }
    // Every choice is, of the ready tasks the robot can do, one whose parts (its own, or
    // its prerequisites') came first: checked against the arrivals themselves.
    fn came(cell: &Workcell, arrivals: &Arrivals, unit: usize, task: usize) -> f64 {
        let spec = &cell.tasks[task];
        let own = spec
            .parts
            .iter()
            .map(|&part| arrivals.at[unit][part])
            .fold(f64::NEG_INFINITY, f64::max);
        spec.after
            .iter()
            .map(|&before| came(cell, arrivals, unit, before))
            .fold(own, f64::max)
    }
    struct Ordered<'a>(&'a Workcell, &'a Arrivals, usize);
    impl Policy for Ordered<'_> {
        fn choose(&mut self, robot: usize, state: &State<'_>) -> Option<(usize, usize)> {
            let (unit, task) = PartDriven.choose(robot, state)?;
            let chosen = came(self.0, self.1, unit, task);
            for (other_unit, other) in state.ready_tasks() {
                if state.can(robot, other) {
                    assert!(chosen <= came(self.0, self.1, other_unit, other));
                }
            }
            self.2 += 1;
            Some((unit, task))
        }
    }
    let arrivals = Arrivals::random(&cell, 30, 9);
    let mut ordered = Ordered(&cell, &arrivals, 0);
    assert_eq!(simulate(&cell, &arrivals, &mut ordered).units, 30);
    assert_eq!(ordered.2, 180);
}
