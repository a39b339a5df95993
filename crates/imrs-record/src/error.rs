//! What can go wrong making or reading a recording.

use std::fmt;
use std::path::PathBuf;

/// A recording could not be made, finished or read.
#[derive(Debug)]
#[non_exhaustive]
pub enum RecordError {
    /// The file could not be created or written.
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said.
        error: std::io::Error,
    },
    /// The MCAP writer refused.
    Write {
        /// The file.
        path: PathBuf,
        /// What the writer said.
        error: String,
    },
    /// The file is not a whole MCAP recording.
    Corrupt {
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        error: String,
    },
    /// The picture could not be drawn.
    Draw {
        /// The file.
        path: PathBuf,
        /// What the plotting backend said.
        error: String,
    },
}

impl fmt::Display for RecordError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Io { path, error } => write!(f, "{}: {error}", path.display()),
            Self::Write { path, error } => {
                write!(f, "{}: the MCAP writer failed: {error}", path.display())
            }
            Self::Corrupt { path, error } => write!(
                f,
                "{}: not a readable MCAP recording (truncated or corrupt?): {error}",
                path.display()
            ),
            Self::Draw { path, error } => {
                write!(
                    f,
                    "{}: the timeline could not be drawn: {error}",
                    path.display()
                )
            }
        }
    }
}

impl std::error::Error for RecordError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Self::Io { error, .. } => Some(error),
            _ => None,
        }
    }
}
