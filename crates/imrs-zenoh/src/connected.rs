//! The owner's host's answer to a module's connection.

use serde::{Deserialize, Serialize};

/// What a module learns when it connects to a port: who owns it, and the port's TIMEOUT
/// for the module, so that its side of the port waits as long as the owner's side would.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub(crate) struct Connected {
    /// The module that owns the port.
    pub(crate) owner: String,
    /// The port's TIMEOUT for the connecting module in milliseconds; 0 for none.
    pub(crate) timeout_ms: u64,
}
