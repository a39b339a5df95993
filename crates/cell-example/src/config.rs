//! How a run is made: the configuration the flags are read into, and that every way of
//! running the cell starts from. Apart from the running in one process ([`run`](mod@crate::run)),
//! since the runs across processes it starts read it too.

use std::path::PathBuf;
use std::time::{Duration, SystemTime};

use imrs_core::{Event, Log};
use imrs_sim::Line;

use crate::faults::CellFault;
use crate::feeder_policy::FeederPolicy;

/// How a run is made.
#[derive(Debug, Clone, PartialEq)]
pub struct CellConfig {
    /// Simulated hours.
    pub hours: f64,
    /// Seeds every random choice.
    pub seed: u64,
    /// How the chip robots share the feeders.
    pub feeder: FeederPolicy,
    /// Run on the wall clock instead of virtual time.
    pub realtime: bool,
    /// Faults to inject.
    pub faults: Vec<CellFault>,
    /// Show a progress bar on a terminal.
    pub progress: bool,
    /// Print the module tree (Shin 1985, §2) before the report.
    pub show_tree: bool,
    /// How many of the most recent events each log keeps in memory for the record (the
    /// report is folded from every event as it comes, whatever this is).
    pub kept_events: usize,
    /// Record the run into this MCAP file.
    pub record: Option<PathBuf>,
    /// Draw a timeline of a window of the run.
    pub timeline: Option<TimelineConfig>,
    /// Run across processes: the world in this one, each line in its own (see
    /// [`processes`](crate::processes)).
    pub processes: bool,
    /// Across processes, how many times as fast as the wall clock the cell runs.
    pub speed: f64,
    /// Across processes, what carries the ports between them.
    pub transport: Transport,
    /// Set in a line's process, which the world started.
    pub line_process: Option<LineProcess>,
    /// Be seen from ROS 2, a zenoh peer listening on this endpoint (see [`crate::ros2`]);
    /// on the wall clock.
    pub ros2: Option<String>,
}

/// Where to draw a timeline, and of which window of the run.
#[derive(Debug, Clone, PartialEq)]
pub struct TimelineConfig {
    /// The SVG file.
    pub path: PathBuf,
    /// Where the window starts, from the start of the run.
    pub from: Duration,
    /// How long it is.
    pub span: Duration,
}

impl Default for CellConfig {
    fn default() -> Self {
        Self {
            hours: 1.0,
            seed: 1985,
            feeder: FeederPolicy::Arbiter,
            realtime: false,
            faults: Vec::new(),
            progress: false,
            show_tree: false,
            kept_events: Log::<Event>::DEFAULT_CAPACITY,
            record: None,
            timeline: None,
            processes: false,
            speed: DEFAULT_SPEED,
            transport: Transport::Ipc,
            line_process: None,
            ros2: None,
        }
    }
}

/// The longest run: a year of shifts.
pub const MAX_HOURS: f64 = 8760.0;

/// How much faster than the wall clock a run across processes goes, unless `--speed` says.
pub const DEFAULT_SPEED: f64 = 60.0;

/// What carries the ports between the processes of a run across processes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Transport {
    /// iceoryx2: the processes of one host, through shared memory.
    Ipc,
    /// zenoh: each process a host of its own (a network namespace, where they can be made).
    Zenoh,
}

impl Transport {
    /// Its name, as `--transport` takes it.
    pub fn name(self) -> &'static str {
        match self {
            Transport::Ipc => "ipc",
            Transport::Zenoh => "zenoh",
        }
    }
}

/// What makes a process one line's part of a cell run across processes: the line, the
/// cell's name, where the world's host is (over zenoh), and the moment its time starts.
#[derive(Debug, Clone, PartialEq)]
pub struct LineProcess {
    /// The line whose modules it runs.
    pub line: Line,
    /// Which run of the line's process it is: 0 first, then one more each time the world
    /// starts it again.
    pub run: u32,
    /// The cell's name, from which every port's service name (or key) is derived.
    pub remote: String,
    /// Over zenoh, the world's host's endpoint, which the line's host connects to; over
    /// iceoryx2, `None`.
    pub connect: Option<String>,
    /// When the cell's time is zero, on the system clock.
    pub epoch: SystemTime,
}
