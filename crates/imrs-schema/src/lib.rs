//! Schemas, assemblages and task-units: the port-automata model of Lyons & Arbib,
//! *A Model for Distributed Robot Control* (seed 004), on the synchronous ports of
//! [`imrs_ports::synchronous`](imrs_core::imrs_ports::synchronous).
//!
//! TODO crate docs

mod cx;
mod error;
mod instance;
mod network;
mod ports;
mod race;
mod schema;
mod scope;
pub mod seed;
pub mod special;

pub use cx::Cx;
pub use error::SchemaError;
pub use imrs_core::imrs_ports::Name;
pub use imrs_core::imrs_ports::synchronous::{AnyPort, Input, Output, ReadError, WriteError};
pub use instance::Si;
pub use network::{Ending, Network, TraceEntry};
pub use ports::{Declare, Ports};
pub use schema::{Behavior, Flow, Kind, Schema};
