//! The `order` statement (seed 000, §5.1): a module's ranking of its sections.

use std::fmt;

use imrs_ports::Name;

/// A place in a module's order. Rank 1 is the most urgent; a smaller rank outranks a larger.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Rank(u32);

impl Rank {
    /// The rank of a response or exception handler that the order does not name: it may run
    /// at any suspension point, as it would in a module without an order.
    pub const UNRANKED_HANDLER: Rank = Rank(0);

    /// The rank at `position` (1-based) in an order.
    pub const fn at(position: u32) -> Self {
        Self(position)
    }

    /// The 1-based position in the order (0 for an unranked handler).
    pub const fn position(self) -> u32 {
        self.0
    }

    /// Whether `self` is more urgent than `other`.
    pub fn outranks(self, other: Rank) -> bool {
        self.0 < other.0
    }

    pub(crate) const fn from_raw(raw: u32) -> Self {
        Self(raw)
    }
}

impl fmt::Debug for Rank {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Rank({})", self.0)
    }
}

/// A module's order: `ORDER(READY_TO_CHIP.TIMEOUT, SHARE_FEEDER.TIMEOUT, CHIP_IT, GRASP, ...)`.
///
/// Names are the module's own name (its background code), `PORT.resp` for a response
/// handler, `PORT.TIMEOUT` (or any exception name) for an exception handler, and named
/// sections such as `GRASP`. Code in no named section is background code; a section the
/// order does not name ranks as the code around it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Order {
    module: Name,
    names: Vec<Name>,
}

impl Order {
    /// The order `names` of module `module`. An empty order ranks the background alone.
    pub fn new(module: Name, names: Vec<Name>) -> Self {
        Self { module, names }
    }

    /// The rank of `name`, if the order names it.
    pub fn rank_of(&self, name: &str) -> Option<Rank> {
        let position = self.names.iter().position(|n| n.as_str() == name)?;
        Some(Rank::at(position as u32 + 1))
    }

    /// The rank of the module's background code: where the order names the module, or after
    /// everything it names.
    pub fn background(&self) -> Rank {
        self.rank_of(self.module.as_str())
            .unwrap_or(Rank::at(self.names.len() as u32 + 1))
    }

    /// The rank of a handler named `name` (`PORT.resp`, `PORT.TIMEOUT`).
    pub fn handler_rank(&self, name: &str) -> Rank {
        self.rank_of(name).unwrap_or(Rank::UNRANKED_HANDLER)
    }

    /// The names, most urgent first.
    pub fn names(&self) -> &[Name] {
        &self.names
    }
}
