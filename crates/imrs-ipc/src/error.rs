//! What can go wrong across processes; every error names the port.

use std::fmt;

use imrs_ports::{Name, WireError};

/// Why a port could not cross processes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum IpcError {
    /// The cell or port name cannot name an iceoryx2 service.
    BadName {
        /// The name.
        name: String,
        /// Why.
        why: String,
    },
    /// The two processes disagree on the port's message types (name, size or alignment).
    TypeMismatch {
        /// The port.
        port: Name,
        /// What iceoryx2 said.
        detail: String,
    },
    /// The owner refused the importing module: the port's own wiring error.
    Refused(WireError),
    /// No owner answered within the time allowed.
    NoOwner {
        /// The port.
        port: Name,
    },
    /// iceoryx2 failed: what it was doing, for which port, and what it said.
    Transport {
        /// The port.
        port: Name,
        /// What failed.
        detail: String,
    },
    /// The local side of the port could not be wired.
    Local(WireError),
}

impl fmt::Display for IpcError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadName { name, why } => write!(f, "{name:?} cannot name a service: {why}"),
            Self::TypeMismatch { port, detail } => write!(
                f,
                "port {port}: the processes disagree on its message types ({detail})"
            ),
            Self::Refused(error) => write!(f, "refused by the port's owner: {error}"),
            Self::NoOwner { port } => write!(f, "port {port}: no owner process answered"),
            Self::Transport { port, detail } => write!(f, "port {port}: {detail}"),
            Self::Local(error) => write!(f, "{error}"),
        }
    }
}

impl std::error::Error for IpcError {}
