//! The coordination layer of a multiple-arm cell, after G. Jiménez, J. L. Sevillano,
//! A. Civit-Balcells, F. Díaz and A. Civit-Breu, *RISC-based architectures for multiple robot
//! systems* (1992; seed 003): arms that share space and tools, a coordinator, and the network
//! that carries their messages.
//!
//! Built so far:
//! - [`network`]: the worst-case delay of a deterministic CSMA/DCR bus for a given cell
//!   (the seed's `D_max`), the priority-ordered, non-preemptive transmit queue that bounds a
//!   high-priority message's wait, and a report of every port's worst case once the cell's
//!   modules are placed on stations;
//! - [`scheduler`]: the run-time task scheduler, against static assignments;
//! - [`zones`]: zones and tools as resources, the coordinator's table of them, deadlock
//!   detection among exclusive resources and its resolution, the robots' positions as they
//!   told them, against which the coordinator checks a robot's way ahead and computes the
//!   alternative trajectory round a stopped robot, and the arm's pipeline of points checked
//!   ahead;
//! - [`coordinator`]: the zone coordinator as a module, speaking the seed's message set over
//!   typed ports.
//!
//! A cell of four arms on the simulated table under the coordinator, fed by the run-time
//! scheduler, is the `table-cell` crate (`cargo run --release --example coord_cell`).
//!
//! Why a crate of its own: the layer uses the core, but the core must not depend on it; a
//! robot crate embedding `imrs-core` does not compile it. It drives no simulated world
//! (parry3d measures its zones and sweeps, with no physics engine), so a user of the layer
//! compiles neither rapier nor a simulation.

pub mod coordinator;
pub mod network;
pub mod scheduler;
pub mod zones;
