//! Which of the seed's mechanisms buys what: the table cell over the same arrivals with
//! zones only; zones and the pipeline; and the coordinator's geometric check and
//! alternative trajectory — each under a static assignment — and then with the run-time
//! scheduler too. Each row sums or sets side by side what rapier and the coordinator saw
//! over every seed.
//!
//! `cargo run --release --example ablation -- [--seeds N] [--hours H]` (10 seeds of 1 h by
//! default), and with `--offset K` a row of the pipeline with an offset of K points.

use std::process::ExitCode;

use table_cell::{Ablation, Assignment, Coordination, ablation};

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("ablation: {error}");
            ExitCode::FAILURE
        }
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let (mut seeds, mut hours, mut offset) = (10_u64, 1.0_f64, None);
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
            "--offset" => {
                offset = Some(
                    value("--offset")?
                        .parse()
                        .map_err(|e| format!("--offset: {e}"))?,
                )
            }
            other => {
                return Err(format!(
                    "unknown argument {other}; use --seeds N, --hours H, --offset K"
                )
                .into());
            }
        }
    }
    let mut rows = vec![
        (Coordination::ZonesOnly, Assignment::Programs),
        (Coordination::Pipeline, Assignment::Programs),
        (Coordination::Full, Assignment::Programs),
        (Coordination::Full, Assignment::RunTime),
    ];
    if let Some(offset) = offset {
        rows.insert(
            1,
            (Coordination::PipelineOffset(offset), Assignment::Programs),
        );
    }
    let table: Ablation = ablation(&rows, 1..=seeds, hours)?;
    print!("{table}");
    Ok(())
}
