//! Synchronous ports: the port-automata communication of Lyons & Arbib 1985 (Lyons & Arbib, §4).
//!
//! An [`Output`] and an [`Input`] are connected by [`connect`] (or [`connect_any`] when the
//! connection is made by name at run time), as a schema instance's *connection map* connects
//! its ports. Communication is synchronous:
//!
//! - **A write suspends until a connected input has read it.** The value goes to every input
//!   connected to the output at the time of the write, and to any connected while the write
//!   is still waiting (fan-out); the writer proceeds as soon as *one* of them has read it.
//!   The others still read it later: every connected reader gets every value, once.
//! - **A read suspends until a connected output writes.** With several outputs connected to
//!   one input (fan-in), a read completes when *any* of them writes, and every value written
//!   stays readable in turn, in the order written.
//! - **A write that is given up is withdrawn.** Dropping a [`Write`] before any input has read
//!   it takes the value back from every input, so a sensor can replace a stale sample with a
//!   fresh one (`select` the write against its next sample) without a reader ever seeing the
//!   stale one.
//! - **Select.** An input is an alternative of [`select`](crate::select()), beside ports'
//!   ends: of the ready alternatives the one of highest priority is taken
//!   ([`Input::with_priority`]), so a module can wait on a schema network and on its other
//!   ports at once.
//! - **Ends.** An end is closed by [`Input::close`] / [`Output::close`], or when its last clone
//!   is dropped. A read on an input all of whose connected outputs are closed, with nothing
//!   left to read, fails with [`ReadError::Disconnected`]; so does a write whose connected
//!   inputs are all closed. An end with no connection at all waits: a network may still
//!   connect it.
//!
//! ```
//! use imrs_ports::synchronous::{Input, Output, connect};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build()?;
//! # runtime.block_on(async {
//! // Fan-out: Jposition_1(actual) feeds two readers.
//! let actual = Output::<f32>::new("actual", "Jposition_1");
//! let closejoint = Input::<f32>::new("Pin", "Closejoint_1");
//! let monitor = Input::<f32>::new("Pin", "Monitor_1");
//! connect(&actual, &closejoint);
//! connect(&actual, &monitor);
//!
//! let reading = tokio::spawn(async move { closejoint.read().await });
//! actual.write(0.25).await?; // released by the first read
//! assert_eq!(reading.await??, 0.25);
//! assert_eq!(monitor.read().await?, 0.25); // and the other reader still gets it
//! # Ok::<_, Box<dyn std::error::Error>>(())
//! # })?;
//! # Ok(())
//! # }
//! ```

mod any;
mod error;
mod handle;
mod input;
mod output;
mod ticket;

pub use any::{AnyPort, Direction, connect_any};
pub use error::{ConnectError, ReadError, WriteError};
pub use input::{Input, Read};
pub use output::{Output, Write};

/// Connects `output` to `input`: every later write on `output` (and one it is waiting on now)
/// reaches `input`. The types must agree, so a static connection is checked by the compiler.
/// Connecting the same pair twice is the same as once.
pub fn connect<T: Clone + Send + 'static>(output: &Output<T>, input: &Input<T>) {
    output.connect(input);
}
