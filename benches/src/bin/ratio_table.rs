//! Prints one table from criterion's saved estimates: each case, its median, its baseline's
//! median from the same run, the ratio, and the target. Run after `cargo bench`:
//!
//! ```text
//! cargo run -p imrs-benches --bin ratio_table
//! ```
//!
//! It also saves the run's ratios to `<criterion>/ratios.tsv`. One run on a shared machine
//! says little: `benches/runs.sh N` runs the benches N times, keeps each run's ratios, and
//! ends with `ratio_table --runs DIR`, which prints each row's median and spread over them.

use std::path::Path;

use imrs_benches::criterion_dir;

/// Appends a line to the output, printed whole at the end: a reader that stops early
/// (`| head`) then costs nothing but the rest of the text.
macro_rules! say {
    ($out:expr) => {
        $out.push('\n')
    };
    ($out:expr, $($arg:tt)*) => {{
        use std::fmt::Write as _;
        let _ = writeln!($out, $($arg)*);
    }};
}

/// Prints `out`; a closed pipe is no error of the table's.
fn emit(out: &str) {
    use std::io::Write as _;
    let _ = std::io::stdout().lock().write_all(out.as_bytes());
}

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
    let mut args = std::env::args().skip(1);
    if args.next().as_deref() == Some("--runs") {
        let Some(dir) = args.next() else {
            eprintln!("usage: ratio_table [--runs DIR]");
            std::process::exit(2);
        };
        summarize(Path::new(&dir));
        return;
    }
    let mut out = String::new();
    let root = criterion_dir();
    if !root.exists() {
        eprintln!(
            "no estimates under {}: run `cargo bench` first",
            root.display()
        );
        std::process::exit(1);
    }
    let mut rows: Vec<(String, String, f64, &str)> = Vec::new();
    let mut row = |case: &str, baseline: &str, scale: f64, target: &'static str| {
        rows.push((case.to_owned(), baseline.to_owned(), scale, target));
    };
    for (size, same_thread_target, tight_target) in
        [("8B", "<= 0.25", "<= 1.2"), ("1KiB", "<= 0.5", "-")]
    {
        let same = |who: &str| format!("rendezvous_same_thread/{who}/{size}");
        let cold = |who: &str| format!("rendezvous_cross_thread_cold/{who}/{size}");
        let tight = |who: &str| format!("rendezvous_tight/{who}/{size}");
        row(
            &same("imrs_one_processor"),
            &same("tokio_two_tasks"),
            1.0,
            same_thread_target,
        );
        row(
            &same("imrs_one_processor"),
            &same("kameo_ask"),
            1.0,
            "(vs kameo)",
        );
        row(
            &same("imrs_one_processor"),
            &same("ractor_call"),
            1.0,
            "(vs ractor)",
        );
        row(
            &same("imrs_one_processor_prioritized"),
            &same("imrs_one_processor"),
            1.0,
            "<= 1.1 (priorities on)",
        );
        row(
            &same("imrs_two_tasks"),
            &same("tokio_two_tasks"),
            1.0,
            "(one task per end)",
        );
        row(
            &cold("imrs"),
            &cold("tokio_ask"),
            1.0,
            "<= 0.8 (see cross_thread_runs)",
        );
        row(&cold("imrs"), &cold("kameo_ask"), 1.0, "(vs kameo)");
        row(&cold("imrs"), &cold("ractor_call"), 1.0, "(vs ractor)");
        row(
            &cold("crossbeam_ping_pong"),
            &cold("tokio_ask"),
            1.0,
            "(baseline)",
        );
        row(
            &tight("imrs"),
            &tight("atomic_spin_ping_pong"),
            1.0,
            tight_target,
        );
        let payload_target = if size == "8B" { "-" } else { "<= 2" };
        row(
            &tight("imrs"),
            &tight("atomic_spin_ping_pong_payload"),
            1.0,
            payload_target,
        );
    }
    row(
        "ctx_same_thread/ctx",
        "ctx_same_thread/raw_end",
        1.0,
        "<= 1.3",
    );
    row(
        "ctx_multi_thread/ctx",
        "ctx_multi_thread/raw_end",
        1.0,
        "<= 1.3",
    );
    row(
        "query/responder_idle",
        "query/same_thread_rendezvous",
        1.0,
        "<= 1.5",
    );
    row(
        "query/responder_in_lower_section",
        "query/same_thread_rendezvous",
        1.0,
        "-",
    );
    // Per task: linear growth means the n-task round costs n/2 times the 2-task one.
    row("waitfor/16", "waitfor/2", 8.0, "-");
    row(
        "waitfor/64",
        "waitfor/2",
        32.0,
        "<= 1.05 (per task, vs n = 2)",
    );
    row(
        "waitfor/256",
        "waitfor/2",
        128.0,
        "<= 1.05 (per task, vs n = 2)",
    );
    row(
        "waitfor/tokio_barrier/64",
        "waitfor/tokio_barrier/2",
        32.0,
        "(tokio's own growth)",
    );
    row(
        "waitfor/tokio_barrier/256",
        "waitfor/tokio_barrier/2",
        128.0,
        "(tokio's own growth)",
    );
    row(
        "waitfor/64",
        "waitfor/tokio_barrier/64",
        1.0,
        "(vs tokio Barrier)",
    );
    row(
        "select/8_ports_all_ready",
        "select/8_ports_one_ready",
        1.0,
        "-",
    );
    row("filter/bounded_buffer", "filter/tokio_mpsc", 1.0, "<= 3");
    row(
        "filter/bounded_buffer_on_processor",
        "filter/tokio_mpsc",
        1.0,
        "<= 3",
    );
    let cores = std::thread::available_parallelism().map_or(2, usize::from);
    let mut threads = vec![1, 2, cores];
    threads.dedup();
    for n in threads {
        let ring = |who: &str| format!("ring_1000/{who}/{n}_threads");
        row(&ring("imrs"), &ring("tokio"), 1.0, "(time per hop)");
    }

    say!(
        out,
        "{:<58} {:>10} {:>10} {:>7}  target",
        "case (baseline below)",
        "median",
        "baseline",
        "ratio"
    );
    let mut saved = String::new();
    for (case, baseline, scale, target) in rows {
        let (a, b) = (median(&root, &case), median(&root, &baseline));
        let ratio = match (a, b) {
            (Some(a), Some(b)) if b > 0.0 => format!("{:.2}", a / (b * scale)),
            _ => "-".into(),
        };
        saved.push_str(&format!("{case}\t{baseline}\t{ratio}\t{target}\n"));
        say!(
            out,
            "{case:<58} {:>10} {:>10} {ratio:>7}  {target}",
            show(a),
            show(b)
        );
        say!(out, "  vs {baseline}");
    }
    if let Err(error) = std::fs::write(root.join("ratios.tsv"), saved) {
        eprintln!("cannot save this run's ratios: {error}");
    }
    let tail = |case: &str| -> Option<f64> {
        let text = std::fs::read_to_string(root.join("tail").join(format!("{case}.txt"))).ok()?;
        text.split_whitespace().nth(2)?.parse().ok()
    };
    let (imrs, tokio) = (
        tail("rendezvous_cross_thread_cold_imrs_8B"),
        tail("rendezvous_cross_thread_cold_tokio_ask_8B"),
    );
    if let (Some(imrs), Some(tokio)) = (imrs, tokio) {
        say!(
            out,
            "{:<58} {:>10} {:>10} {:>7.2}  <= 1 (p99.9 vs tokio's)",
            "rendezvous_cross_thread_cold/imrs/8B p99.9",
            show(Some(imrs)),
            show(Some(tokio)),
            imrs / tokio
        );
    }
    if let Some(minute) = median(&root, "sim_speed/busy_cell_minute") {
        say!(
            out,
            "sim_speed: {:.0} simulated seconds per wall second (busy two-line cell)",
            60.0 / (minute / 1e9)
        );
    }
    say!(out);
    say!(
        out,
        "tail latency of single round trips (p50 / p99 / p99.9):"
    );
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
            say!(
                out,
                "  {name:<56} {} / {} / {}",
                show(p50),
                show(p99),
                show(p999)
            );
        }
    }
    emit(&out);
}

/// Each row's median ratio and spread over the runs saved in `dir` (one `.tsv` a run).
fn summarize(dir: &Path) {
    let mut out = String::new();
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .filter_map(Result::ok)
                .map(|entry| entry.path())
                .filter(|path| path.extension().is_some_and(|ext| ext == "tsv"))
                .collect()
        })
        .unwrap_or_default();
    files.sort();
    if files.is_empty() {
        eprintln!("no saved runs (*.tsv) in {}", dir.display());
        std::process::exit(1);
    }
    // Rows in the order of the first run; ratios of every run, by (case, baseline).
    let mut order: Vec<(String, String, String)> = Vec::new();
    let mut ratios: std::collections::HashMap<(String, String), Vec<f64>> = Default::default();
    for file in &files {
        for line in std::fs::read_to_string(file).unwrap_or_default().lines() {
            let fields: Vec<&str> = line.split('\t').collect();
            let [case, baseline, ratio, target] = fields[..] else {
                continue;
            };
            let key = (case.to_owned(), baseline.to_owned());
            if !ratios.contains_key(&key) {
                order.push((key.0.clone(), key.1.clone(), target.to_owned()));
            }
            let entry = ratios.entry(key).or_default();
            if let Ok(ratio) = ratio.parse() {
                entry.push(ratio);
            }
        }
    }
    say!(
        out,
        "{} runs; each row: the median ratio over them, and its spread (lowest to highest)\n",
        files.len()
    );
    say!(
        out,
        "{:<58} {:>6} {:>13}  target",
        "case (baseline below)",
        "median",
        "spread"
    );
    for (case, baseline, target) in order {
        let mut values = ratios
            .remove(&(case.clone(), baseline.clone()))
            .unwrap_or_default();
        values.sort_by(f64::total_cmp);
        let (median, spread) = match values.as_slice() {
            [] => ("-".to_owned(), "-".to_owned()),
            all => (
                format!("{:.2}", all[all.len() / 2]),
                format!("{:.2} to {:.2}", all[0], all[all.len() - 1]),
            ),
        };
        say!(out, "{case:<58} {median:>6} {spread:>13}  {target}");
        say!(out, "  vs {baseline}");
    }
    emit(&out);
}
