//! Modules: actors that own their state, run tasks, and answer queries as their order allows.

pub(crate) mod ctx;
pub(crate) mod module_shared;
pub(crate) mod run;
pub(crate) mod spec;
