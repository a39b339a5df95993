//! The chip-insertion cell of Shin (1985), Appendix, on two lines, with a report.
//!
//! ```text
//! cargo run --release --example chip_cell -- [--hours H] [--seed S]
//!     [--feeder arbiter|appendix] [--realtime] [--fault KIND[:WHICH]@TIME]...
//! ```

use std::process::ExitCode;

use cell_example::{CellConfig, CellFault, FeederPolicy, MAX_HOURS, Report, run, speed_line};

const USAGE: &str = "usage: chip_cell [--hours H] [--seed S] [--feeder arbiter|appendix] [--realtime] \
                     [--fault KIND[:WHICH]@TIME]... (KIND: release, robot, feeder, jam)";

fn parse(args: impl Iterator<Item = String>) -> Result<CellConfig, String> {
    let mut config = CellConfig {
        progress: true,
        ..CellConfig::default()
    };
    let mut args = args.peekable();
    while let Some(flag) = args.next() {
        let mut value = |name: &str| {
            args.next()
                .ok_or_else(|| format!("{name} needs a value\n{USAGE}"))
        };
        match flag.as_str() {
            "--hours" => {
                let text = value("--hours")?;
                config.hours = text
                    .parse::<f64>()
                    .ok()
                    .filter(|hours| hours.is_finite() && *hours > 0.0 && *hours <= MAX_HOURS)
                    .ok_or_else(|| {
                        format!("--hours {text:?}: expected a number of hours above 0, at most {MAX_HOURS}")
                    })?;
            }
            "--seed" => {
                let text = value("--seed")?;
                config.seed = text
                    .parse()
                    .map_err(|_| format!("--seed {text:?}: expected a whole number"))?;
            }
            "--feeder" => {
                config.feeder = match value("--feeder")?.as_str() {
                    "arbiter" => FeederPolicy::Arbiter,
                    "appendix" => FeederPolicy::Appendix,
                    other => {
                        return Err(format!("--feeder {other:?}: expected arbiter or appendix"));
                    }
                }
            }
            "--realtime" => config.realtime = true,
            "--fault" => config.faults.push(
                value("--fault")?
                    .parse::<CellFault>()
                    .map_err(|e| e.to_string())?,
            ),
            "--help" | "-h" => return Err(USAGE.into()),
            other => return Err(format!("unknown argument {other:?}\n{USAGE}")),
        }
    }
    Ok(config)
}

fn main() -> ExitCode {
    let config = match parse(std::env::args().skip(1)) {
        Ok(config) => config,
        Err(message) => {
            eprintln!("{message}");
            return ExitCode::from(2);
        }
    };
    let report = match run(&config) {
        Ok(record) => Report::of(&record),
        Err(problems) => {
            eprintln!("{problems}");
            return ExitCode::FAILURE;
        }
    };
    print!("{report}");
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
                FeederPolicy::Appendix => (&report, &other),
                FeederPolicy::Arbiter => (&other, &report),
            };
            println!();
            println!("feeder policies side by side (same seed, hours and faults):");
            print!("{}", Report::side_by_side(appendix, arbiter));
        }
        Err(problems) => eprintln!("the other feeder policy could not run: {problems}"),
    }
    println!();
    println!("{}", speed_line(&report));
    if report.all_held() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
