//! The simulated chip-insertion cell: two assembly lines of robots, conveyors, pallets and a
//! shared feeder zone, in a rapier3d world stepped on the framework clock; and, in
//! [`hand`], a dextrous hand over a table of objects, for the schemas of seed 004.
//!
//! The seed's Appendix omits its device drivers; this crate stands in for the hardware. It
//! runs faster than real time on a [`VirtualClock`](imrs_core::imrs_ports::VirtualClock), or
//! on the wall clock, and the physical facts of a run — who was inside the feeder zone and
//! when, which robots touched, where the pallets are — are measured by rapier, never taken
//! from the bookkeeping of the modules under test.
//!
//! A chip robot reaches into the feeder zone and back:
//!
//! ```
//! use std::sync::Arc;
//! use std::time::Duration;
//! use imrs_core::imrs_ports::{Instant, VirtualClock};
//! use imrs_sim::{FeederId, Line, Role, RobotId, Sim, SimConfig, Target};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # let runtime = tokio::runtime::Builder::new_current_thread().enable_all().start_paused(true).build()?;
//! # runtime.block_on(async {
//! let clock = VirtualClock::new();
//! let sim = Sim::new(SimConfig::seeded(7), Arc::new(clock.clone()));
//! sim.spawn();
//! let chip_it = sim.robot(RobotId::new(Line::A, Role::ChipIt));
//! let driving = tokio::spawn(async move {
//!     chip_it.move_to(Target::Feeder(FeederId(0))).await?;
//!     let chip = chip_it.grasp(FeederId(0)).await?;
//!     chip_it.move_to(Target::Home).await?;
//!     Ok::<_, imrs_sim::DeviceError>(chip)
//! });
//! imrs_core::time::drive(&clock, Instant::from_start(Duration::from_secs(5))).await;
//! assert_eq!(driving.await??, 1);
//! for event in sim.log().snapshot() {
//!     println!("{event}"); // entered the feeder zone ... left the feeder zone
//! }
//! # Ok::<_, Box<dyn std::error::Error>>(())
//! # })?;
//! # Ok(())
//! # }
//! ```

mod device;
mod error;
mod event;
mod fault;
pub mod hand;
mod ids;
pub mod layout;
pub mod profile;
mod rng;
pub mod scara;
mod scene;
mod sim;
pub mod table;
mod world;

pub use device::{Gate, Relay, Release, Robot};
pub use error::DeviceError;
pub use event::{SimEvent, SimEventKind, SimLog};
pub use fault::{Fault, FaultKind};
pub use ids::{FeederId, Line, PalletId, RobotId, Role, Station};
pub use rng::Rng;
pub use scene::{ArmPose, BoxPose, FeederView, LinkPose, PalletPose, Scene};
pub use sim::{Sim, SimConfig};
pub use world::{FEEDER_CHIPS, RobotTimes, Target};
