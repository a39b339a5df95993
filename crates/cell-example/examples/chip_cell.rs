//! The chip-insertion cell of Shin (1985), Appendix, on two lines, with a report.
//!
//! ```text
//! cargo run --release --example chip_cell -- [--hours H] [--seed S]
//!     [--feeder arbiter|appendix] [--realtime] [--tree] [--fault KIND[:WHICH]@TIME]...
//! ```

use std::process::ExitCode;

use std::io::{self, Write};

use cell_example::{CellConfig, FeederPolicy, Report, parse, run, speed_line};

fn main() -> ExitCode {
    let config = match parse(std::env::args_os().skip(1)) {
        Ok(config) => config,
        Err(message) => {
            eprintln!("{message}");
            return ExitCode::from(2);
        }
    };
    let (report, tree) = match run(&config) {
        Ok(record) => (
            Report::of(&record),
            config.show_tree.then(|| record.tree.to_string()),
        ),
        Err(problems) => {
            eprintln!("{problems}");
            return ExitCode::FAILURE;
        }
    };
    let mut out = io::stdout().lock();
    let printed = match tree {
        Some(tree) => writeln!(out, "module tree (seed 000 §2):\n{tree}"),
        None => Ok(()),
    };
    match printed.and_then(|()| print_all(&mut out, &config, &report)) {
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

/// Writes the report, then the other feeder policy's beside it, to `out`.
fn print_all(out: &mut impl Write, config: &CellConfig, report: &Report) -> io::Result<()> {
    write!(out, "{report}")?;
    // The other feeder policy, same seed, hours and faults, for the side-by-side table.
    let other = CellConfig {
        feeder: match config.feeder {
            FeederPolicy::Arbiter => FeederPolicy::Appendix,
            FeederPolicy::Appendix => FeederPolicy::Arbiter,
        },
        progress: false,
        ..config.clone()
    };
    match run(&other) {
        Ok(record) => {
            let other = Report::of(&record);
            let (appendix, arbiter) = match config.feeder {
                FeederPolicy::Appendix => (report, &other),
                FeederPolicy::Arbiter => (&other, report),
            };
            writeln!(out)?;
            writeln!(
                out,
                "feeder policies side by side (same seed, hours and faults):"
            )?;
            write!(out, "{}", Report::side_by_side(appendix, arbiter))?;
        }
        Err(problems) => eprintln!("the other feeder policy could not run: {problems}"),
    }
    writeln!(out)?;
    writeln!(out, "{}", speed_line(report))?;
    out.flush()
}
