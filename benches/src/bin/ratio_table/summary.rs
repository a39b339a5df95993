//! The runs' rows summarized: each row's median and spread over the saved runs, as a
//! Markdown table, and that table written between its markers in a file.

use std::collections::HashMap;
use std::path::Path;

use super::emit;
use super::run::Measured;

/// The lines that enclose the table in a Markdown file, for `--write`.
const BEGIN: &str = "<!-- ratio-table:begin -->";

const END: &str = "<!-- ratio-table:end -->";

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
pub(super) fn summarize(dir: &Path, write: Option<&Path>) {
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
