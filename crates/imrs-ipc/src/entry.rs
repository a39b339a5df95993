//! The transport's two entry points, [`export`] and [`import`]: one each, whatever the port.
//!
//! How a port crosses processes depends on its usage (who starts each rendezvous) and on
//! its messages (values copied across, or [`Shared`] messages built in place in shared
//! memory). Both are in the port's type, so the type chooses: the owner's process exports
//! its `Port`, and a user's process imports an [`Imported`] of the same usage and message
//! kind. A port of a usage or a message kind that cannot cross does not compile.

use imrs_ports::{Port, Shared, UserList, usage};

use crate::export::exported::Exported;
use crate::import::Imported;
use crate::{IpcError, Remote, Wire};

/// A port its owner's process can export: every usage, of [`Wire`] values or of
/// [`Shared`] wire messages. `W` is the pair of wire types, found from the port's type.
#[diagnostic::on_unimplemented(
    message = "`{Self}` cannot cross processes",
    label = "not a port whose messages an IPC port can carry",
    note = "a port crosses processes when its request and reply are both `Wire` values, or \
            both `Shared` messages of `Wire` types: #[repr(C)], self-contained, valid for any \
            bits, Copy and Default, deriving ZeroCopySend and FromBytes"
)]
pub trait Export<W>: sealed::Exports<W> {}

/// A port a user's process can import: an [`Imported`] of any usage, of [`Wire`] values or
/// of [`Shared`] wire messages. `W` is the pair of wire types, found from its type.
#[diagnostic::on_unimplemented(
    message = "`{Self}` cannot be imported across processes",
    label = "not a port whose messages an IPC port can carry",
    note = "import an `Imported<Req, Rep, Usage>` whose request and reply are both `Wire` \
            values, or both `Shared` messages of `Wire` types"
)]
pub trait Import<W>: sealed::Imports<W> {}

/// Exports `port` to the other processes of `remote`'s cell, for their modules to use as
/// its users: their sends, queries and answers to its broadcasts come and go as in one
/// process. The port's type chooses how it crosses: its usage, and whether its messages are
/// values or [`Shared`] messages read in place. Call it within the tokio runtime the cell
/// runs on. Refused if another process already exports the port, or if the processes
/// disagree on its types.
pub fn export<P: Export<W>, W>(remote: &Remote, port: &P) -> Result<Exported, IpcError> {
    port.export_to(remote)
}

/// Imports port `port`, owned by module `owner` in another process of `remote`'s cell, for
/// module `module` of this one. The [`Imported`] asked for chooses how it crosses: its usage
/// (the owner's, as the port was declared) and message kind must be the exporter's.
/// Connects at once: refused with the port's own wiring error if `module` is not on its
/// user list or the port has no room for it, and with [`IpcError::TypeMismatch`] if the
/// processes disagree on its types. Call it within the tokio runtime the cell runs on.
///
/// ```no_run
/// # use imrs_ipc::{Imported, Remote};
/// # use imrs_ports::usage;
/// # fn main() -> Result<(), imrs_ipc::IpcError> {
/// let remote = Remote::new("CELL")?;
/// // STATUS, a RESPONSE port of ROBOT's process, queried by this process's ASKER.
/// let status: Imported<u32, u64, usage::Response> =
///     imrs_ipc::import(&remote, "STATUS", "ROBOT", "ASKER")?;
/// # Ok(())
/// # }
/// ```
pub fn import<I: Import<W>, W>(
    remote: &Remote,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<I, IpcError> {
    I::import_from(remote, port, owner, module)
}

mod sealed {
    use super::*;

    pub trait Exports<W> {
        fn export_to(&self, remote: &Remote) -> Result<Exported, IpcError>;
    }

    pub trait Imports<W>: Sized {
        fn import_from(
            remote: &Remote,
            port: &str,
            owner: &str,
            module: &str,
        ) -> Result<Self, IpcError>;
    }

    /// One impl of each trait per usage and message kind, naming the function that carries it.
    macro_rules! crossing {
        ($usage:ty, values: $export:path, $import:path; shared: $export_shared:path, $import_shared:path) => {
            impl<Req: Wire, Rep: Wire, L: UserList, const N: usize> Exports<(Req, Rep)>
                for Port<Req, Rep, $usage, L, N>
            {
                fn export_to(&self, remote: &Remote) -> Result<Exported, IpcError> {
                    $export(remote, self)
                }
            }
            impl<Req: Wire, Rep: Wire, L: UserList, const N: usize> Export<(Req, Rep)>
                for Port<Req, Rep, $usage, L, N>
            {
            }
            impl<Req: Wire, Rep: Wire, L: UserList, const N: usize> Exports<(Req, Rep)>
                for Port<Shared<Req>, Shared<Rep>, $usage, L, N>
            {
                fn export_to(&self, remote: &Remote) -> Result<Exported, IpcError> {
                    $export_shared(remote, self)
                }
            }
            impl<Req: Wire, Rep: Wire, L: UserList, const N: usize> Export<(Req, Rep)>
                for Port<Shared<Req>, Shared<Rep>, $usage, L, N>
            {
            }
            impl<Req: Wire, Rep: Wire> Imports<(Req, Rep)> for Imported<Req, Rep, $usage> {
                fn import_from(
                    remote: &Remote,
                    port: &str,
                    owner: &str,
                    module: &str,
                ) -> Result<Self, IpcError> {
                    $import(remote, port, owner, module)
                }
            }
            impl<Req: Wire, Rep: Wire> Import<(Req, Rep)> for Imported<Req, Rep, $usage> {}
            impl<Req: Wire, Rep: Wire> Imports<(Req, Rep)>
                for Imported<Shared<Req>, Shared<Rep>, $usage>
            {
                fn import_from(
                    remote: &Remote,
                    port: &str,
                    owner: &str,
                    module: &str,
                ) -> Result<Self, IpcError> {
                    $import_shared(remote, port, owner, module)
                }
            }
            impl<Req: Wire, Rep: Wire> Import<(Req, Rep)>
                for Imported<Shared<Req>, Shared<Rep>, $usage>
            {
            }
        };
    }

    crossing!(usage::Receive,
        values: crate::export::export, crate::import::import;
        shared: crate::export::export_shared, crate::import::import_shared);
    crossing!(usage::Response,
        values: crate::export::export_response, crate::import::import_response;
        shared: crate::export::export_response_shared, crate::import::import_response_shared);
    crossing!(usage::SendAll,
        values: crate::send_all::export_send_all, crate::send_all::import_send_all;
        shared: crate::send_all::export_send_all_shared, crate::send_all::import_send_all_shared);
    crossing!(usage::CallAll,
        values: crate::send_all::export_call_all, crate::send_all::import_call_all;
        shared: crate::send_all::export_call_all_shared, crate::send_all::import_call_all_shared);
    crossing!(usage::Query,
        values: crate::send_all::export_query, crate::send_all::import_query;
        shared: crate::send_all::export_query_shared, crate::send_all::import_query_shared);
}
