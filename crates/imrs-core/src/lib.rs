//! Modules as actors and the order scheduler of an integrated multi-robot system.
//!
//! This crate is the next layer above [`imrs_ports`]: modules with state, tasks, response
//! and exception handlers, named sections and an `order` that ranks them. Until it lands,
//! it re-exports the ports so that cell crates can already depend on `imrs-core` alone.

pub use imrs_ports;
