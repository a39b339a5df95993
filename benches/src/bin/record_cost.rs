//! What recording costs: the chip cell (seed 1985, arbiter, virtual time) run alternately
//! without and with `--record`, round after round in this one process, so that both see the
//! same machine; prints each round, the medians, and the slowdown as their ratio (the target:
//! under 2). Also the file's size, and the resident memory after each recorded run, which
//! stays flat whatever the run's length (the recorder streams).
//!
//! ```text
//! cargo run --release -p imrs-benches --bin record_cost [HOURS] [ROUNDS]
//! ```

use std::time::Instant;

use cell_example::{CellConfig, run};
use imrs_benches::resident_bytes;

fn main() {
    let mut args = std::env::args().skip(1);
    let hours: f64 = args.next().and_then(|h| h.parse().ok()).unwrap_or(1.0);
    let rounds: usize = args.next().and_then(|n| n.parse().ok()).unwrap_or(5);
    let path = std::env::temp_dir().join(format!("imrs-record-cost-{}.mcap", std::process::id()));
    let plain = CellConfig {
        hours,
        ..CellConfig::default()
    };
    let recorded = CellConfig {
        record: Some(path.clone()),
        ..plain.clone()
    };
    let (mut off, mut on) = (Vec::new(), Vec::new());
    println!("chip cell, {hours} h simulated, {rounds} rounds");
    for round in 1..=rounds {
        let started = Instant::now();
        run(&plain).expect("the chip cell runs");
        off.push(started.elapsed().as_secs_f64());
        let started = Instant::now();
        run(&recorded).expect("the chip cell runs and records");
        on.push(started.elapsed().as_secs_f64());
        let size = std::fs::metadata(&path).map_or(0, |m| m.len());
        let resident = resident_bytes().unwrap_or(0);
        println!(
            "  round {round}: off {:.3} s, on {:.3} s ({:.2}x), file {:.1} MB, resident {:.1} MB",
            off[round - 1],
            on[round - 1],
            on[round - 1] / off[round - 1],
            size as f64 / 1e6,
            resident as f64 / 1e6
        );
    }
    let _ = std::fs::remove_file(&path);
    let (off, on) = (median(&mut off), median(&mut on));
    println!(
        "median: off {off:.3} s, on {on:.3} s: recording slows the run {:.2}x (target < 2)",
        on / off
    );
}

fn median(values: &mut [f64]) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}
