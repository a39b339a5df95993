//! What can go wrong across hosts. Every error names the port, or the name refused.

use std::fmt;

/// Why a host could not be opened, or a port exported or imported.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ZenohError {
    /// A cell, port or module name that cannot be part of a key expression.
    BadName {
        /// What the name is of: "cell", "port" or "module".
        what: &'static str,
        /// The name.
        name: String,
    },
    /// An endpoint zenoh does not accept, or a session that could not be opened.
    Session {
        /// What zenoh said.
        reason: String,
    },
    /// No host answered the port's connection in time: nobody exports it, or this host is
    /// not admitted to it.
    NoOwner {
        /// The port.
        port: String,
    },
    /// The owner's host refused the connection: the port's own wiring error (not on the
    /// user list, too many users) or a declaration that does not match.
    Refused {
        /// The port.
        port: String,
        /// The owner's host's reason, naming the port.
        reason: String,
    },
    /// A port this host does not admit, on a host that admits ports: every port that crosses
    /// to or from it must be ([`HostBuilder::admit`](crate::HostBuilder::admit)).
    NotAdmitted {
        /// The port.
        port: String,
    },
    /// A module this host does not admit to a port it admits
    /// ([`HostBuilder::admit`](crate::HostBuilder::admit)).
    ModuleNotAdmitted {
        /// The port.
        port: String,
        /// The module.
        module: String,
    },
    /// A module watched as a port's user that is not on the port's user list: no host can
    /// import the port for it ([`Exported::watch_user`](crate::Exported::watch_user)).
    NotAUser {
        /// The port.
        port: String,
        /// The module.
        module: String,
    },
    /// A message that could not be encoded, or bytes that are not the port's message.
    Encoding {
        /// The port.
        port: String,
        /// Why.
        reason: String,
    },
}

impl fmt::Display for ZenohError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadName { what, name } => write!(
                f,
                "{what} name {name:?} cannot cross hosts: it must be non-empty, not start with \
                 @, and hold none of / * $ ? # \" \\ or whitespace"
            ),
            Self::Session { reason } => write!(f, "zenoh session: {reason}"),
            Self::NoOwner { port } => {
                write!(
                    f,
                    "port {port}: no host answered this host's connection (nobody exports it, \
                     or this host is not admitted to it)"
                )
            }
            Self::Refused { port, reason } => {
                write!(f, "port {port}: its owner's host refused: {reason}")
            }
            Self::NotAdmitted { port } => write!(
                f,
                "port {port} is not admitted on this host, which admits ports: admit it \
                 (HostBuilder::admit) on its owner's host and on each of its users'"
            ),
            Self::ModuleNotAdmitted { port, module } => write!(
                f,
                "module {module} is not admitted to port {port} on this host: admit it with \
                 its host (HostBuilder::admit) on the port's owner's host and on its own"
            ),
            Self::NotAUser { port, module } => write!(
                f,
                "module {module} is not on the user list of port {port}: no host can import \
                 the port for it, so there is nothing to watch"
            ),
            Self::Encoding { port, reason } => write!(f, "port {port}: {reason}"),
        }
    }
}

impl std::error::Error for ZenohError {}

impl ZenohError {
    pub(crate) fn session(error: impl fmt::Display) -> Self {
        Self::Session {
            reason: error.to_string(),
        }
    }
}
