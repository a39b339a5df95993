//! Names of ports, modules, tasks and sections: interned, so that copying and comparing one
//! costs no more than a pointer.
//!
//! The paths that run at every message — the event log, the deadlock diagnosis, a port's
//! errors — copy and compare names. A reference-counted string would make each copy an
//! atomic read-modify-write on a line shared by every thread that names the same module;
//! an interned name is a `&'static str`, copied for free and compared by address.
//!
//! The cost: each distinct name is kept for the life of the process. Name modules, ports and
//! sections by role (`CHIP_IT`, `SHARE_FEEDER`), as the seed does, not by part or time: a cell
//! that makes a new name per pallet would keep every one.
//!
//! Text a peer sends is made a name only once a port accepts it ([`Port::claim`]), and at
//! most [`Name::MOST_FROM_PEERS`] names are first made that way: a peer that claims a new
//! name at every connection, on a port without a user list, is refused by name once that
//! many are kept, instead of growing its owner for ever. Names on user lists are made when
//! the port is declared, so they are never refused.
//!
//! [`Port::claim`]: crate::Port::claim

use std::cmp::Ordering;
use std::collections::HashSet;
use std::fmt;
use std::hash::{Hash, Hasher};
use std::sync::{OnceLock, PoisonError, RwLock};

/// A port's or a module's name: cloned by copying a pointer, compared by address.
#[derive(Clone)]
pub struct Name(&'static str);

/// Every name made so far, and how many of them were first made from a peer's text.
#[derive(Default)]
struct Interned {
    names: HashSet<&'static str>,
    from_peers: usize,
}

fn interned() -> &'static RwLock<Interned> {
    static INTERNED: OnceLock<RwLock<Interned>> = OnceLock::new();
    INTERNED.get_or_init(RwLock::default)
}

impl Name {
    /// The most names a process makes from peers' text: see the module's documentation.
    pub const MOST_FROM_PEERS: usize = 4096;

    /// The name `text`, the same `Name` for the same text wherever it is made.
    fn intern(text: &str) -> Self {
        Self::made(text, false).unwrap_or_else(|| unreachable!("only a peer's name is refused"))
    }

    /// The name `text` from a peer, made if it is new and fewer than
    /// [`MOST_FROM_PEERS`](Self::MOST_FROM_PEERS) names have been made from peers' text;
    /// `None` if it would be one too many.
    pub(crate) fn from_peer(text: &str) -> Option<Self> {
        Self::made(text, true)
    }

    fn made(text: &str, from_peer: bool) -> Option<Self> {
        // Each critical section is one lookup, or one check and insert: a panic cannot leave
        // the set half-changed.
        if let Some(known) = Self::known(text) {
            return Some(known);
        }
        let mut interned = interned().write().unwrap_or_else(PoisonError::into_inner);
        if let Some(known) = interned.names.get(text) {
            return Some(Self(known));
        }
        if from_peer {
            if interned.from_peers >= Self::MOST_FROM_PEERS {
                return None;
            }
            interned.from_peers += 1;
        }
        let kept: &'static str = Box::leak(text.into());
        interned.names.insert(kept);
        Some(Self(kept))
    }

    /// The name `text`, if it has been made already; never keeps a new one. For text from
    /// outside the process (a peer's message), which is kept only once it is accepted.
    pub fn known(text: &str) -> Option<Self> {
        interned()
            .read()
            .unwrap_or_else(PoisonError::into_inner)
            .names
            .get(text)
            .map(|known| Self(known))
    }

    /// The name as text.
    pub fn as_str(&self) -> &'static str {
        self.0
    }

    /// A number that stands for this name, never 0: for a record that must be written with
    /// one atomic store and read by another thread, such as the port a module's thread
    /// waits on. [`Name::from_token`] gives the name back. One text, one token, for the
    /// life of the process.
    #[inline]
    pub fn token(&self) -> usize {
        // Each name is its own leaked allocation, so its address is its own; an empty
        // text's dangling address is still not 0.
        self.0.as_ptr() as usize
    }

    /// The name whose [`token`](Name::token) is `token`, if any name has it. It looks
    /// through every name made so far, so that names cost no room for it: for a rare reader,
    /// such as a report of a deadlock.
    pub fn from_token(token: usize) -> Option<Self> {
        interned()
            .read()
            .unwrap_or_else(PoisonError::into_inner)
            .names
            .iter()
            .find(|known| known.as_ptr() as usize == token)
            .map(|known| Self(known))
    }
}

impl PartialEq for Name {
    fn eq(&self, other: &Self) -> bool {
        // Interned: one text, one address.
        std::ptr::eq(self.0, other.0)
    }
}

impl Eq for Name {}

impl Hash for Name {
    fn hash<H: Hasher>(&self, state: &mut H) {
        self.0.hash(state);
    }
}

impl Ord for Name {
    /// By text, so that whatever is sorted by name reads in the same order in every run.
    fn cmp(&self, other: &Self) -> Ordering {
        if self == other {
            return Ordering::Equal;
        }
        self.0.cmp(other.0)
    }
}

impl PartialOrd for Name {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl From<&str> for Name {
    fn from(name: &str) -> Self {
        Self::intern(name)
    }
}

impl From<String> for Name {
    fn from(name: String) -> Self {
        Self::intern(&name)
    }
}

impl fmt::Display for Name {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.0)
    }
}

impl fmt::Debug for Name {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Debug::fmt(self.0, f)
    }
}

impl PartialEq<str> for Name {
    fn eq(&self, other: &str) -> bool {
        self.0 == other
    }
}

impl PartialEq<&str> for Name {
    fn eq(&self, other: &&str) -> bool {
        self.0 == *other
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_text_is_one_name_however_it_was_made() {
        let made = format!("{}_{}", "SHARE", "FEEDER");
        let a = Name::from("SHARE_FEEDER");
        let b = Name::from(made);
        assert_eq!(a, b);
        assert!(std::ptr::eq(a.as_str(), b.as_str()));
        assert_ne!(a, Name::from("SHARE_FEEDER1"));
        let (a, b) = (Name::from("A"), Name::from("B"));
        assert_eq!(a.cmp(&b), Ordering::Less);
    }

    #[test]
    fn a_token_gives_its_name_back() {
        let name = Name::from("TOKEN_OF_A_PORT");
        assert_ne!(name.token(), 0);
        assert_eq!(Name::from_token(name.token()), Some(name.clone()));
        assert_eq!(
            Name::from(String::from("TOKEN_OF_A_PORT")).token(),
            name.token()
        );
        assert_ne!(Name::from("TOKEN_OF_ANOTHER").token(), name.token());
        assert_eq!(Name::from_token(0), None);
        assert_eq!(Name::from_token(name.token() + 1), None);
    }

    #[test]
    fn a_name_looked_up_is_not_kept() {
        assert_eq!(Name::known("NEVER_MADE_BY_ANYONE"), None);
        assert_eq!(Name::known("NEVER_MADE_BY_ANYONE"), None);
        let made = Name::from("MADE_ONCE");
        assert_eq!(Name::known("MADE_ONCE"), Some(made));
    }

    #[test]
    fn names_made_on_many_threads_at_once_agree() {
        let names: Vec<Name> = std::thread::scope(|scope| {
            let makers: Vec<_> = (0..8)
                .map(|_| scope.spawn(|| Name::from(String::from("RACED_NAME"))))
                .collect();
            makers
                .into_iter()
                .map(|maker| maker.join().unwrap())
                .collect()
        });
        assert!(names.windows(2).all(|pair| pair[0] == pair[1]));
    }
}
