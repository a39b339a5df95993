//! Deadlocks of each kind the seed names, made to happen in the running cell: arms going
//! straight on to their next job, the cell as laid out and changed in one thing for each
//! kind. Each row sums over every seed what the coordinator found and resolved, and what
//! rapier measured.
//!
//! `cargo run --release --example deadlocks -- [--seeds N] [--hours H]` (10 seeds of 1 h by
//! default).

use std::process::ExitCode;

use imrs_coord::zones::DeadlockKind;
use table_cell::{CellConfig, Report, Travel, Variant, run_all};

fn main() -> ExitCode {
    match table() {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("deadlocks: {error}");
            ExitCode::FAILURE
        }
    }
}

fn table() -> Result<(), Box<dyn std::error::Error>> {
    let (mut seeds, mut hours) = (10_u64, 1.0_f64);
    let mut args = std::env::args().skip(1);
    while let Some(arg) = args.next() {
        let mut value = |flag: &str| args.next().ok_or_else(|| format!("{flag} needs a value"));
        match arg.as_str() {
            "--seeds" => {
                seeds = value("--seeds")?
                    .parse()
                    .map_err(|e| format!("--seeds: {e}"))?
            }
            "--hours" => {
                hours = value("--hours")?
                    .parse()
                    .map_err(|e| format!("--hours: {e}"))?
            }
            other => {
                return Err(format!("unknown argument {other}; use --seeds N, --hours H").into());
            }
        }
    }
    if seeds == 0 {
        return Err("--seeds: at least one seed".into());
    }
    println!(
        "{seeds} seeds × {hours} h each, arms going straight on; deadlocks found and resolved \
         by the coordinator (zone / tool / mixed), the rest measured by rapier"
    );
    println!();
    println!(
        "| cell | in the books | of space and zones | victims | collisions | closest | \
         zone conflicts | units / h |"
    );
    println!("|---|---:|---:|---:|---:|---:|---:|---:|");
    for variant in Variant::ALL {
        let configs: Vec<CellConfig> = (1..=seeds)
            .map(|seed| CellConfig {
                travel: Travel::Straight,
                variant,
                ..CellConfig::new(seed, hours)
            })
            .collect();
        let reports = run_all(&configs)?;
        let sum = |count: &dyn Fn(&Report) -> usize| -> usize { reports.iter().map(count).sum() };
        let kinds = |count: &dyn Fn(&Report, DeadlockKind) -> usize| -> String {
            let each = [DeadlockKind::Zone, DeadlockKind::Tool, DeadlockKind::Mixed]
                .map(|kind| sum(&|r: &Report| count(r, kind)).to_string());
            each.join(" / ")
        };
        let closest = reports
            .iter()
            .filter_map(|r| r.measured.closest)
            .reduce(f32::min)
            .map_or("-".to_string(), |c| format!("{:.0} mm", c * 1000.0));
        let units = sum(&|r: &Report| r.units) as f64 / (seeds as f64 * hours);
        println!(
            "| {variant} | {} | {} | {} | {} | {closest} | {} | {units:.1} |",
            kinds(&Report::deadlocks),
            kinds(&Report::in_the_way),
            sum(&|r: &Report| r.stats.victims as usize),
            sum(&|r: &Report| r.measured.collisions.len()),
            sum(&|r: &Report| r.measured.zone_conflicts.len()),
        );
    }
    Ok(())
}
