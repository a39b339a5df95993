//! What crosses: the message types, the headers beside them, and the services' names.

use std::fmt::Debug;

use iceoryx2::prelude::*;
use zerocopy::FromBytes;

use crate::IpcError;

/// A message that can cross processes: `#[repr(C)]`, self-contained (no `Vec`, `String` or
/// reference), and `ZeroCopySend`, so that it can lie in shared memory and be read in place
/// by another process; and `FromBytes` — every bit pattern is one of its values (no `bool`,
/// `char` or enum) — so that whatever a peer writes into a sample is read as a value, never
/// as undefined behaviour: a message that makes no sense is the receiver's to refuse.
/// `Default` gives the bridge a value for its own handshake.
#[diagnostic::on_unimplemented(
    message = "`{Self}` cannot cross processes",
    label = "not a message an IPC port can carry",
    note = "an IPC port's messages lie in shared memory, written by another process: make \
            the type #[repr(C)], self-contained (no Vec, String, Box or reference), of \
            fields valid for any bits (no bool, char or enum), Copy and Default, and \
            #[derive(ZeroCopySend, FromBytes)]"
)]
pub trait Wire: ZeroCopySend + FromBytes + Copy + Default + Debug + Send + Sync + 'static {}

impl<T: ZeroCopySend + FromBytes + Copy + Default + Debug + Send + Sync + 'static> Wire for T {}

/// What a request is for.
pub(crate) const CONNECT: u32 = 1;
pub(crate) const SEND: u32 = 2;

/// The longest module name that crosses.
pub(crate) const MODULE_NAME: usize = 64;

/// Beside each request: what it is for, and the module it comes from.
#[derive(Debug, Clone, Copy, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("imrs_ipc::RequestMeta")]
pub(crate) struct RequestMeta {
    pub(crate) kind: u32,
    pub(crate) module_len: u32,
    pub(crate) module: [u8; MODULE_NAME],
}

impl Default for RequestMeta {
    fn default() -> Self {
        Self {
            kind: 0,
            module_len: 0,
            module: [0; MODULE_NAME],
        }
    }
}

impl RequestMeta {
    pub(crate) fn new(kind: u32, module: &str) -> Self {
        let mut meta = Self {
            kind,
            ..Self::default()
        };
        let bytes = module.as_bytes();
        let len = bytes.len().min(MODULE_NAME);
        meta.module[..len].copy_from_slice(&bytes[..len]);
        meta.module_len = len as u32;
        meta
    }

    /// The module's name; `None` if the header is malformed (a length past the buffer, or
    /// bytes that are not UTF-8) — a peer that wrote garbage.
    pub(crate) fn module(&self) -> Option<&str> {
        let len = usize::try_from(self.module_len).ok()?;
        std::str::from_utf8(self.module.get(..len)?).ok()
    }
}

/// Beside each reply: how the request went.
#[derive(Debug, Clone, Copy, Default, ZeroCopySend, FromBytes)]
#[repr(C)]
#[type_name("imrs_ipc::ReplyMeta")]
pub(crate) struct ReplyMeta {
    pub(crate) status: u32,
    /// For a refused connection: the port's capacity, where it matters; for an accepted
    /// one, how the port waits ([`TIGHT`] or not).
    pub(crate) detail: u32,
}

/// Statuses of a reply.
pub(crate) const OK: u32 = 0;
pub(crate) const NOT_ON_USER_LIST: u32 = 1;
pub(crate) const TOO_MANY_USERS: u32 = 2;
pub(crate) const REFUSED: u32 = 3;
pub(crate) const MALFORMED: u32 = 4;
pub(crate) const NO_REPLY: u32 = 5;
/// The module's name would be one more than the owner's process keeps from peers; the
/// detail is that number.
pub(crate) const TOO_MANY_NAMES: u32 = 6;

/// In the answer to a connection: the owner declared the port TIGHT.
pub(crate) const TIGHT: u32 = 1;

/// Where a cell's ports cross: the cell's name, from which every service name is derived, so
/// that two cells on one host never meet.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Remote {
    cell: String,
}

impl Remote {
    /// The ports of cell `cell`. Refused if the name cannot be part of a service name.
    pub fn new(cell: &str) -> Result<Self, IpcError> {
        let valid = !cell.is_empty()
            && cell
                .chars()
                .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'));
        if !valid {
            return Err(IpcError::BadName {
                name: cell.into(),
                why: "a cell's name is letters, digits, '_', '-' and '.'".into(),
            });
        }
        Ok(Self { cell: cell.into() })
    }

    /// The cell's name.
    pub fn cell(&self) -> &str {
        &self.cell
    }

    /// The service carrying port `port`'s requests and replies, or one of its events.
    pub(crate) fn service(&self, port: &str, part: &str) -> Result<ServiceName, IpcError> {
        let name = format!("imrs/{}/{port}/{part}", self.cell);
        ServiceName::new(&name).map_err(|error| IpcError::BadName {
            name,
            why: format!("{error:?}"),
        })
    }
}
