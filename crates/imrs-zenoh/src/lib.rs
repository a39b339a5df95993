//! Ports across hosts: a port's owner on one host, its users on others, the messages
//! carried by zenoh and encoded in CDR.
//!
//! Module code does not change. The owner's host *exports* its port; a user's host
//! *imports* it, getting a port of the same name and types whose owner is a bridge to the
//! other host. The user module sends or queries on it exactly as it would in one process.
//! Which ports cross, and on which transport, is decided where the cell is wired.
//!
//! ```no_run
//! use imrs_ports::{AnyUser, Port, PortSpec, usage};
//! use imrs_zenoh::{Host, Imported, export, import};
//!
//! # async fn owner() -> Result<(), Box<dyn std::error::Error>> {
//! // The owner's host: listens for the others, and exports its port.
//! let host = Host::builder("my_cell").listen("tcp/0.0.0.0:7447").open().await?;
//! let port: Port<u64, u64, usage::Receive, AnyUser, 4> =
//!     Port::new(PortSpec::new("DOUBLE", "DOUBLER"));
//! let _exported = export(&host, &port).await?;
//! let mut doubler = port.owner()?;
//! let (n, reply) = doubler.receive().await?;
//! reply.reply(2 * n);
//! # Ok(()) }
//! # async fn user() -> Result<(), Box<dyn std::error::Error>> {
//! // A user's host: connects to the owner's, and imports the port for module ASKER.
//! let host = Host::builder("my_cell").connect("tcp/10.0.0.1:7447").open().await?;
//! let imported: Imported<u64, u64, usage::Receive> =
//!     import(&host, "DOUBLE", "DOUBLER", "ASKER").await?;
//! let mut asker = imported.port().user_named("ASKER")?;
//! assert_eq!(asker.send(21).await?, 42);
//! # Ok(()) }
//! ```
//!
//! Every usage crosses: ports whose owner receives (each send reaches its `receive`, and
//! the reply comes back); `RESPONSE` ports (a query waits for the owner's response
//! handler, which runs when the owner's order says); and ports whose owner starts each
//! rendezvous — `SENDALL` (a broadcast reaches modules on other hosts, and their replies
//! come back), `CALLALL` (answered by their response handlers) and `QUERY` (the owner asks
//! a module on another host). The restrictions hold across hosts:
//! a module not on the port's user list, or beyond its number of users, is refused when it
//! imports, with the port's own wiring error; the port's TIMEOUT for the module is learnt
//! when it connects, and its local side waits as long.
//!
//! Hosts find each other through the endpoints they are given: one listens, the others
//! connect (peer mode, no multicast scouting, no router needed). A zenoh router is an
//! option: each host connects to it instead. With [`TlsFiles`], hosts connect over mutual
//! TLS, and [`HostBuilder::admit`] lets onto a port's keys only the hosts of its owner and
//! of the modules on its user list, by their certificates' common names.
//!
//! A host that is killed, cut off past its lease ([`Host::DEFAULT_LEASE`], 2 s), or closed
//! is seen gone through zenoh's liveliness tokens: waits on its ports end with `PeerGone`,
//! and a request it had taken and not answered ends with `NoReply` (its reply is lost).
//! When the host comes back and exports again, the same import is served again. A request
//! is asked once, with one zenoh query: while one host exports the port it is never
//! served twice, and its reply reaches only its own sender.
//!
//! # On the wire
//!
//! An outside client speaks to a cell with these keys (module and port names must not
//! hold `/ * $ ? # @` or whitespace):
//!
//! | key | what |
//! |---|---|
//! | `imrs/<cell>/port/<PORT>/<MODULE>` | module `MODULE`'s request: a zenoh query whose payload is the message in CDR (below); the reply's payload is the answer in CDR, or an error reply whose payload is the reason in UTF-8, naming the port |
//! | `imrs/<cell>/connect/<PORT>/<MODULE>` | module `MODULE`'s connection: a query; answered with the owner's name and the port's TIMEOUT in milliseconds (a CDR struct of a string and a `u64`, 0 for none), or an error reply naming the port and the restriction refused |
//! | `imrs/<cell>/live/<PORT>` | a liveliness token, held by the owner's host while it exports the port |
//! | `imrs/<cell>/user/<PORT>/<MODULE>` | a liveliness token, held by a user's host while it imports the port for the module |
//! | `imrs/<cell>/deliver/<PORT>/<MODULE>` | for `SENDALL`, `CALLALL` and `QUERY` ports: the user's host's queryable, where the owner's broadcasts and queries reach the module (attachment: the owner's name), answered with the module's reply in CDR |
//!
//! Messages are [`Message`]s, any `serde` type, in little-endian CDR after the four-byte
//! encapsulation header `00 01 00 00`, as ROS 2 encodes them: a `u64` is that header and
//! its eight bytes. A message is refused, naming the port, if it does not decode, or would
//! be read past [`MAX_MESSAGE`] bytes.

mod access;
mod asking;
mod connected;
mod error;
mod export;
mod forward;
// What reads a peer's bytes, for the fuzz targets in `fuzz/` (`cargo fuzz` sets the cfg).
#[cfg(fuzzing)]
#[doc(hidden)]
pub mod fuzzing;
mod host;
mod import;
mod key;
mod message;
pub mod netns;
mod opening;
mod relay;
mod take;
mod user_watch;
mod watch;

pub use access::TlsFiles;
pub use error::ZenohError;
pub use export::{Export, Exported, export};
pub use host::{Host, HostBuilder};
pub use import::{Import, Imported, import};
pub use message::{MAX_MESSAGE, Message, decode, encode};
pub use user_watch::UserWatch;
