//! Prints one table from criterion's saved estimates: each case, its median, its baseline's
//! median from the same run, the ratio, and the target. Run after `cargo bench`:
//!
//! ```text
//! cargo run -p imrs-benches --bin ratio_table
//! ```

use std::path::Path;

use imrs_benches::criterion_dir;

/// The median of a case, in nanoseconds, from `<criterion>/<case>/new/estimates.json`.
fn median(root: &Path, case: &str) -> Option<f64> {
    let text = std::fs::read_to_string(root.join(case).join("new/estimates.json")).ok()?;
    let after = &text[text.find("\"median\"")?..];
    let after = &after[after.find("\"point_estimate\":")? + "\"point_estimate\":".len()..];
    let end = after.find([',', '}'])?;
    after[..end].trim().parse().ok()
}

fn show(nanos: Option<f64>) -> String {
    match nanos {
        Some(n) if n >= 1e6 => format!("{:.2} ms", n / 1e6),
        Some(n) if n >= 1e3 => format!("{:.2} us", n / 1e3),
        Some(n) => format!("{n:.0} ns"),
        None => "-".into(),
    }
}

fn main() {
    let root = criterion_dir();
    if !root.exists() {
        eprintln!(
            "no estimates under {}: run `cargo bench` first",
            root.display()
        );
        std::process::exit(1);
    }
    let mut rows: Vec<(String, String, f64, &str)> = Vec::new();
    for size in ["8B", "1KiB"] {
        rows.push((
            format!("rendezvous_same_thread/imrs/{size}"),
            format!("rendezvous_same_thread/tokio_ask_current_thread/{size}"),
            1.0,
            "<= 0.25",
        ));
        rows.push((
            format!("rendezvous_same_thread/imrs_prioritized/{size}"),
            format!("rendezvous_same_thread/imrs/{size}"),
            1.0,
            "<= 1.1 (priorities on)",
        ));
        rows.push((
            format!("rendezvous_same_thread/imrs_two_tasks/{size}"),
            format!("rendezvous_same_thread/tokio_ask_current_thread/{size}"),
            1.0,
            "(one task per end)",
        ));
        rows.push((
            format!("rendezvous_cross_thread_cold/imrs/{size}"),
            format!("rendezvous_cross_thread_cold/tokio_ask_multi_thread/{size}"),
            1.0,
            "<= 0.8",
        ));
        rows.push((
            format!("rendezvous_cross_thread_cold/crossbeam_ping_pong/{size}"),
            format!("rendezvous_cross_thread_cold/tokio_ask_multi_thread/{size}"),
            1.0,
            "(baseline)",
        ));
        rows.push((
            format!("rendezvous_tight/imrs/{size}"),
            format!("rendezvous_tight/atomic_spin_ping_pong/{size}"),
            1.0,
            "<= 1.2",
        ));
    }
    rows.push((
        "query/responder_idle".into(),
        "query/same_thread_rendezvous".into(),
        1.0,
        "<= 1.5",
    ));
    rows.push((
        "query/responder_in_lower_section".into(),
        "query/same_thread_rendezvous".into(),
        1.0,
        "-",
    ));
    // Linear growth means the 64-task round costs at most 32 times the 2-task one.
    rows.push((
        "waitfor/64".into(),
        "waitfor/2".into(),
        32.0,
        "<= 1 (linear in n)",
    ));
    rows.push((
        "waitfor/16".into(),
        "waitfor/2".into(),
        8.0,
        "<= 1 (linear in n)",
    ));
    rows.push((
        "select/8_ports_all_ready".into(),
        "select/8_ports_one_ready".into(),
        1.0,
        "-",
    ));
    rows.push((
        "filter/bounded_buffer".into(),
        "filter/tokio_mpsc".into(),
        1.0,
        "-",
    ));

    println!(
        "{:<58} {:>10} {:>10} {:>7}  target",
        "case (baseline below)", "median", "baseline", "ratio"
    );
    for (case, baseline, scale, target) in rows {
        let (a, b) = (median(&root, &case), median(&root, &baseline));
        let ratio = match (a, b) {
            (Some(a), Some(b)) if b > 0.0 => format!("{:.2}", a / (b * scale)),
            _ => "-".into(),
        };
        println!(
            "{case:<58} {:>10} {:>10} {ratio:>7}  {target}",
            show(a),
            show(b)
        );
        println!("  vs {baseline}");
    }
    if let Some(minute) = median(&root, "sim_speed/busy_cell_minute") {
        println!(
            "sim_speed: {:.0} simulated seconds per wall second (busy two-line cell)",
            60.0 / (minute / 1e9)
        );
    }
    println!();
    println!("tail latency of single round trips (p50 / p99 / p99.9):");
    let mut tails: Vec<_> = std::fs::read_dir(root.join("tail"))
        .map(|dir| {
            dir.filter_map(Result::ok)
                .map(|entry| entry.path())
                .collect()
        })
        .unwrap_or_default();
    tails.sort();
    for path in tails {
        let text = std::fs::read_to_string(&path).unwrap_or_default();
        let values: Vec<Option<f64>> = text.split_whitespace().map(|v| v.parse().ok()).collect();
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_default();
        if let [p50, p99, p999] = values[..] {
            println!(
                "  {name:<56} {} / {} / {}",
                show(p50),
                show(p99),
                show(p999)
            );
        }
    }
}
