//! Ports across processes: a port's owner in one process, its users in others, the messages
//! carried through shared memory by iceoryx2.
//!
//! Module code does not change. The owner's process *exports* its port; a user's process
//! *imports* it, getting a port of the same name and types whose owner is a bridge to the
//! other process. The user module sends on it exactly as it would in one process. Which
//! ports cross is decided where the cell is wired, not in the modules.
//!
//! ```no_run
//! use imrs_ports::{AnyUser, Port, PortSpec, usage};
//! use imrs_ipc::{Imported, Remote, export, import};
//!
//! # async fn owner() -> Result<(), Box<dyn std::error::Error>> {
//! // The owner's process: the port, declared as ever, and exported.
//! let port: Port<u64, u64, usage::Receive, AnyUser, 4> = Port::new(PortSpec::new("DOUBLE", "DOUBLER"));
//! let _bridge = export(&Remote::new("my_cell")?, &port)?;
//! let mut owner = port.owner()?;
//! let (n, reply) = owner.receive().await?;
//! reply.reply(2 * n);
//! # Ok(()) }
//! # async fn user() -> Result<(), Box<dyn std::error::Error>> {
//! // A user's process: the same port, imported for module "ASKER".
//! let imported: Imported<u64, u64, usage::Receive> =
//!     import(&Remote::new("my_cell")?, "DOUBLE", "DOUBLER", "ASKER")?;
//! let mut asker = imported.port().user_named("ASKER")?;
//! assert_eq!(asker.send(21).await?, 42);
//! # Ok(()) }
//! ```
//!
//! Every port crosses with these two calls, [`export`] and [`import`]; the port's type
//! chooses how (the owner's usage, and values or [`Shared`](imrs_ports::Shared)
//! messages), and the [`Imported`] a user's process asks for must match it. Ports whose owner
//! receives carry each send to it. `RESPONSE` ports, whose users query them: a remote query
//! waits for the owner's response handler, which runs when the owner's order says.
//! `SENDALL` ports: the owner's broadcast reaches modules in other processes, and their
//! replies come back. `CALLALL` ports: the owner's query reaches the response handlers of
//! modules in other processes, each run when its module's order says. And `QUERY` ports,
//! whose owner queries its users, answered by a remote module's response handler.

//! The bridges are woken by iceoryx2's events through tokio's reactor (the listener's
//! socket, as an `AsyncFd`), and do their work where they are woken: a remote request goes
//! into the owner's port in the reactor's thread, which wakes the module; the module's
//! reply goes into shared memory as part of its `reply`; a user's send goes there as part
//! of the send, and its reply to the sender in the reactor's thread. A round trip switches
//! to no task but the modules'. Each bridge also has a task in the runtime the cell runs
//! on, which does the work where the waking thread cannot (the bridge busy in another
//! thread, or a TIGHT port). They poll no message; an exported port's task also looks at
//! each 50 ms tick, so that a request whose notify was lost waits a tick at most. Call the
//! functions from within a runtime whose I/O driver is enabled (`enable_all`).
//!
//! A TIGHT port's modules spin on both sides, and the bridges' work is done in their turns
//! ([`Pump`](imrs_ports::transport::Pump)): the user's spinning send puts its request into
//! shared memory and reads the reply there itself, and the owner's spinning receive takes
//! the request from shared memory and sends the reply itself, so that a round trip wakes
//! no task and no thread. The importing process learns that the port is TIGHT when it
//! connects, and declares its side of the port so. Each side holds back the wake-up of the
//! other process while the other may be spinning too, and sends it once a message has
//! waited a few tens of turns, or when its own wait parks, or when its bridge's task next
//! runs; so a side that has parked is woken as on any port. The bridges'
//! own ends park at once ([`End::park_waits`](imrs_ports::transport::EndTransport::park_waits)).
//!
//! What crosses is a [`Wire`] type: `#[repr(C)]`, self-contained, `ZeroCopySend`. Both
//! processes must agree on it — iceoryx2 compares its name, size and alignment when the
//! port connects — and a mismatch is refused, naming the port.
//!
//! The restrictions hold across processes: an importing module not on the port's user
//! list, or beyond its number of users, is refused when it connects, with the port's own
//! [`WireError`](imrs_ports::WireError). A process that dies does not hang its
//! peers: a user's pending sends to a dead owner fail with
//! [`SendError::NoReply`](imrs_ports::SendError::NoReply), and a new copy of
//! the owner that exports the port again is served. The owner of a `SENDALL`, `CALLALL`
//! or `QUERY` port hears nothing from its users once they connect, so their processes
//! connect again every half second, and a new copy of the owner reaches them from then on. A process that answers requests from
//! others awaits [`Exported::settled`] (or [`Imported::settled`]) before it ends cleanly, so
//! that its modules' last answers, which may be left to tasks of the runtime, are not cut
//! off.
//!
//! Service names are derived from the cell's name and the port's, so two cells on one
//! host never meet; no iceoryx2 configuration file is needed. The owner's process creates a
//! port's services sized from its restrictions — as many user processes as the port has
//! users, not iceoryx2's default of eight — and a user's process only opens them, so an
//! import of a port nobody exports fails at once with [`IpcError::NoOwner`]. Across
//! processes the ports run on the wall clock: each process has its own clock, and processes
//! that must agree on one time build it from one epoch
//! ([`RealClock::from_epoch`](imrs_ports::RealClock::from_epoch)).
//!
//! A port of values copies each message into shared memory and moves it by value through
//! the bridges: cheap for small messages, and costly for large ones (tens of KiB),
//! which in a debug build can also overflow tokio's default 2 MiB worker stack. A port of
//! [`Shared`](imrs_ports::Shared) messages crosses in shared memory instead,
//! through the same two calls: the sender loans a sample of shared memory from its end,
//! builds its message there, and sends it with nothing copied; the owner reads it where it
//! lies, and builds its reply in a loan made for the request
//! ([`Shared::loan_reply`](imrs_ports::Shared::loan_reply)), which crosses back
//! the same way (a reply built on the heap is copied once), to be read where it lies. The
//! module's code is the one it would run in a single process, where a loan is on the heap:
//!
//! ```no_run
//! use imrs_ports::{AnyUser, Port, PortSpec, Shared, usage};
//! use imrs_ipc::{FromBytes, Imported, Remote, ZeroCopySend, export, import};
//!
//! #[derive(Debug, Clone, Copy, ZeroCopySend, FromBytes)]
//! #[repr(C)]
//! #[type_name("my_cell::Image")]
//! struct Image {
//!     pixels: [u8; 65536],
//! }
//! impl Default for Image {
//!     fn default() -> Self {
//!         Self { pixels: [0; 65536] }
//!     }
//! }
//!
//! # async fn owner() -> Result<(), Box<dyn std::error::Error>> {
//! let port: Port<Shared<Image>, Shared<u64>, usage::Receive, AnyUser, 1> =
//!     Port::new(PortSpec::new("IMAGE", "VISION"));
//! let _bridge = export(&Remote::new("my_cell")?, &port)?;
//! let mut vision = port.owner()?;
//! let (image, reply) = vision.receive().await?; // read where the camera wrote it
//! let mut lit = image.loan_reply(); // where the reply will cross back
//! *lit = image.pixels.iter().filter(|&&p| p > 0).count() as u64;
//! reply.reply(lit);
//! # Ok(()) }
//! # async fn user() -> Result<(), Box<dyn std::error::Error>> {
//! let imported: Imported<Shared<Image>, Shared<u64>, usage::Receive> =
//!     import(&Remote::new("my_cell")?, "IMAGE", "VISION", "CAMERA")?;
//! let mut camera = imported.port().user_named("CAMERA")?;
//! let mut image = camera.loan()?; // a sample of shared memory, zeroed
//! image.pixels[..100].fill(255);
//! let lit = camera.send(image).await?;
//! assert_eq!(*lit, 100);
//! # Ok(()) }
//! ```
//!
//! `RESPONSE` ports of `Shared` messages cross the same way: a query loaned and built in place, read in place by the
//! owner's response handler, whose answer is built in a reply loan. So do `QUERY` ports:
//! the owner's query, loaned from
//! the user's process, is read in place by the user's response handler, which builds its
//! answer in a reply loan, read in place by the owner. And `SENDALL` and `CALLALL` ports:
//! the owner's loans are samples of a publish-subscribe
//! service of the port's own, and a broadcast built in one goes out once, when the port
//! hands it to its users (`Shared`'s `Clone`, which shares a message no one writes rather
//! than copying it). Every user, in any process, reads that one sample where the owner
//! built it, and it is let go when the last handle is dropped. A broadcast built on the
//! heap is copied into a sample once, as the port hands it over
//! ([`Port::broadcast_with`](imrs_ports::transport::PortTransport::broadcast_with)), and goes out
//! the same way. The user module builds its answer in a reply loan, read in place by the
//! owner.
//!
//! A loan is refused, naming the port, while the module holds as many loans and requests as
//! the port allows at once (16). A `Shared` message that does not lie in one of the port's
//! own loans — a heap value, or another port's loan — is copied into one when sent.

mod bridge;
mod broadcast;
mod carry;
mod connect;
mod dispatch;
mod entry;
mod error;
mod export;
// What reads a peer's bytes, for the fuzz targets in `fuzz/` (`cargo fuzz` sets the cfg).
#[cfg(fuzzing)]
#[doc(hidden)]
pub mod fuzzing;
mod import;
mod send_all;
mod sweep;
mod turn;
mod wire;

pub use entry::{Export, Import, export, import};
pub use error::IpcError;
pub use export::exported::Exported;
pub use import::Imported;
pub use wire::{Remote, Wire};

pub use iceoryx2::prelude::ZeroCopySend;
pub use zerocopy::FromBytes;
