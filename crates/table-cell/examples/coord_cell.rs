//! The coordinated table cell: four arms sharing an exclusive fixture, a shared tray and
//! one screwdriver, under the zone coordinator and the run-time task scheduler.
//!
//! `cargo run --release --example coord_cell -- [--seed N] [--hours H] [--straight]
//! [--variant as-laid-out|exclusive-tray|screwed-base|rights-kept] [--compare]`
//!
//! With `--compare`, the same arrivals also run under the static assignment (each arm's
//! fixed program, and the same assignment dispatched) and the part-driven variant, and the
//! units made are set side by side. With `--straight`, each arm goes straight on to its
//! next job instead of home, and asks for the fixture from inside the tray. With
//! `--variant`, the cell is changed in one thing so that deadlocks of one kind happen (with
//! `--straight`): the tray exclusive (zone), the base screwed down (tool), or rights to move
//! kept at a border against the seed's rule (mixed).

use std::process::ExitCode;

use table_cell::{Assignment, CellConfig, Travel, run};

fn main() -> ExitCode {
    match cell() {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("coord_cell: {error}");
            ExitCode::FAILURE
        }
    }
}

fn cell() -> Result<(), Box<dyn std::error::Error>> {
    let mut config = CellConfig::new(1, 1.0);
    let mut compare = false;
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = |flag: &str| args.next().ok_or_else(|| format!("{flag} needs a value"));
        match arg.as_str() {
            "--seed" => {
                config.seed = value("--seed")?
                    .parse()
                    .map_err(|e| format!("--seed: {e}"))?
            }
            "--hours" => {
                config.hours = value("--hours")?
                    .parse()
                    .map_err(|e| format!("--hours: {e}"))?
            }
            "--compare" => compare = true,
            "--straight" => config.travel = Travel::Straight,
            "--variant" => {
                config.variant = value("--variant")?
                    .parse()
                    .map_err(|e| format!("--variant: {e}"))?
            }
            other => {
                return Err(format!(
                    "unknown argument {other}; use --seed N, --hours H, --straight, \
                     --variant V, --compare"
                )
                .into());
            }
        }
    }
    let report = run(&config)?;
    print!("{report}");
    println!("  (ran in {:.1} s)", report.wall.as_secs_f64());
    if compare {
        println!();
        println!("the same arrivals, units per hour:");
        println!(
            "  {:<20} {:>7.1}",
            Assignment::RunTime.to_string(),
            report.per_hour()
        );
        for assignment in [
            Assignment::Programs,
            Assignment::Dispatching,
            Assignment::PartDriven,
        ] {
            let other = run(&CellConfig {
                assignment,
                ..config.clone()
            })?;
            let gain = 100.0 * (report.per_hour() / other.per_hour() - 1.0);
            println!(
                "  {:<20} {:>7.1}   run-time {gain:+.1} %{}",
                assignment.to_string(),
                other.per_hour(),
                if other.is_clean() {
                    ""
                } else {
                    "  (not clean: see its report)"
                }
            );
        }
    }
    Ok(())
}
