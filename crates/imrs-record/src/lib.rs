//! Seeing a cell: an MCAP recording of a run that Foxglove opens as a moving 3D cell with its
//! messages and log, a timeline picture of who was in which section and who waited, and a
//! reader that sums a recording up.
//!
//! ```no_run
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! use imrs_record::Recorder;
//! # let cell: imrs_sim::imrs_core::Cell = unimplemented!();
//! # let sim: imrs_sim::Sim = unimplemented!();
//! let recorder = Recorder::create("cell.mcap")?;
//! recorder.record_cell(cell.events());
//! recorder.record_sim(&sim, Recorder::SCENE_PERIOD);
//! // ... run the cell ...
//! recorder.finish()?;
//! println!("{}", imrs_record::read_summary("cell.mcap")?);
//! # Ok(())
//! # }
//! ```
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
