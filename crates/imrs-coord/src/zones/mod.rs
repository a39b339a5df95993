//! Zones and tools as shared resources, the coordinator's bookkeeping of them (Jiménez et al. 1992,
//! "Coordination": centralized loose coordination), deadlock detection among exclusive
//! resources, and the arm controller's pipeline of points checked ahead.
//!
//! The working space is divided into logical subzones, all defined before start
//! ([`ZoneDef`], a parry3d shape where it lies); they are activated or deactivated at run
//! time only while every robot is stopped. A zone is for **exclusive** use (one robot inside)
//! or for **simultaneous use with restrictions** (several inside, one moving at a time);
//! tools are always exclusive. The [`Resources`] table answers each request as the seed's
//! coordinator does — a grant, or *sleep* (stop at the border) — and wakes sleepers when a
//! resource frees. Exclusive zones and tools can deadlock: [`Resources::deadlock`] finds the
//! cycle and [`Resources::resolve`] makes one robot back off. Robots say where their links
//! are ([`Positions`]), and the coordinator checks a robot's way ahead against that alone. A
//! stopped robot in the way of one that may move is a geometric deadlock: [`detour`]
//! computes the alternative trajectory round it.
//!
//! ```
//! use imrs_coord::zones::{Answer, Resources, ZoneDef, ZoneKind};
//!
//! let mut table = Resources::new(
//!     [ZoneDef::boxed("FEEDERS", ZoneKind::Shared, [0.0, 0.0, 0.3], [0.2, 0.2, 0.3])],
//!     ["GRIPPER"],
//!     ["CHIP_IT", "CHIP_IT2"],
//! );
//! assert_eq!(table.request_move("CHIP_IT", "FEEDERS")?, Answer::Grant);
//! // Only one robot moves in a shared zone at a time: the other sleeps at the border…
//! assert_eq!(table.request_move("CHIP_IT2", "FEEDERS")?, Answer::Sleep);
//! // …until the first stops inside (or leaves): then it is woken.
//! let woken = table.stopped_inside("CHIP_IT", "FEEDERS")?;
//! assert_eq!(woken, ["CHIP_IT2"]);
//! # Ok::<(), imrs_coord::zones::ZoneError>(())
//! ```

mod deadlock;
mod detour;
mod pipeline;
mod positions;
mod space;
mod sweep;
mod table;

pub use deadlock::{Deadlock, DeadlockKind};
pub use detour::{Obstacle, detour, first_blocked};
pub use pipeline::{Command, Next, Pipeline};
pub use positions::{PARTING, Pose, Positions};
pub use sweep::{Reservations, Sweep};
pub use table::{Answer, Resources, ZoneDef, ZoneError, ZoneKind};
