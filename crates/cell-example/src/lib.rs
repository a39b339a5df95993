//! The three-workcell chip-insertion line of Shin (1985), Appendix, running on IMRS modules
//! and the simulated cell: `cargo run --release --example chip_cell`.
//!
//! Put the Appendix beside this crate: GATE with its tasks BOUNDED_BUFFER and RELEASE and its
//! ports FREQUENCY and LET_1_GO is [`gate`]; LOAD_IT, LOAD_CARD and SCREW_IN_CARD are in
//! [`load`]; CHIP_IT (and its twin CHIP_IT2 on the second line) with its order, its work
//! schedule and the SHARE_FEEDER ports are in [`chip`]; the port declarations, with the
//! Appendix's restrictions, in [`ports`]. Where the Appendix writes `{signal for help}`, the
//! modules raise an alarm and retry or restart, as the paper suggests.
//!
//! Three policies share the feeders: the Appendix's query/order scheme, which deadlocks as
//! the paper's note 6 predicts and breaks the deadlock with asymmetric timeout handlers, an
//! arbiter (the monitor task the paper's conclusion points to), and a coordinator that
//! reserves the space each trajectory sweeps. [`compare()`] runs the cell under all three at
//! once, and the [`report`] sets them side by side, with what rapier measured.

pub mod alarms;
pub mod carrier;
pub mod chip;
pub mod cli;
pub mod compare;
pub mod config;
pub mod devices;
pub mod faults;
pub mod feeder_policy;
pub mod gate;
pub mod help;
pub mod lateness;
mod line_modules;
pub mod load;
pub mod module_name;
pub mod names;
pub mod outage;
pub mod ports;
pub mod processes;
pub mod report;
pub mod reservation;
#[cfg(feature = "ros2")]
pub mod ros2;
pub mod run;
pub mod run_error;
pub mod run_record;
pub mod tally;
pub mod zone_asker;

pub use cli::{CliError, parse};
pub use compare::{Comparison, POLICIES, compare};
pub use config::{CellConfig, MAX_HOURS, TimelineConfig};
pub use faults::{CellFault, CellFaultKind};
pub use feeder_policy::FeederPolicy;
pub use lateness::keeping_up_line;
pub use report::{Report, speed_line};
pub use run::{refused, run};
pub use run_error::RunError;
pub use run_record::RunRecord;
pub use tally::Tally;
