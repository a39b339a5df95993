//! Seeing a cell: an MCAP recording of a run that Foxglove opens as a moving 3D cell with its
//! messages and log, a timeline picture of who was in which section and who waited, and a
//! reader that sums a recording up.
//!
//! Record a cell and its simulation, run it, finish, and read the file back:
//!
//! ```
//! use std::sync::Arc;
//! use std::time::Duration;
//! use imrs_record::{Recorder, Timeline, read_summary};
//! use imrs_core::{Cell, time::drive};
//! use imrs_ports::Instant;
//! use imrs_sim::{FeederId, Line, Role, RobotId, Sim, SimConfig, Target};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # let runtime = tokio::runtime::Builder::new_current_thread().enable_all().start_paused(true).build()?;
//! # runtime.block_on(async {
//! let path = std::env::temp_dir().join(format!("imrs-doc-{}.mcap", std::process::id()));
//! let (cell, clock) = Cell::virtual_clock();
//! let sim = Sim::new(SimConfig::seeded(7), Arc::clone(cell.clock()));
//!
//! let recorder = Recorder::create(&path)?;
//! recorder.record_cell(&cell);
//! recorder.record_sim(&sim, Recorder::SCENE_PERIOD);
//! let timeline = Timeline::new(Duration::ZERO, Duration::from_secs(60));
//! timeline.record_sim(&sim);
//!
//! sim.spawn();
//! let robot = sim.robot(RobotId::new(Line::A, Role::ChipIt));
//! tokio::spawn(async move { robot.move_to(Target::Feeder(FeederId(0))).await });
//! drive(&clock, Instant::from_start(Duration::from_secs(5))).await;
//!
//! recorder.finish()?;
//! let summary = read_summary(&path)?;
//! assert!(summary.indexed);
//! assert!(summary.channels.iter().any(|channel| channel.topic == "/tf"));
//! // The robot reached into the feeder zone: rapier saw it, the timeline shows it.
//! assert!(timeline.rows().iter().any(|row| row.name == "zone: chip-robot-A"));
//! # std::fs::remove_file(&path)?;
//! # Ok::<_, Box<dyn std::error::Error>>(())
//! # })?;
//! # Ok(())
//! # }
//! ```
//!
//! The simulation is any world that implements [`imrs_scene::World`]: it gives the
//! recorder and the timeline its conveyors, arms, pallets, feeders and zone, and the facts
//! it measures, so that this crate compiles no world (neither rapier nor one cell's
//! geometry); the chip line's `imrs_sim::Sim` implements it.
//!
//! The scene and the log use Foxglove's well-known schemas through the `foxglove` crate,
//! Foxglove's own SDK, rather than schemas written out here: its message types are generated
//! from the same definitions the app reads, so the 3D and log panels work with no set-up and
//! cannot drift from the app. The cell's own messages are JSON with a JSON schema, which
//! Foxglove's raw-message and plot panels show field by field.

mod error;
mod messages;
mod recorder;
pub mod scene;
mod summary;
mod time;
pub mod timeline;

pub use error::RecordError;
pub use recorder::{Recorded, Recorder};
pub use summary::{ChannelSummary, RecordingSummary, read_summary};
pub use timeline::Timeline;
