//! What can go wrong in a schema network. Every error names the instance, and a connection
//! error names both ends.

use std::fmt;

use imrs_ports::Name;
use imrs_ports::synchronous::{ConnectError, ReadError, WriteError};
use imrs_sim::hand::HandError;

/// Why an instantiation, a connection or a behaviour failed.
#[derive(Debug, Clone, PartialEq)]
pub enum SchemaError {
    /// An explicit instance number already in use in this assemblage.
    InstanceExists {
        /// The assemblage, `/` for the network's top.
        assemblage: String,
        /// The schema.
        schema: &'static str,
        /// The number asked for.
        number: u32,
    },
    /// Instance numbers start at 1.
    ZeroInstance {
        /// The schema.
        schema: &'static str,
    },
    /// A port name the instance does not have.
    NoPort {
        /// The instance.
        instance: Name,
        /// The name asked for.
        port: String,
    },
    /// A connection refused: different types, or the wrong direction.
    Connect(ConnectError),
    /// A read failed.
    Read(ReadError),
    /// A write failed (the value is dropped).
    Write {
        /// The instance that wrote.
        owner: Name,
        /// Its output.
        port: Name,
        /// Why.
        reason: String,
    },
    /// The hand refused a joint or sensor number.
    Hand {
        /// The instance that asked.
        instance: Name,
        /// What the hand said.
        error: HandError,
    },
    /// A behaviour's own failure.
    Failed {
        /// The instance.
        instance: Name,
        /// Why.
        reason: String,
    },
}

impl fmt::Display for SchemaError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::InstanceExists {
                assemblage,
                schema,
                number,
            } => write!(
                f,
                "{schema}_{number} already exists in assemblage {assemblage}"
            ),
            Self::ZeroInstance { schema } => {
                write!(f, "{schema}_0: instance numbers start at 1")
            }
            Self::NoPort { instance, port } => write!(f, "{instance} has no port {port}"),
            Self::Connect(error) => error.fmt(f),
            Self::Read(error) => error.fmt(f),
            Self::Write {
                owner,
                port,
                reason,
            } => write!(f, "write on {owner}({port}) failed: {reason}"),
            Self::Hand { instance, error } => write!(f, "{instance}: {error}"),
            Self::Failed { instance, reason } => write!(f, "{instance} failed: {reason}"),
        }
    }
}

impl std::error::Error for SchemaError {}

impl From<ConnectError> for SchemaError {
    fn from(error: ConnectError) -> Self {
        Self::Connect(error)
    }
}

impl From<ReadError> for SchemaError {
    fn from(error: ReadError) -> Self {
        Self::Read(error)
    }
}

impl<T> From<WriteError<T>> for SchemaError {
    fn from(error: WriteError<T>) -> Self {
        let reason = error.to_string();
        let (WriteError::Closed { owner, port, .. } | WriteError::Disconnected { owner, port, .. }) =
            error;
        Self::Write {
            owner,
            port,
            reason,
        }
    }
}
