//! The simulated chip-insertion cell: two assembly lines of robots, conveyors, pallets and a
//! shared feeder zone, in a rapier3d world stepped on the framework clock; in `hand`, a
//! dextrous hand over a table of objects, for the schemas of Lyons & Arbib 1985; and in `table`, a
//! table of SCARA arms sharing zones and tools, for the coordination layer.
//!
//! Each world is a cargo feature of its own — `chip` (the crate root's items, `layout`,
//! `profile`), `hand` and `table` (with `scara`, which the chip line's arms share) — all on by
//! default. The three worlds share nothing but the framework clock, so a user of one does
//! not compile the others: a schema crate asks for `hand` alone. With no feature the crate
//! is empty and compiles neither rapier nor nalgebra.
//!
//! The seed's Appendix omits its device drivers; this crate stands in for the hardware. It
//! runs faster than real time on a [`VirtualClock`](imrs_ports::VirtualClock), or
//! on the wall clock, and the physical facts of a run — who was inside the feeder zone and
//! when, which robots touched, where the pallets are — are measured by rapier, never taken
//! from the bookkeeping of the modules under test.
//!
//! A chip robot reaches into the feeder zone and back:
//!
//! ```
//! use std::sync::Arc;
//! use std::time::Duration;
//! use imrs_ports::{Instant, VirtualClock};
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

#[cfg(feature = "chip")]
mod device;
#[cfg(feature = "chip")]
mod drawn;
#[cfg(feature = "chip")]
mod error;
#[cfg(feature = "chip")]
mod event;
#[cfg(feature = "chip")]
mod fault;
#[cfg(feature = "hand")]
pub mod hand;
#[cfg(feature = "chip")]
mod ids;
#[cfg(feature = "chip")]
pub mod layout;
#[cfg(feature = "chip")]
pub mod profile;
#[cfg(any(feature = "chip", feature = "hand"))]
mod rng;
#[cfg(any(feature = "chip", feature = "table"))]
pub mod scara;
#[cfg(feature = "chip")]
mod scene;
#[cfg(feature = "chip")]
mod sim;
#[cfg(any(feature = "chip", feature = "hand"))]
mod step;
#[cfg(feature = "table")]
pub mod table;
#[cfg(feature = "chip")]
mod world;

#[cfg(feature = "chip")]
pub use device::{Gate, Relay, Release, Robot};
#[cfg(feature = "chip")]
pub use error::DeviceError;
#[cfg(feature = "chip")]
pub use event::{SimEvent, SimEventKind, SimLog};
#[cfg(feature = "chip")]
pub use fault::{Fault, FaultKind};
#[cfg(feature = "chip")]
pub use ids::{FeederId, Line, PalletId, RobotId, Role, Station};
#[cfg(feature = "chip")]
pub use scene::{ArmPose, BoxPose, FeederView, LinkPose, PalletPose, Scene};
#[cfg(feature = "chip")]
pub use sim::{Sim, SimConfig};
#[cfg(feature = "chip")]
pub use world::{FEEDER_CHIPS, RobotTimes, Target};
