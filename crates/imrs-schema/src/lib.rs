//! Schemas, assemblages and task-units: the port-automata model of Damian Lyons and Michael
//! Arbib, *A Task-Level Model of Distributed Computation for Sensory-Based Control of
//! Complex Robot Systems* (1985; seed 004), on the synchronous ports of
//! [`imrs_ports::synchronous`], with the special
//! schemas of a simulated dextrous hand.
//!
//! Why a crate of its own: the model is a second way of programming a cell, beside
//! `imrs-core`'s modules, and its special schemas drive the simulated hand of `imrs-sim`,
//! which a robot crate embedding `imrs-core` should not have to compile. The synchronous
//! ports themselves live in `imrs-ports`, so a module talks to a schema network without
//! this crate's help.
//!
//! # The notation, in Rust
//!
//! | Lyons & Arbib 1985 | here |
//! |---|---|
//! | `[N (ip) (op) (v) (b)]` | a type implementing [`Schema`]: `NAME`, `Ports` (declared with [`ports!`]), its fields are `(v)`, [`Schema::behavior`] is one pass of `(b)` |
//! | `[N (ip) (op) (s) (ib) (p) (n)]` | a [`Schema`] of [`Kind::Assemblage`]: [`Schema::set_up`] instantiates and connects the components (`s`, `ib`, `n`) and returns the component ports that are its own (`p`) |
//! | `[N (ip) (op) (sl) (ml) (ib) (var) (b)]` | [`Kind::TaskUnit`]: `set_up` makes the sensing and motor components, `behavior` is the r-schema |
//! | `N_i{V0}{C0}` | [`Cx::instantiate_as`]`(i, N { v0… })`, then [`Cx::connect`] per couplet (checked by the compiler); or [`Cx::instantiate_with`] and a map of [`Couplet`]s by name (checked at instantiation) |
//! | `STOP` / `STOP{N_i}` | `Ok(Flow::Stop)` / [`Si::stop`] |
//! | `FORALL N DO … ENDFOR` | `for si in cx.forall::<N>() { … }` |
//! | `x := p` (read), `p := e` (write) | `p.read().await?`, `p.write(e).await?` |
//! | `Jmotor_i`, `Jposition_i`, `Tactile_i`, `SEF_i` | [`special`] |
//!
//! An instance runs its behaviour pass after pass until it stops, is stopped, or a read or
//! write fails; then its components are stopped and its ports closed. Everything runs on
//! one [`Processor`](imrs_core::Processor) on the framework clock, so a run on virtual time
//! is reproducible. A behaviour must await something each pass — a port, a delay, a step
//! of the hand — or it holds the processor and the clock never moves.
//!
//! # Example: the guarded move
//!
//! The hand reaches over the cube, then closes its fingers until each touches it:
//!
//! ```
//! use std::sync::Arc;
//! use std::time::Duration;
//! use imrs_ports::{Instant, VirtualClock};
//! use imrs_schema::{Network, seed::{Grip, Reach}, special::Vision};
//! use imrs_sim::hand::{FINGERS, Hand, HandConfig, Touch, finger_joints};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # let runtime = tokio::runtime::Builder::new_current_thread().enable_all().start_paused(true).build()?;
//! # runtime.block_on(async {
//! let clock = VirtualClock::new();
//! let hand = Hand::new(HandConfig::seeded(1), Arc::new(clock.clone()));
//! hand.spawn();
//! let net = Network::new("HAND", Arc::new(clock.clone()));
//! net.instantiate(Vision::new(&hand))?; // one SEF per object: the cube is SEF_2
//! let at = |s: f64| Instant::from_start(Duration::from_secs_f64(s));
//! imrs_core::time::drive(&clock, at(0.1)).await;
//! net.instantiate(Reach::new(&hand, 2, 0.2))?; // over the cube…
//! imrs_core::time::drive(&clock, at(2.0)).await;
//! net.instantiate(Reach::new(&hand, 2, 0.1))?; // …and down around it
//! imrs_core::time::drive(&clock, at(3.0)).await;
//! let joints = FINGERS.into_iter().flat_map(finger_joints);
//! net.instantiate(Grip::new(&hand, joints, 0.01))?;
//! imrs_core::time::drive(&clock, at(6.0)).await;
//! for finger in FINGERS {
//!     assert_eq!(hand.touch(finger)?, Some(Touch::Object(0)));
//! }
//! # Ok::<_, Box<dyn std::error::Error>>(())
//! # })?;
//! # Ok(())
//! # }
//! ```

pub mod automaton;
mod cx;
mod error;
mod instance;
mod net;
mod network;
mod port_array;
mod ports;
mod race;
mod schema;
mod scope;
pub mod seed;
pub mod special;
mod trace;

pub use cx::Cx;
pub use error::SchemaError;
pub use imrs_ports::Name;
pub use imrs_ports::synchronous::{AnyPort, Input, Output, ReadError, WriteError};
pub use instance::{Couplet, Si};
pub use network::Network;
pub use port_array::PortArray;
pub use ports::{Declare, Ports};
pub use schema::{Behavior, Flow, Kind, Schema};
pub use trace::{Ending, TraceEntry};
