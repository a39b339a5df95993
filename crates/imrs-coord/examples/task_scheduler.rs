//! The run-time task scheduler against a static assignment, on the same random arrivals:
//! ten seeds of 200 units each, in the assembly cell and in a cell whose shared zone bounds
//! the throughput. Two static baselines: the robots' fixed programs, and the same
//! assignment dispatched in any order; and the part-driven variant, tasks in the order
//! their parts came. Run: `cargo run --release --example task_scheduler`.

use imrs_coord::scheduler::{Arrivals, PartDriven, RunTime, Static, Workcell, simulate};

fn main() {
    for (name, cell) in [
        ("assembly", Workcell::assembly()),
        ("zone-bound", Workcell::zone_bound()),
    ] {
        println!("{name} cell");
        compare(&cell);
    }
}

fn compare(cell: &Workcell) {
    println!(
        "seed  programs u/h  dispatching u/h  part-driven u/h  run-time u/h  gain over programs / dispatching / part-driven"
    );
    let (mut over_programs, mut over_dispatching) = (Vec::new(), Vec::new());
    let mut over_parts = Vec::new();
    for seed in 1..=10 {
        let arrivals = Arrivals::random(cell, 200, seed);
        let programs = simulate(cell, &arrivals, &mut Static::programs(cell));
        let dispatching = simulate(cell, &arrivals, &mut Static::dispatching(cell));
        let part_driven = simulate(cell, &arrivals, &mut PartDriven);
        let run_time = simulate(cell, &arrivals, &mut RunTime::default());
        assert_eq!(
            [
                programs.units,
                dispatching.units,
                part_driven.units,
                run_time.units
            ],
            [200; 4]
        );
        let gain = |baseline: f64| run_time.per_hour() / baseline - 1.0;
        over_programs.push(gain(programs.per_hour()));
        over_dispatching.push(gain(dispatching.per_hour()));
        over_parts.push(gain(part_driven.per_hour()));
        println!(
            "{seed:>4}  {:>12.1}  {:>15.1}  {:>15.1}  {:>12.1}  {:>+6.1} % / {:>+5.1} % / {:>+5.1} %",
            programs.per_hour(),
            dispatching.per_hour(),
            part_driven.per_hour(),
            run_time.per_hour(),
            over_programs[seed as usize - 1] * 100.0,
            over_dispatching[seed as usize - 1] * 100.0,
            over_parts[seed as usize - 1] * 100.0,
        );
    }
    for gains in [&mut over_programs, &mut over_dispatching, &mut over_parts] {
        gains.sort_by(f64::total_cmp);
    }
    let median = |g: &[f64]| (g[4] + g[5]) / 2.0 * 100.0;
    println!(
        "median gain over programs {:+.1} % (least {:+.1} %), over dispatching {:+.1} % (least {:+.1} %), over part-driven {:+.1} % (least {:+.1} %)",
        median(&over_programs),
        over_programs[0] * 100.0,
        median(&over_dispatching),
        over_dispatching[0] * 100.0,
        median(&over_parts),
        over_parts[0] * 100.0
    );
}
