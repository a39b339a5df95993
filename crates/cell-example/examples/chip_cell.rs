//! The chip-insertion cell of Shin (1985), Appendix, on two lines, with a report.
//!
//! ```text
//! cargo run --release --example chip_cell -- [--hours H] [--seed S]
//!     [--feeder arbiter|appendix] [--realtime] [--tree] [--fault KIND[:WHICH]@TIME]...
//!     [--record FILE.mcap] [--timeline FILE.svg [--timeline-from S] [--timeline-span S]]
//!     [--processes [--speed X]]
//! ```
//!
//! `--help` lists every flag. `RUST_LOG=imrs=debug` shows the events and spans the core
//! emits, on stderr.

use std::io::{self, IsTerminal, Write};
use std::process::ExitCode;
use std::time::Instant;

use cell_example::processes::run_line;
use cell_example::{
    CellConfig, Comparison, Report, compare, keeping_up_line, parse, run, speed_line,
};
use tracing_subscriber::EnvFilter;

fn main() -> ExitCode {
    // The speed line counts the whole command's wall time.
    let started = Instant::now();
    // Silent unless RUST_LOG asks: the report is the example's output.
    let filter = EnvFilter::try_from_default_env().unwrap_or_else(|_| EnvFilter::new("error"));
    tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(io::stderr)
        .with_ansi(io::stderr().is_terminal())
        .init();
    let config = match parse(std::env::args_os().skip(1)) {
        // The report is folded from the events as they come: none is kept to be read later.
        Ok(config) => CellConfig {
            kept_events: 0,
            ..config
        },
        Err(refused) if refused.status == 0 => {
            print!("{refused}");
            return ExitCode::SUCCESS;
        }
        Err(refused) => {
            eprint!("{refused}");
            return ExitCode::from(refused.status);
        }
    };
    // A line's process of a run across processes: the world that started it reports.
    if let Some(line) = &config.line_process {
        return match run_line(&config, line) {
            Ok(()) => ExitCode::SUCCESS,
            Err(problem) => {
                eprintln!("{problem}");
                ExitCode::FAILURE
            }
        };
    }
    // The other feeder policies, same seed, hours and faults, run beside the chosen one for
    // the side-by-side table; across processes, the chosen one runs alone.
    let comparison = (!config.processes).then(|| compare(&config));
    let alone;
    let chosen = match &comparison {
        Some(comparison) => comparison
            .run_of(config.feeder)
            .expect("every policy is compared"),
        None => {
            alone = run(&config);
            &alone
        }
    };
    let (report, tree) = match chosen {
        Ok(record) => (
            Report::of(record),
            config.show_tree.then(|| record.tree.to_string()),
        ),
        Err(problems) => {
            eprintln!("{problems}");
            return ExitCode::FAILURE;
        }
    };
    if let Some(path) = &config.record {
        eprintln!(
            "recording written to {}: open it in Foxglove (Open local file), or sum it up with \
             `cargo run --example mcap_summary -- {}`",
            path.display(),
            path.display()
        );
    }
    if let Some(timeline) = &config.timeline {
        eprintln!("timeline drawn in {}", timeline.path.display());
    }
    let mut out = io::stdout().lock();
    let printed = match tree {
        Some(tree) => writeln!(out, "module tree (Shin 1985, §2):\n{tree}"),
        None => Ok(()),
    };
    let printed = printed.and_then(|()| match &comparison {
        Some(comparison) => print_compared(&mut out, &report, comparison, started),
        None => print_alone(&mut out, &report),
    });
    match printed {
        Ok(()) => {}
        // A reader that stopped reading (`| head`) is not a failure of the run.
        Err(error) if error.kind() == io::ErrorKind::BrokenPipe => {}
        Err(error) => {
            eprintln!("cannot write the report: {error}");
            return ExitCode::FAILURE;
        }
    }
    if report.all_held() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

/// Writes the report of a run across processes to `out`, with whether its processes kept up.
fn print_alone(out: &mut impl Write, report: &Report) -> io::Result<()> {
    write!(out, "{report}")?;
    // The other policies do not run across processes: see `cell_example::processes`.
    writeln!(out)?;
    if let Some(kept_up) = keeping_up_line(report) {
        writeln!(out, "{kept_up}")?;
    }
    writeln!(out, "{}", speed_line(report))?;
    out.flush()
}

/// Writes the report, then every feeder policy's beside it, to `out`, and last how fast they
/// all ran since the command `started`.
fn print_compared(
    out: &mut impl Write,
    report: &Report,
    comparison: &Comparison,
    started: Instant,
) -> io::Result<()> {
    write!(out, "{report}")?;
    let mut reports = Vec::new();
    for (policy, ran) in &comparison.runs {
        match ran {
            Ok(_) if *policy == report.policy => reports.push(report.clone()),
            Ok(record) => reports.push(Report::of(record)),
            Err(problems) => {
                eprintln!("the {policy:?} feeder policy could not run: {problems}");
                return out.flush();
            }
        }
    }
    writeln!(out)?;
    writeln!(
        out,
        "feeder policies side by side (same seed, hours and faults):"
    )?;
    write!(out, "{}", Report::side_by_side(&reports))?;
    writeln!(out)?;
    writeln!(out, "{}", comparison.speed_line(started.elapsed()))?;
    out.flush()
}
