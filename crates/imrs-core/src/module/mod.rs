//! Modules: actors that own their state, run tasks, and answer queries as their order allows.

pub(crate) mod ctx;
pub(crate) mod run;
pub(crate) mod spec;
pub(crate) mod thread;
