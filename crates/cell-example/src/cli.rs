//! The flags of `cargo run --example chip_cell`, read into a [`CellConfig`].

use std::ffi::OsString;

use crate::chip::FeederPolicy;
use crate::faults::CellFault;
use crate::run::{CellConfig, MAX_HOURS};

/// The example's usage line.
pub const USAGE: &str = "usage: chip_cell [--hours H] [--seed S] [--feeder arbiter|appendix] [--realtime] [--tree] \
                     [--fault KIND[:WHICH]@TIME]... (KIND: release, robot, feeder, jam)";

/// Reads the example's flags into a [`CellConfig`]; a bad flag or value is an error that
/// says what was wrong, never a panic (also for an argument that is not UTF-8).
pub fn parse(args: impl IntoIterator<Item = OsString>) -> Result<CellConfig, String> {
    let mut config = CellConfig {
        progress: true,
        ..CellConfig::default()
    };
    let mut args = args.into_iter().map(|arg| {
        arg.into_string().map_err(|arg| {
            format!(
                "argument {:?} is not valid UTF-8\n{USAGE}",
                arg.to_string_lossy()
            )
        })
    });
    while let Some(flag) = args.next() {
        let flag = flag?;
        let mut value = |name: &str| {
            args.next()
                .ok_or_else(|| format!("{name} needs a value\n{USAGE}"))?
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
            "--tree" => config.show_tree = true,
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
