//! The devices of the cell — robots, gates, freeze relays — as async operations on the
//! framework clock: a module's hardware division.

mod robot;
mod station;

pub use robot::Robot;
pub use station::{Gate, Relay, Release};
