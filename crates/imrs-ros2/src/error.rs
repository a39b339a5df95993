//! What can go wrong between a cell and ROS 2.

use std::fmt;

/// An error of the ROS 2 side of a cell, naming what it is about.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Ros2Error {
    /// A name ROS 2 would refuse.
    Name {
        /// What the name is of: "node name", "namespace", "topic or service name".
        what: &'static str,
        /// The name.
        name: String,
        /// What ROS 2 allows.
        rule: &'static str,
    },
    /// A port refused the bridge (off its user list, no room, its owner gone).
    Wiring {
        /// The port.
        port: String,
        /// Its refusal.
        reason: String,
    },
    /// zenoh refused or failed something on `what` (a topic, a service, the node).
    Zenoh {
        /// What it was about.
        what: String,
        /// zenoh's word.
        reason: String,
    },
}

impl Ros2Error {
    pub(crate) fn name(what: &'static str, name: &str) -> Self {
        Self::Name {
            what,
            name: name.to_owned(),
            rule: "parts of [A-Za-z_][A-Za-z0-9_]* joined by '/'",
        }
    }

    pub(crate) fn wiring(port: impl fmt::Display, reason: impl fmt::Display) -> Self {
        Self::Wiring {
            port: port.to_string(),
            reason: reason.to_string(),
        }
    }

    pub(crate) fn zenoh(what: &str, reason: impl fmt::Display) -> Self {
        Self::Zenoh {
            what: what.to_owned(),
            reason: reason.to_string(),
        }
    }
}

impl fmt::Display for Ros2Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Ros2Error::Name { what, name, rule } => {
                write!(f, "{what} {name:?} is not a ROS 2 name: {rule}")
            }
            Ros2Error::Wiring { port, reason } => {
                write!(f, "port {port} cannot be bridged to ROS 2: {reason}")
            }
            Ros2Error::Zenoh { what, reason } => write!(f, "{what}: {reason}"),
        }
    }
}

impl std::error::Error for Ros2Error {}
