//! Port priorities (Shin 1985, restriction 7).

use std::cmp::Ordering;
use std::fmt;

/// The priority of a port: which ready port a `select` serves first.
///
/// As in the seed's `order` and work schedules, 1 is the most urgent. A port declared with
/// no priority gets [`Priority::DEFAULT`], which is lower than any declared one. Compare with
/// `>`: the greater priority is the more urgent one.
#[derive(Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct Priority(Option<u32>);

impl Priority {
    /// The priority of a port that declares none: below every declared priority.
    pub const DEFAULT: Priority = Priority(None);

    /// `PRIORITY=n`: 1 is the most urgent.
    pub const fn declared(n: u32) -> Self {
        Self(Some(n))
    }

    /// The declared number, if any.
    pub const fn number(self) -> Option<u32> {
        self.0
    }
}

impl Ord for Priority {
    fn cmp(&self, other: &Self) -> Ordering {
        match (self.0, other.0) {
            (None, None) => Ordering::Equal,
            (None, Some(_)) => Ordering::Less,
            (Some(_), None) => Ordering::Greater,
            // Lower numbers are more urgent, so they compare greater.
            (Some(a), Some(b)) => b.cmp(&a),
        }
    }
}

impl PartialOrd for Priority {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl fmt::Debug for Priority {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(n) => write!(f, "PRIORITY={n}"),
            None => f.write_str("PRIORITY=default"),
        }
    }
}
