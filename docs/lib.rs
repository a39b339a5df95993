//! The IMRS guide: every chapter of `docs/`, and the repository's README, included here so
//! that each of their Rust blocks is compiled (and, unless marked `no_run`, run) by
//! `cargo test -p imrs-guide`. Read the chapters as Markdown; this crate holds no code.
#![doc = include_str!("README.md")]

/// The README at the root of the repository.
#[doc = include_str!("../README.md")]
pub mod readme {}

/// Modules, their order, and the cell.
#[doc = include_str!("modules-and-orders.md")]
pub mod modules_and_orders {}

/// Ports and their restrictions.
#[doc = include_str!("ports-and-restrictions.md")]
pub mod ports_and_restrictions {}

/// The framework clock, real and virtual.
#[doc = include_str!("time.md")]
pub mod time {}

/// Ports across processes.
#[doc = include_str!("across-processes.md")]
pub mod across_processes {}

/// Ports across hosts, on zenoh.
#[doc = include_str!("across-hosts.md")]
pub mod across_hosts {}

/// ROS 2 over rmw_zenoh.
#[doc = include_str!("with-ros2.md")]
pub mod with_ros2 {}

/// Recordings, Foxglove and the timeline.
#[doc = include_str!("recording.md")]
pub mod recording {}

/// The coordination layer.
#[doc = include_str!("coordination.md")]
pub mod coordination {}

/// Schemas on synchronous ports.
#[doc = include_str!("schemas.md")]
pub mod schemas {}

/// Benchmarks and their figures.
#[doc = include_str!("benchmarks.md")]
pub mod benchmarks {}
