//! Typed ports and the communication primitives of an integrated multi-robot system, after
//! Shin, *Intertask Communications in an Integrated Multi-Robot System* (1985).
//!
//! Modules talk only through ports. A port is owned by one module and used by others; it
//! carries a request type and a reply type, and its restrictions live where misuse is
//! caught earliest:
//!
//! | restriction | where it is checked |
//! |---|---|
//! | message format | types: `Port<Req, Rep, ..>` |
//! | usage (send, receive, query, response, sendall, callall) | types: an [`End`] has only its usage's methods, and a user's usage is the complement of the owner's |
//! | user list | types ([`user_list!`]) or on attach ([`PortSpec::user_list`]) |
//! | number of active users | const generic `N`, buffers sized once; a user beyond `N` is a [`WireError`] |
//! | filter | [`FilteredPort`]; the [`BoundedBuffer`] of the seed's Appendix ships ready |
//! | timeout | run time, on the framework [`Clock`], on each end it is declared for ([`PortSpec::owner_timeout`], [`PortSpec::user_timeout`]): a typed timeout error |
//! | priority | run time: [`select()`] serves the highest-priority ready port, FIFO within a port; a message's wake carries its port's priority ([`transport::waking`]), which a processor uses to lift the module it wakes |
//! | process type | [`ProcessType::Tight`] ports spin briefly before parking |
//!
//! A send, a receive and a reply between two tasks:
//!
//! ```
//! use imrs_ports::{Port, PortSpec, usage};
//!
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! # let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build()?;
//! # runtime.block_on(async {
//! // CARD_IN_PLACE, owned by LOAD_CARD: it sends, SCREW_IN_CARD receives and replies.
//! let port = Port::<u32, i32, usage::Send>::new(PortSpec::new("CARD_IN_PLACE", "LOAD_CARD"));
//! let mut load_card = port.owner()?;
//! let mut screw_in_card = port.user_named("SCREW_IN_CARD")?;
//!
//! let screwing = tokio::spawn(async move {
//!     let (card, reply) = screw_in_card.receive().await?;
//!     reply.reply(if card > 0 { 0 } else { 1 }); // RC=0: anchored
//!     Ok::<_, imrs_ports::ReceiveError>(())
//! });
//! let rc = load_card.send(7).await?;
//! assert_eq!(rc, 0);
//! screwing.await??;
//! # Ok::<_, Box<dyn std::error::Error>>(())
//! # })?;
//! # Ok(())
//! # }
//! ```
//!
//! The ports here run in one process. The primitives' meaning does not depend on that: a
//! transport across processes plugs in beneath [`End`] without changing module code.

mod attachment;
mod broadcast;
pub mod clock;
mod core;
mod end;
mod error;
pub mod filter;
mod hooks;
mod inline;
mod loom;
mod meta;
mod module_name;
mod name;
mod port;
pub mod post;
mod presence;
mod priority;
mod process_type;
mod pump;
mod receive;
mod response;
pub mod select;
pub mod shared;
pub mod shown;
mod slot;
pub mod synchronous;
pub mod transport;
mod urgency;
pub mod usage;
mod user_list;
mod wiring;

pub use broadcast::{Broadcast, Broadcasting};
pub use clock::{Clock, Instant, RealClock, SharedClock, VirtualClock};
pub use end::End;
pub use error::{BroadcastError, ClaimRefused, QueryError, ReceiveError, SendError, WireError};
pub use filter::{BoundedBuffer, BoundedBufferPort, FilterEnds, FilteredPort};
pub use meta::{Name, Named};
pub use module_name::Module;
pub use port::{Handler, Port, PortSpec};
pub use priority::Priority;
pub use process_type::ProcessType;
pub use receive::{Receiving, Replied, ReplyHandle};
pub use response::{ModuleState, Respond, ResponseEnd, Served, respond_while};
pub use select::{AllClosed, Select, select, when};
pub use shared::{LoanError, Shared};
pub use shown::Shown;
pub use usage::UsageKind;
pub use user_list::{Admits, AnyUser, UserList};
pub use wiring::{PortInfo, WireErrors, Wiring};

/// Everything a module author needs, in one import.
pub mod prelude {
    pub use crate::{
        AnyUser, BoundedBuffer, BoundedBufferPort, Clock, End, FilteredPort, Module, ModuleState,
        Named, Port, PortSpec, Priority, ProcessType, ReplyHandle, ResponseEnd, VirtualClock,
        select, usage, user_list, when,
    };
}
