//! Errors of synchronous ports. Each names the end it happened on; a failed write hands the
//! value back.

use std::error::Error;
use std::fmt;

use crate::meta::Name;

/// Why a [`read`](super::Input::read) failed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ReadError {
    /// The input itself was closed.
    Closed {
        /// The instance that owns the input.
        owner: Name,
        /// The input.
        port: Name,
    },
    /// Every output connected to the input is closed and nothing is left to read.
    Disconnected {
        /// The instance that owns the input.
        owner: Name,
        /// The input.
        port: Name,
    },
}

impl fmt::Display for ReadError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Closed { owner, port } => write!(f, "input {owner}({port}) is closed"),
            Self::Disconnected { owner, port } => write!(
                f,
                "input {owner}({port}): every connected output is closed and nothing is left to read"
            ),
        }
    }
}

impl Error for ReadError {}

/// Why a [`write`](super::Output::write) failed; the value comes back.
pub enum WriteError<T> {
    /// The output itself was closed.
    Closed {
        /// The instance that owns the output.
        owner: Name,
        /// The output.
        port: Name,
        /// The value, unread.
        value: T,
    },
    /// Every input connected to the output is closed before one read the value.
    Disconnected {
        /// The instance that owns the output.
        owner: Name,
        /// The output.
        port: Name,
        /// The value, unread.
        value: T,
    },
}

impl<T> WriteError<T> {
    /// The value that was not read.
    pub fn into_value(self) -> T {
        match self {
            Self::Closed { value, .. } | Self::Disconnected { value, .. } => value,
        }
    }
}

impl<T> fmt::Debug for WriteError<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

impl<T> fmt::Display for WriteError<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Closed { owner, port, .. } => write!(f, "output {owner}({port}) is closed"),
            Self::Disconnected { owner, port, .. } => write!(
                f,
                "output {owner}({port}): every connected input closed before one read the value"
            ),
        }
    }
}

impl<T> Error for WriteError<T> {}

/// Why a connection made by name was refused. Names both ends.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ConnectError {
    /// The two ends carry different types.
    Types {
        /// The output, as `INSTANCE(PORT)`.
        output: String,
        /// The output's message type.
        output_type: &'static str,
        /// The input, as `INSTANCE(PORT)`.
        input: String,
        /// The input's message type.
        input_type: &'static str,
    },
    /// An end was given where the other direction was needed.
    Direction {
        /// The end, as `INSTANCE(PORT)`.
        port: String,
        /// What the connection needed there.
        expected: super::Direction,
    },
}

impl fmt::Display for ConnectError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Types {
                output,
                output_type,
                input,
                input_type,
            } => write!(
                f,
                "cannot connect {output} to {input}: {output} writes {output_type}, {input} reads {input_type}"
            ),
            Self::Direction { port, expected } => {
                write!(f, "cannot connect {port}: it is not an {expected} port")
            }
        }
    }
}

impl Error for ConnectError {}
