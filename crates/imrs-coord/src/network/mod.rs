//! The network bound of Jiménez et al. 1992 ("Communications"): a deterministic CSMA/DCR bus (the
//! Intel i82596's deterministic collision resolution), whose delays the seed bounds by
//!
//! ```text
//! D_max = Σ_i (X_i/R + τ + IFS) + IFS + γ + τ,     γ = 2τ + jam + ε
//! ```
//!
//! After a collision, each of the `N` stations transmits once, in its own slot; in the worst
//! case the seed sees, resolution periods follow one another with no idle time. The bus
//! simulated slot by slot ([`simulate`]) shows where that holds: with slots no longer than
//! `IFS` it does; with 802.3's slot time a message that just misses its own empty slot waits
//! longer, and [`slot_bound`] (used by [`Bus::worst_wait`] and [`report`]) is the bound that
//! holds.
//!
//! `X_i` the longest packet of station `i`, `R` the data rate, `τ` the end-to-end
//! propagation delay, `IFS` the interframe spacing, `jam` the jam time and `ε` the
//! collision detection time. With all `X_i` equal this is the seed's
//! `N (X/R + τ + IFS) + IFS + γ + τ`.
//!
//! ```
//! use imrs_coord::network::{Bus, SEED_CASE};
//!
//! // The seed's case: a coordinator (X_t = 148 B) and nine robots (X_p = 51 B) on 100 m.
//! let bus = Bus::ieee_802_3(100.0);
//! let d = bus.d_max(&SEED_CASE);
//! assert!((d.as_secs_f64() * 1e6 - 600.9).abs() < 0.1); // µs; the seed reports 604
//! ```

mod bus;
mod queue;
mod report;
mod sim;

pub use bus::{Bus, SEED_CASE, SEED_D_MAX};
pub use queue::TransmitQueue;
pub use report::{Placement, PlacementError, PortBound, report};
pub use sim::{
    Delivery, MAX_SEARCHED, NoStation, Offer, Simulated, missed_slot, simulate, slot_bound,
    worst_missed_slot,
};
