//! Port automata as a formal object (Lyons & Arbib 1985, §4: the model the paper is named
//! for): an automaton's states, its input and output ports, its transition map and its
//! output map ([`PortAutomaton`]); a network of them composed into one automaton
//! ([`Composition`]) and explored state by state, to answer what the formalism allows —
//! can this network deadlock, does it always end ([`Composition::explore`]); and the same
//! declaration run as a schema on synchronous ports ([`AutomatonSchema`]), so that a run
//! of the composition and the network's behaviour can be set side by side
//! ([`Composition::run`]).
//!
//! Each state communicates on one port, as a schema's behaviour does: it reads an input
//! (the transition map gives the next state for the value read), or writes an output (the
//! output map is the value it writes), or it is final (STOP).
//!
//! ```
//! use imrs_schema::automaton::{Composition, PortAutomaton};
//!
//! // A finger closes until it touches, or up to its limit, then says so; the grip waits
//! // for it.
//! let finger = PortAutomaton::new("Closefinger_1", "p0")
//!     .read("p0", "Tin", |t| if t != 0 { "done" } else { "p1" })
//!     .read("p1", "Tin", |_| "done")
//!     .write("done", "Done", 1, "stop")
//!     .stop("stop");
//! let grip = PortAutomaton::new("Grip", "wait")
//!     .read("wait", "Done_1", |_| "stop")
//!     .stop("stop");
//! let network = Composition::new([finger, grip])?
//!     .environment(("Closefinger_1", "Tin"), [0, 1])?
//!     .connect(("Closefinger_1", "Done"), ("Grip", "Done_1"))?;
//! let found = network.explore()?;
//! assert!(found.always_ends && found.deadlock.is_none());
//! # Ok::<(), imrs_schema::automaton::AutomatonError>(())
//! ```

mod compose;
mod def;
mod schema;

pub use compose::{At, Composition, Exploration, Run, Stuck};
pub use def::{AutomatonError, PortAutomaton, Step, Transition, Value};
pub use schema::{AutomatonPorts, AutomatonSchema};
