//! How a port's messages and replies read in a cell's event log and recordings.
//!
//! A port says how its values are shown once, when it is declared ([`Port::shown`] for
//! types that are `Debug`, [`Port::shown_with`] otherwise); a module's primitives then put
//! the text beside each operation in the event log — but only while the cell asks for it
//! (a recorder does), so that a cell nobody records formats nothing.
//!
//! [`Port::shown`]: crate::Port::shown
//! [`Port::shown_with`]: crate::Port::shown_with

use std::fmt;

/// How a port's messages (`Req`) and replies (`Rep`) are shown.
pub struct Shown<Req, Rep> {
    /// The text of a message.
    pub request: fn(&Req) -> String,
    /// The text of a reply.
    pub reply: fn(&Rep) -> String,
}

impl<Req: fmt::Debug, Rep: fmt::Debug> Shown<Req, Rep> {
    /// Both as `Debug` writes them.
    pub fn debug() -> Self {
        Self {
            request: debug::<Req>,
            reply: debug::<Rep>,
        }
    }
}

fn debug<T: fmt::Debug>(value: &T) -> String {
    format!("{value:?}")
}

// By hand: the derives would ask `Req` and `Rep` to be `Clone` and `Debug` themselves.
impl<Req, Rep> Clone for Shown<Req, Rep> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<Req, Rep> Copy for Shown<Req, Rep> {}

impl<Req, Rep> fmt::Debug for Shown<Req, Rep> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Shown").finish_non_exhaustive()
    }
}
