//! The flags of `cargo run --example chip_cell`, read into a [`CellConfig`] by clap: `--help`
//! lists every flag with its meaning and default, and a bad value is refused naming its flag.

use std::ffi::OsString;
use std::fmt;
use std::path::PathBuf;
use std::time::{Duration, UNIX_EPOCH};

use clap::Parser;
use imrs_ports::RealClock;
use imrs_sim::Line;

use crate::config::{CellConfig, DEFAULT_SPEED, LineProcess, MAX_HOURS, TimelineConfig, Transport};
use crate::faults::CellFault;
use crate::feeder_policy::FeederPolicy;

/// The chip-insertion cell of Shin (1985), Appendix, on two lines, with a report.
#[derive(Debug, Parser)]
#[command(name = "chip_cell", version, about, long_about = None)]
struct Flags {
    /// Simulated hours to run (above 0, at most a year).
    #[arg(long, value_name = "H", default_value_t = 1.0, value_parser = hours, allow_negative_numbers = true)]
    hours: f64,
    /// Seeds every random choice: the same seed and flags give the same report.
    #[arg(long, value_name = "S", default_value_t = 1985)]
    seed: u64,
    /// How the chip robots share the feeder zone: the Appendix's query/order scheme, an
    /// arbiter module that holds the zone for one robot's round trip, or a coordinator that
    /// reserves the space each trajectory sweeps (Jiménez et al. 1992).
    #[arg(long, value_enum, default_value_t = FeederPolicy::Arbiter)]
    feeder: FeederPolicy,
    /// Run on the wall clock instead of virtual time.
    #[arg(long)]
    realtime: bool,
    /// Print the module tree (Shin 1985, §2) before the report.
    #[arg(long)]
    tree: bool,
    /// Inject a fault: KIND one of release, robot, feeder, jam; WHICH a line A or B, or a
    /// feeder 0 to 3; TIME in seconds, or with s, m or h (e.g. robot:B@15m). Repeatable.
    #[arg(long = "fault", value_name = "KIND[:WHICH]@TIME", value_parser = fault)]
    faults: Vec<CellFault>,
    /// Record the run into an MCAP file that Foxglove opens as a 3D cell with its messages.
    #[arg(long, value_name = "FILE.mcap")]
    record: Option<PathBuf>,
    /// Draw a timeline of a window of the run (sections, waits, zone occupancy, deadlocks)
    /// as an SVG picture.
    #[arg(long, value_name = "FILE.svg")]
    timeline: Option<PathBuf>,
    /// Where the timeline's window starts, in simulated seconds.
    #[arg(long, value_name = "SECONDS", default_value_t = 0.0, value_parser = seconds, allow_negative_numbers = true)]
    timeline_from: f64,
    /// How long the timeline's window is, in simulated seconds.
    #[arg(long, value_name = "SECONDS", default_value_t = 300.0, value_parser = seconds, allow_negative_numbers = true)]
    timeline_span: f64,
    /// Be seen from ROS 2 (rmw_zenoh) as node /chip_cell: the robots' joints on
    /// /joint_states, the alarms on /alarms, and the status service /status
    /// (std_srvs/Trigger). A zenoh peer listening on ENDPOINT, where ROS 2 nodes connect
    /// (rmw_zenoh's default router is tcp/localhost:7447). Runs on the wall clock. Needs
    /// the chip cell built with its `ros2` feature.
    #[arg(long, value_name = "ENDPOINT", conflicts_with = "processes")]
    ros2: Option<String>,
    /// Show no progress bar (it is shown only on a terminal anyway).
    #[arg(long)]
    no_progress: bool,
    /// Run across three processes: the world (simulation, devices, feeder zone's keeper) in this
    /// one, each line's modules in its own, talking over iceoryx2; on the wall clock sped
    /// up by --speed.
    #[arg(long)]
    processes: bool,
    /// With --processes: what carries the ports between the processes: iceoryx2 on this
    /// host, or zenoh with each process a host of its own (a network namespace, as root;
    /// needs the chip cell built with its `zenoh` feature).
    #[arg(long, value_enum, default_value_t = Transport::Ipc, requires = "processes")]
    transport: Transport,
    /// With --processes: how many times as fast as the wall clock the cell runs.
    #[arg(long, value_name = "X", default_value_t = DEFAULT_SPEED, value_parser = speed, requires = "processes")]
    speed: f64,
    /// Set by the world on a line's process it starts: the line.
    #[arg(long, hide = true, value_parser = line, requires_all = ["processes", "remote", "epoch"])]
    line_process: Option<Line>,
    /// Set by the world on a line's process: the cell's name on this host.
    #[arg(long, hide = true, requires = "line_process")]
    remote: Option<String>,
    /// Set by the world on a line's process: when the cell's time is zero, in nanoseconds
    /// since 1970.
    #[arg(long, hide = true, requires = "line_process")]
    epoch: Option<u64>,
    /// Set by the world on a line's process over zenoh: the world's host's endpoint.
    #[arg(long, hide = true, requires = "line_process")]
    connect: Option<String>,
    /// Set by the world on a line's process: which run of the line's process it is (the
    /// world restarts a line whose process died).
    #[arg(long, hide = true, default_value_t = 0, requires = "line_process")]
    run: u32,
}

/// Why a flag is refused by a build without the cargo feature `feature` that brings its
/// layer in, and how to turn it on.
pub(crate) fn not_built(flag: &str, feature: &str) -> String {
    format!(
        "{flag} needs the chip cell built with its `{feature}` feature: \
         cargo run --release --features cell-example/{feature} --example chip_cell -- ..."
    )
}

/// Refuses a flag that was `used` where its feature is not `built`, by name.
fn built_for(used: bool, flag: &str, feature: &str, built: bool) -> Result<(), CliError> {
    if used && !built {
        return Err(CliError {
            message: format!("error: {}\n", not_built(flag, feature)),
            status: 2,
        });
    }
    Ok(())
}

fn speed(text: &str) -> Result<f64, String> {
    text.parse::<f64>()
        .ok()
        .filter(|speed| speed.is_finite() && (1.0..=RealClock::MAX_SPEED).contains(speed))
        .ok_or_else(|| format!("expected a speed-up from 1 to {}", RealClock::MAX_SPEED))
}

fn line(text: &str) -> Result<Line, String> {
    match text {
        "A" => Ok(Line::A),
        "B" => Ok(Line::B),
        _ => Err("expected A or B".into()),
    }
}

fn hours(text: &str) -> Result<f64, String> {
    text.parse::<f64>()
        .ok()
        .filter(|hours| hours.is_finite() && *hours > 0.0 && *hours <= MAX_HOURS)
        .ok_or_else(|| format!("expected a number of hours above 0, at most {MAX_HOURS}"))
}

fn seconds(text: &str) -> Result<f64, String> {
    text.parse::<f64>()
        .ok()
        .filter(|seconds| seconds.is_finite() && (0.0..=MAX_HOURS * 3600.0).contains(seconds))
        .ok_or_else(|| "expected a number of seconds, 0 or more, within a year".into())
}

fn fault(text: &str) -> Result<CellFault, String> {
    text.parse::<CellFault>().map_err(|error| error.reason())
}

/// Why the flags gave no configuration: a mistake (status 2), or `--help` and `--version`,
/// whose text is the answer (status 0).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CliError {
    /// What to print.
    pub message: String,
    /// The exit status: 0 for help and version, 2 for a mistake.
    pub status: u8,
}

impl fmt::Display for CliError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for CliError {}

/// Reads the example's flags (without the program's name) into a [`CellConfig`]; a bad flag
/// or value is an error that names it, never a panic (also for an argument that is not
/// UTF-8).
pub fn parse(args: impl IntoIterator<Item = OsString>) -> Result<CellConfig, CliError> {
    let mut checked = vec![String::from("chip_cell")];
    for arg in args {
        // Named here: clap would only say that some argument was not UTF-8.
        let arg = arg.into_string().map_err(|arg| CliError {
            message: format!(
                "error: argument {:?} is not valid UTF-8",
                arg.to_string_lossy()
            ),
            status: 2,
        })?;
        checked.push(arg);
    }
    let flags = Flags::try_parse_from(checked).map_err(|error| CliError {
        message: error.render().to_string(),
        status: if error.use_stderr() { 2 } else { 0 },
    })?;
    built_for(
        flags.ros2.is_some(),
        "--ros2",
        "ros2",
        cfg!(feature = "ros2"),
    )?;
    let zenoh = flags.transport == Transport::Zenoh || flags.connect.is_some();
    built_for(zenoh, "--transport zenoh", "zenoh", cfg!(feature = "zenoh"))?;
    let timeline = flags.timeline.map(|path| TimelineConfig {
        path,
        from: Duration::from_secs_f64(flags.timeline_from),
        span: Duration::from_secs_f64(flags.timeline_span),
    });
    let line_process = match (flags.line_process, flags.remote, flags.epoch) {
        (Some(line), Some(remote), Some(epoch)) => Some(LineProcess {
            line,
            run: flags.run,
            remote,
            connect: flags.connect,
            epoch: UNIX_EPOCH + Duration::from_nanos(epoch),
        }),
        _ => None,
    };
    Ok(CellConfig {
        hours: flags.hours,
        seed: flags.seed,
        feeder: flags.feeder,
        realtime: flags.realtime,
        faults: flags.faults,
        progress: !flags.no_progress,
        show_tree: flags.tree,
        record: flags.record,
        timeline,
        processes: flags.processes,
        speed: flags.speed,
        transport: flags.transport,
        line_process,
        ros2: flags.ros2,
        ..CellConfig::default()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flag_whose_feature_is_not_built_is_refused_by_name_with_how_to_build_it() {
        let refused = built_for(true, "--ros2", "ros2", false).unwrap_err();
        assert_eq!(refused.status, 2);
        assert!(
            refused
                .message
                .contains("--ros2 needs the chip cell built with its `ros2` feature"),
            "{}",
            refused.message
        );
        assert!(refused.message.contains("--features cell-example/ros2"));
        assert!(built_for(true, "--ros2", "ros2", true).is_ok());
        assert!(built_for(false, "--ros2", "ros2", false).is_ok());
    }
}
