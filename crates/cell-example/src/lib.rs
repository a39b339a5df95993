//! The chip-insertion line of Shin (1985), Appendix, as IMRS modules.
//!
//! The modules (GATE, LOAD_IT, LOAD_CARD, SCREW_IN_CARD, CHIP_IT, CHIP_IT2) arrive with the
//! order scheduler and the simulated cell they run on.

pub use imrs_sim;
