//! A module's name as a message that can cross processes: how a chip robot's words to the
//! feeder zone's keeper ([`ZoneAsker`](crate::zone_asker::ZoneAsker),
//! [`Reservation`](crate::reservation::Reservation)) name it. Apart, so that those words need
//! not reach into the ports that carry them.

use std::fmt;

use imrs_ipc::{FromBytes, ZeroCopySend};
use serde::{Deserialize, Serialize};

/// The longest module name a [`ModuleName`] holds.
const MODULE_NAME: usize = 32;

/// A module's name as a message that can cross processes: fixed-size and self-contained.
#[derive(Clone, Copy, Default, PartialEq, Eq, ZeroCopySend, FromBytes, Serialize, Deserialize)]
#[repr(C)]
#[type_name("cell_example::ModuleName")]
pub struct ModuleName {
    len: u32,
    bytes: [u8; MODULE_NAME],
}

impl ModuleName {
    /// `name`, cut to its first 32 bytes (at a character's boundary).
    pub fn new(name: &str) -> Self {
        let mut len = name.len().min(MODULE_NAME);
        while !name.is_char_boundary(len) {
            len -= 1;
        }
        let mut bytes = [0; MODULE_NAME];
        bytes[..len].copy_from_slice(&name.as_bytes()[..len]);
        Self {
            len: len as u32,
            bytes,
        }
    }

    /// The name; empty if a peer wrote a record that is not one.
    pub fn as_str(&self) -> &str {
        let len = usize::try_from(self.len).unwrap_or(usize::MAX);
        self.bytes
            .get(..len)
            .and_then(|bytes| std::str::from_utf8(bytes).ok())
            .unwrap_or("")
    }
}

impl fmt::Debug for ModuleName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.as_str(), f)
    }
}

impl fmt::Display for ModuleName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}
