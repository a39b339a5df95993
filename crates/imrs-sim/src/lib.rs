//! The simulated work cell: robots, conveyor, pallets and the shared feeder zone, stepped
//! on the framework clock so that physical facts come from the physics.
//!
//! The world itself is the subject of a later change; this crate fixes its place in the
//! dependency chain `cell-example → imrs-sim → imrs-core → imrs-ports`.

pub use imrs_core;
