//! The run-time task scheduler of Jiménez et al. 1992 ("Programming/user interface"):
//! robot-independent elementary tasks with task and part prerequisites, parts that come in
//! random order at random times, and tasks assigned to robots as the cell runs — by
//! capability, speed, and a score for the resource and collision conflicts each assignment
//! would meet (the entry points of the zones on its way, the robots at work it would go
//! round), worked out ahead, with the search pruned.
//!
//! [`simulate`] runs a [`Workcell`] on a stream of [`Arrivals`] under a [`Policy`]: the
//! [`RunTime`] scheduler, or the [`Static`] assignment it is compared with — each task kind
//! bound to one robot beforehand, each robot running its program in a fixed order (or, as
//! a stronger baseline, taking its oldest ready task); or the [`PartDriven`] variant, tasks
//! in the order their parts came. All meet the same arrivals, so their throughputs compare.
//!
//! The cell here is a discrete-event model (travel at a robot's speed, work scaled by it,
//! one robot at a time in a shared zone), not the rapier world: what is compared is the
//! scheduling, on equal terms.
//!
//! ```
//! use imrs_coord::scheduler::{Arrivals, RunTime, Static, Workcell, simulate};
//!
//! let cell = Workcell::assembly();
//! let arrivals = Arrivals::random(&cell, 40, 7);
//! let fixed = simulate(&cell, &arrivals, &mut Static::programs(&cell));
//! let run_time = simulate(&cell, &arrivals, &mut RunTime::default());
//! assert_eq!(run_time.units, 40);
//! assert!(run_time.per_hour() > fixed.per_hour());
//! ```

mod cell;
mod policy;
mod sim;
mod state;
mod way;

pub use cell::{Arrivals, Robot, Skill, TaskSpec, Workcell, Zone};
pub use policy::{PartDriven, Policy, RunTime, Static};
pub use sim::{Dispatch, Outcome, Refusal, simulate};
pub use state::{Estimate, State};
