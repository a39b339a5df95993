//! The ratio table, made from saved measurements rather than typed.
//!
//! After `cargo bench` (and `idle_modules`), with no arguments: reads criterion's estimates
//! of this run, prints each row (case, baseline, both medians, the ratio, the target), the
//! tail latencies and the simulation speed, and saves the rows to `<criterion>/ratios.tsv`.
//!
//! ```text
//! cargo run --release -p imrs-benches --bin ratio_table
//! cargo run --release -p imrs-benches --bin ratio_table -- --runs DIR [--write FILE]
//! ```
//!
//! With `--runs DIR`: reads every run's saved rows (`DIR/*.tsv`) and prints a Markdown table:
//! each row's median over the runs, its spread (lowest to highest), and the figures of the
//! run whose ratio is the median. With `--write FILE` as well, it puts that table in FILE in
//! place of what stands between the lines `<!-- ratio-table:begin -->` and
//! `<!-- ratio-table:end -->`. `benches/runs.sh N [--write]` runs the benches N times and
//! ends with this.

use std::collections::HashMap;
use std::path::Path;

use imrs_benches::criterion_dir;

/// The lines that enclose the table in a Markdown file, for `--write`.
const BEGIN: &str = "<!-- ratio-table:begin -->";
const END: &str = "<!-- ratio-table:end -->";

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

/// A time in nanoseconds, in the unit that suits it.
fn show(nanos: f64) -> String {
    if nanos >= 1e6 {
        format!("{:.2} ms", nanos / 1e6)
    } else if nanos >= 1e3 {
        format!("{:.2} µs", nanos / 1e3)
    } else {
        format!("{nanos:.0} ns")
    }
}

/// A measured case: criterion's id, what the table calls it, and what one iteration's time is
/// divided by before it is compared (the tasks of a waitfor round, for a time per task).
#[derive(Clone)]
struct Case {
    id: String,
    name: &'static str,
    per: f64,
}

/// A case timed per iteration as it is.
fn case(id: impl Into<String>, name: &'static str) -> Case {
    Case {
        id: id.into(),
        name,
        per: 1.0,
    }
}

/// What a row compares its case with.
enum Baseline {
    One(Case),
    /// The faster of two, in each run: the nearest equivalents that differ in placement.
    Faster(Case, Case),
    /// The slower of the same two, reported beside the faster.
    Slower(Case, Case),
}

/// What a row measures.
enum Measure {
    /// The case's time over the baseline's.
    Ratio(Case, Baseline),
    /// p99.9 of single round trips (the tail files of `benches/rendezvous.rs`), over the
    /// baseline's p99.9.
    TailRatio(&'static str, &'static str),
    /// Resident KiB per idle module from `idle_modules`, beside a tokio task's.
    IdleKib,
}

/// A row of the table, as defined.
struct Def {
    key: String,
    case: String,
    baseline: String,
    target: &'static str,
    measure: Measure,
    /// What the figures are per: " a hop", " a task"; empty for a round trip.
    unit: &'static str,
}

/// A row of one run, as saved in `ratios.tsv`: the value is a ratio, or KiB for the idle row.
#[derive(Clone)]
struct Measured {
    key: String,
    case: String,
    baseline: String,
    target: String,
    value: Option<f64>,
    kib: bool,
    figures: String,
}

impl Measured {
    fn to_line(&self) -> String {
        let value = self.value.map_or("-".into(), |v| format!("{v:.4}"));
        let unit = if self.kib { "KiB" } else { "ratio" };
        [
            self.key.as_str(),
            &self.case,
            &self.baseline,
            self.target.as_str(),
            &value,
            unit,
            &self.figures,
        ]
        .join("\t")
    }

    fn from_line(line: &str) -> Option<Self> {
        let fields: Vec<&str> = line.split('\t').collect();
        let [key, case, baseline, target, value, unit, figures] = fields[..] else {
            return None;
        };
        Some(Self {
            key: key.into(),
            case: case.into(),
            baseline: baseline.into(),
            target: target.into(),
            value: value.parse().ok(),
            kib: unit == "KiB",
            figures: figures.into(),
        })
    }

    fn show_value(&self, value: f64) -> String {
        if self.kib {
            format!("{value:.2} KiB")
        } else {
            format!("{value:.2}")
        }
    }
}

/// Every row of the table, in its order.
fn rows() -> Vec<Def> {
    let mut rows = Vec::new();
    let mut row = |key: String,
                   case: &str,
                   baseline: &str,
                   target: &'static str,
                   measure: Measure,
                   unit: &'static str| {
        rows.push(Def {
            key,
            case: case.into(),
            baseline: baseline.into(),
            target,
            measure,
            unit,
        })
    };
    let one = |id: &str, name| Baseline::One(case(id, name));

    row(
        "ctx/one_processor".into(),
        "`ctx` round trip, both modules on one processor",
        "raw `End` round trip, both ends on one processor",
        "≤ 1.3",
        Measure::Ratio(
            case("ctx_same_thread/ctx", "ctx"),
            one("ctx_same_thread/raw_end", "raw End"),
        ),
        "",
    );
    row(
        "ctx/two_workers".into(),
        "`ctx` round trip, each module a task of a two-worker runtime",
        "raw `End` round trip, placed the same",
        "≤ 1.3",
        Measure::Ratio(
            case("ctx_multi_thread/ctx", "ctx"),
            one("ctx_multi_thread/raw_end", "raw End"),
        ),
        "",
    );

    let imrs_ring_1 = || case("ring_1000/imrs/1_threads", "imrs");
    row(
        "ring/tokio/1".into(),
        "ring of 1,000 modules, 1 thread, time per hop",
        "1,000 tokio tasks + mpsc + oneshot, 1 thread",
        "≤ 1.2",
        Measure::Ratio(imrs_ring_1(), one("ring_1000/tokio/1_threads", "tokio")),
        " a hop",
    );
    row(
        "ring/kameo/1".into(),
        "ring of 1,000 modules, 1 thread",
        "1,000 kameo actors, each hop an `ask`, 1 thread",
        "< 1",
        Measure::Ratio(imrs_ring_1(), one("ring_1000/kameo/1_threads", "kameo")),
        " a hop",
    );
    row(
        "ring/ractor/1".into(),
        "ring of 1,000 modules, 1 thread",
        "1,000 ractor actors, each hop a `call!`, 1 thread",
        "< 1",
        Measure::Ratio(imrs_ring_1(), one("ring_1000/ractor/1_threads", "ractor")),
        " a hop",
    );
    let cores = std::thread::available_parallelism().map_or(2, usize::from);
    let mut threads = vec![2, cores];
    threads.dedup();
    for n in threads.into_iter().filter(|&n| n > 1) {
        let id = |who: &str| format!("ring_1000/{who}/{n}_threads");
        row(
            format!("ring/tokio/{n}"),
            &format!("ring of 1,000 modules, {n} threads"),
            &format!("1,000 tokio tasks + mpsc + oneshot, {n} threads"),
            "–",
            Measure::Ratio(case(id("imrs"), "imrs"), one(&id("tokio"), "tokio")),
            " a hop",
        );
    }

    for (size, bytes, main) in [("8B", "8 B", true), ("1KiB", "1 KiB", false)] {
        let same = |who: &str| format!("rendezvous_same_thread/{who}/{size}");
        let target = |t: &'static str| if main { t } else { "–" };
        let two_tasks = case(same("imrs_two_tasks"), "imrs");
        row(
            format!("same_thread/two_tasks/tokio/{size}"),
            &format!("same-thread {bytes}, each end a task (current-thread runtime)"),
            "tokio mpsc + oneshot ask, each end a task, same runtime",
            target("≤ 0.7"),
            Measure::Ratio(two_tasks.clone(), one(&same("tokio_two_tasks"), "tokio")),
            "",
        );
        let processor = case(same("imrs_one_processor"), "imrs");
        let (join, local) = (
            case(same("tokio_join_one_task"), "tokio `join!` in one task"),
            case(
                same("tokio_local_set"),
                "tokio, two tasks of one `LocalSet`",
            ),
        );
        row(
            format!("same_thread/one_processor/nearest/{size}"),
            &format!("same-thread {bytes}, both ends jobs of one processor"),
            "the faster of its nearest tokio equivalents",
            target("≤ 0.5"),
            Measure::Ratio(
                processor.clone(),
                Baseline::Faster(join.clone(), local.clone()),
            ),
            "",
        );
        if main {
            row(
                format!("same_thread/one_processor/other/{size}"),
                &format!("same-thread {bytes}, both ends jobs of one processor"),
                "the slower of them",
                "–",
                Measure::Ratio(processor, Baseline::Slower(join, local)),
                "",
            );
        }
        row(
            format!("same_thread/two_tasks/kameo/{size}"),
            &format!("same-thread {bytes}, each end a task"),
            "kameo `ask`, actor and asker placed the same",
            target("< 1"),
            Measure::Ratio(two_tasks.clone(), one(&same("kameo_ask"), "kameo")),
            "",
        );
        row(
            format!("same_thread/two_tasks/ractor/{size}"),
            &format!("same-thread {bytes}, each end a task"),
            "ractor `call!`, actor and caller placed the same",
            target("< 1"),
            Measure::Ratio(two_tasks, one(&same("ractor_call"), "ractor")),
            "",
        );
        if main {
            row(
                format!("same_thread/prioritized/{size}"),
                &format!("same-thread {bytes} on one processor, priorities on"),
                "priorities off",
                "≤ 1.1",
                Measure::Ratio(
                    case(same("imrs_one_processor_prioritized"), "on"),
                    one(&same("imrs_one_processor"), "off"),
                ),
                "",
            );
        }
    }

    row(
        "idle".into(),
        "idle module, 10,000 modules waiting in `ctx.receive`: KiB resident each",
        "a tokio task waiting on an mpsc receiver",
        "≤ 2 KiB",
        Measure::IdleKib,
        "",
    );
    row(
        "filter/processor".into(),
        "bounded-buffer filter, a job on one processor with its peers",
        "tokio bounded mpsc, one task",
        "≤ 3",
        Measure::Ratio(
            case("filter/bounded_buffer_on_processor", "filter"),
            one("filter/tokio_mpsc", "mpsc"),
        ),
        "",
    );
    row(
        "filter/task".into(),
        "bounded-buffer filter, a task of its own",
        "tokio bounded mpsc, one task",
        "–",
        Measure::Ratio(
            case("filter/bounded_buffer", "filter"),
            one("filter/tokio_mpsc", "mpsc"),
        ),
        "",
    );
    let per_task = |id: &str, n: f64| Case {
        id: id.into(),
        name: "",
        per: n,
    };
    for (n, id, tokio_id) in [
        (64.0, "waitfor/64", "waitfor/tokio_barrier/64"),
        (256.0, "waitfor/256", "waitfor/tokio_barrier/256"),
    ] {
        row(
            format!("waitfor/{n}"),
            &format!("waitfor, per task, n = {n}"),
            "waitfor, per task, n = 2",
            "≤ 1.05",
            Measure::Ratio(per_task(id, n), Baseline::One(per_task("waitfor/2", 2.0))),
            " a task",
        );
        row(
            format!("waitfor/tokio/{n}"),
            &format!("tokio `Barrier`, per task, n = {n}"),
            "tokio `Barrier`, per task, n = 2",
            "–",
            Measure::Ratio(
                per_task(tokio_id, n),
                Baseline::One(per_task("waitfor/tokio_barrier/2", 2.0)),
            ),
            " a task",
        );
    }
    row(
        "query/idle".into(),
        "query into a response handler, responder idle",
        "rendezvous, both ends on one processor",
        "≤ 1.5",
        Measure::Ratio(
            case("query/responder_idle", "query"),
            one("query/same_thread_rendezvous", "rendezvous"),
        ),
        "",
    );
    row(
        "query/busy".into(),
        "query, responder in a lower-ranked section",
        "rendezvous, both ends on one processor",
        "–",
        Measure::Ratio(
            case("query/responder_in_lower_section", "query"),
            one("query/same_thread_rendezvous", "rendezvous"),
        ),
        "",
    );
    row(
        "select".into(),
        "`select` over 8 ports, all ready",
        "one ready",
        "–",
        Measure::Ratio(
            case("select/8_ports_all_ready", "all"),
            one("select/8_ports_one_ready", "one"),
        ),
        "",
    );

    for (size, bytes, main) in [("8B", "8 B", true), ("1KiB", "1 KiB", false)] {
        let cold = |who: &str| format!("rendezvous_cross_thread_cold/{who}/{size}");
        let placed = "placed the same (a current-thread runtime on each thread)";
        let imrs = case(cold("imrs"), "imrs");
        row(
            format!("cold/tokio/{size}"),
            &format!("cross-thread cold {bytes} (server on a thread of its own)"),
            &format!("tokio mpsc + oneshot ask, {placed}"),
            if main { "≤ 0.8" } else { "–" },
            Measure::Ratio(imrs.clone(), one(&cold("tokio_ask"), "tokio")),
            "",
        );
        if main {
            row(
                format!("cold/tokio/p999/{size}"),
                &format!("cross-thread cold {bytes}, p99.9"),
                "tokio ask's p99.9",
                "≤ 1",
                Measure::TailRatio(
                    "rendezvous_cross_thread_cold_imrs_8B",
                    "rendezvous_cross_thread_cold_tokio_ask_8B",
                ),
                "",
            );
            row(
                format!("cold/kameo/{size}"),
                &format!("cross-thread cold {bytes}"),
                &format!("kameo `ask`, {placed}"),
                "–",
                Measure::Ratio(imrs.clone(), one(&cold("kameo_ask"), "kameo")),
                "",
            );
            row(
                format!("cold/ractor/{size}"),
                &format!("cross-thread cold {bytes}"),
                &format!("ractor `call!`, {placed}"),
                "–",
                Measure::Ratio(imrs, one(&cold("ractor_call"), "ractor")),
                "",
            );
            row(
                format!("cold/crossbeam/{size}"),
                &format!("crossbeam ping-pong {bytes}, two threads"),
                "tokio mpsc + oneshot ask across threads",
                "–",
                Measure::Ratio(
                    case(cold("crossbeam_ping_pong"), "crossbeam"),
                    one(&cold("tokio_ask"), "tokio"),
                ),
                "",
            );
        }
    }
    for (size, bytes, target) in [("8B", "8 B", "≤ 1.2"), ("1KiB", "1 KiB", "≤ 2")] {
        let tight = |who: &str| format!("rendezvous_tight/{who}/{size}");
        row(
            format!("tight/payload/{size}"),
            &format!("TIGHT {bytes}"),
            &format!("two threads spinning on a cache line that carries the {bytes}"),
            target,
            Measure::Ratio(
                case(tight("imrs"), "imrs"),
                one(&tight("atomic_spin_ping_pong_payload"), "spin"),
            ),
            "",
        );
    }
    row(
        "tight/plain/8B".into(),
        "TIGHT 8 B",
        "two threads spinning on one atomic, no message",
        "–",
        Measure::Ratio(
            case("rendezvous_tight/imrs/8B", "imrs"),
            one("rendezvous_tight/atomic_spin_ping_pong/8B", "spin"),
        ),
        "",
    );
    rows
}

/// One row of this run, measured from what `root` holds.
fn measure(root: &Path, def: &Def) -> Measured {
    let mut measured = Measured {
        key: def.key.clone(),
        case: def.case.clone(),
        baseline: def.baseline.clone(),
        target: def.target.into(),
        value: None,
        kib: false,
        figures: "-".into(),
    };
    let timed = |case: &Case| median(root, &case.id).map(|nanos| nanos / case.per);
    match &def.measure {
        Measure::Ratio(case, baseline) => {
            let base = match baseline {
                Baseline::One(base) => timed(base).map(|nanos| (base, nanos)),
                Baseline::Faster(a, b) | Baseline::Slower(a, b) => match (timed(a), timed(b)) {
                    (Some(x), Some(y)) => {
                        let faster = x <= y;
                        let pick_a = faster == matches!(baseline, Baseline::Faster(..));
                        Some(if pick_a { (a, x) } else { (b, y) })
                    }
                    _ => None,
                },
            };
            if matches!(baseline, Baseline::Faster(..) | Baseline::Slower(..))
                && let Some((base, _)) = base
            {
                measured.baseline = format!("{}: {}", def.baseline, base.name);
            }
            if let (Some(a), Some((_, b))) = (timed(case), base)
                && b > 0.0
            {
                measured.value = Some(a / b);
                measured.figures = format!("{}{} vs {}", show(a), def.unit, show(b));
            }
        }
        Measure::TailRatio(case, baseline) => {
            let p999 = |name: &str| -> Option<f64> {
                let text =
                    std::fs::read_to_string(root.join("tail").join(format!("{name}.txt"))).ok()?;
                text.split_whitespace().nth(2)?.parse().ok()
            };
            if let (Some(a), Some(b)) = (p999(case), p999(baseline))
                && b > 0.0
            {
                measured.value = Some(a / b);
                measured.figures = format!("{} vs {}", show(a), show(b));
            }
        }
        Measure::IdleKib => {
            measured.kib = true;
            let figure = |who: &str| -> Option<(f64, String)> {
                let text =
                    std::fs::read_to_string(root.join("idle").join(format!("{who}.txt"))).ok()?;
                let mut fields = text.split_whitespace();
                let kib = fields.next()?.parse().ok()?;
                let (count, millis) = (fields.next()?, fields.next()?);
                Some((kib, format!("{count} started in {millis} ms")))
            };
            if let Some((kib, started)) = figure("imrs") {
                measured.value = Some(kib);
                measured.figures = format!("{kib:.2} KiB ({started})");
                if let Some((tokio, _)) = figure("tokio") {
                    measured.figures.push_str(&format!(" vs {tokio:.2} KiB"));
                }
            }
        }
    }
    measured
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.iter().map(String::as_str).collect::<Vec<_>>()[..] {
        [] => one_run(),
        ["--runs", dir] => summarize(Path::new(dir), None),
        ["--runs", dir, "--write", file] => summarize(Path::new(dir), Some(Path::new(file))),
        _ => {
            eprintln!("usage: ratio_table [--runs DIR [--write FILE]]");
            std::process::exit(2);
        }
    }
}

/// This run's table, from criterion's estimates; saves its rows to `<criterion>/ratios.tsv`.
fn one_run() {
    let mut out = String::new();
    let root = criterion_dir();
    if !root.exists() {
        eprintln!(
            "no estimates under {}: run `cargo bench` first",
            root.display()
        );
        std::process::exit(1);
    }
    let mut saved = String::new();
    say!(
        out,
        "{:<72} {:>8}  target",
        "case (baseline below)",
        "ratio"
    );
    for def in rows() {
        let row = measure(&root, &def);
        saved.push_str(&row.to_line());
        saved.push('\n');
        let value = row.value.map_or("-".into(), |v| row.show_value(v));
        say!(out, "{:<72} {value:>8}  {}", row.case, row.target);
        say!(out, "  vs {}: {}", row.baseline, row.figures);
    }
    if let Err(error) = std::fs::write(root.join("ratios.tsv"), saved) {
        eprintln!("cannot save this run's ratios: {error}");
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
        if let [Some(p50), Some(p99), Some(p999)] = values[..] {
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

/// The machine the runs were made on, in words, for the line above the table.
fn machine() -> String {
    let cpus = std::thread::available_parallelism().map_or(0, usize::from);
    let model = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|info| {
            info.lines()
                .find(|line| line.starts_with("model name"))
                .and_then(|line| line.split_once(':'))
                .map(|(_, model)| model.split_whitespace().collect::<Vec<_>>().join(" "))
        });
    match model {
        Some(model) => format!("{cpus} logical CPUs ({model})"),
        None => format!("{cpus} logical CPUs"),
    }
}

/// Each row's median and spread over the runs saved in `dir` (one `.tsv` a run), as a
/// Markdown table; with `write`, also put in that file between the markers.
fn summarize(dir: &Path, write: Option<&Path>) {
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
    // Rows in the order of the first run that has them; every run's row, by key.
    let mut order: Vec<String> = Vec::new();
    let mut runs: HashMap<String, Vec<Measured>> = HashMap::new();
    for file in &files {
        for line in std::fs::read_to_string(file).unwrap_or_default().lines() {
            let Some(row) = Measured::from_line(line) else {
                continue;
            };
            if !runs.contains_key(&row.key) {
                order.push(row.key.clone());
            }
            runs.entry(row.key.clone()).or_default().push(row);
        }
    }
    let count = files.len();
    let mut table = String::new();
    say!(
        table,
        "{count} run{} of `benches/runs.sh` on {}: each row's median over the runs, its \
         spread (lowest–highest), and the figures of the run whose value is the median. \
         Made by `ratio_table --runs`; do not edit by hand.",
        if count == 1 { "" } else { "s" },
        machine()
    );
    say!(table);
    say!(
        table,
        "| case | baseline | target | median | spread | median run |"
    );
    say!(table, "|---|---|---|---|---|---|");
    for key in order {
        let rows = runs.remove(&key).unwrap_or_default();
        let Some(first) = rows.first() else {
            continue;
        };
        let mut measured: Vec<(f64, &Measured)> = rows
            .iter()
            .filter_map(|row| row.value.map(|value| (value, row)))
            .collect();
        measured.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (value, spread, baseline, figures) = match measured.as_slice() {
            [] => ("-".into(), "-".into(), first.baseline.clone(), "-".into()),
            all => {
                let (value, middle) = all[all.len() / 2];
                let (low, high) = (all[0].0, all[all.len() - 1].0);
                let mut baseline = middle.baseline.clone();
                // A row whose baseline is the faster of two names the one of the median run,
                // and how often it was the one.
                let same = all
                    .iter()
                    .filter(|(_, row)| row.baseline == baseline)
                    .count();
                if same < all.len() {
                    baseline.push_str(&format!(" (in {same} of {} runs)", all.len()));
                }
                let spread = if middle.kib {
                    format!("{low:.2}–{high:.2} KiB")
                } else {
                    format!("{low:.2}–{high:.2}")
                };
                (
                    middle.show_value(value),
                    spread,
                    baseline,
                    middle.figures.clone(),
                )
            }
        };
        say!(
            table,
            "| {} | {baseline} | {} | {value} | {spread} | {figures} |",
            first.case,
            first.target
        );
    }
    emit(&table);
    if let Some(file) = write {
        if let Err(error) = write_between_markers(file, &table) {
            eprintln!("cannot write the table into {}: {error}", file.display());
            std::process::exit(1);
        }
        eprintln!("table written into {}", file.display());
    }
}

/// Replaces what stands between the [`BEGIN`] and [`END`] lines of `file` with `table`.
fn write_between_markers(file: &Path, table: &str) -> Result<(), String> {
    let text = std::fs::read_to_string(file).map_err(|error| error.to_string())?;
    let begin = text
        .find(BEGIN)
        .ok_or_else(|| format!("no `{BEGIN}` line"))?;
    let after_begin = begin + BEGIN.len();
    let end = text[after_begin..]
        .find(END)
        .map(|at| after_begin + at)
        .ok_or_else(|| format!("no `{END}` line after `{BEGIN}`"))?;
    // Blank lines around the table, so that no Markdown reader takes a marker into it.
    let written = format!("{}\n\n{table}\n{}", &text[..after_begin], &text[end..]);
    std::fs::write(file, written).map_err(|error| error.to_string())
}
