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

/// Appends a line to the output, printed whole at the end: a reader that stops early
/// (`| head`) then costs nothing but the rest of the text. Defined before the modules, which
/// write with it.
macro_rules! say {
    ($out:expr) => {
        $out.push('\n')
    };
    ($out:expr, $($arg:tt)*) => {{
        use std::fmt::Write as _;
        let _ = writeln!($out, $($arg)*);
    }};
}

mod rows;
mod run;
mod summary;

use std::path::Path;

use run::one_run;
use summary::summarize;

/// Prints `out`; a closed pipe is no error of the table's.
fn emit(out: &str) {
    use std::io::Write as _;
    let _ = std::io::stdout().lock().write_all(out.as_bytes());
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
