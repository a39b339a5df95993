//! The `order` statement (Shin 1985, §5.1): a module's ranking of its sections.

use std::fmt;

use imrs_ports::Name;

/// A place in a module's order. Rank 1 is the most urgent; a smaller rank outranks a larger.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Rank(u32);

impl Rank {
    /// The rank of a handler the order does not name. The check every module passes at
    /// start refuses such a handler, so a running module never has one; it is kept as the
    /// most urgent rank for a module checked by nobody.
    pub(crate) const UNRANKED_HANDLER: Rank = Rank(0);

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

/// A named section of a module (a subprogram such as `GRASP` or `INSERT`): made once, as a
/// constant where the name is known when the cell is written, and used wherever the section
/// is meant — the module's order and [`Ctx::section`](crate::Ctx::section) — so that a
/// misspelt section is a compile error.
///
/// ```
/// use imrs_core::Section;
/// const GRASP: Section = Section::new("GRASP");
/// assert_eq!(GRASP.name().as_str(), "GRASP");
/// ```
///
/// A cell built from data names its sections with [`Section::named`]; a section entered by a
/// module whose order does not rank it fails the task, naming the section.
#[derive(Clone, PartialEq, Eq, Hash)]
pub struct Section(SectionName);

#[derive(Clone, PartialEq, Eq, Hash)]
enum SectionName {
    Static(&'static str),
    Named(Name),
}

impl Section {
    /// Section `name`, known when the cell is written.
    pub const fn new(name: &'static str) -> Self {
        Self(SectionName::Static(name))
    }

    /// Section `name`, for a cell built from data.
    pub fn named(name: impl Into<Name>) -> Self {
        Self(SectionName::Named(name.into()))
    }

    /// The section's name, as the order names it.
    pub fn name(&self) -> Name {
        match &self.0 {
            SectionName::Static(name) => Name::from(*name),
            SectionName::Named(name) => name.clone(),
        }
    }

    pub(crate) fn as_str(&self) -> &str {
        match &self.0 {
            SectionName::Static(name) => name,
            SectionName::Named(name) => name.as_str(),
        }
    }
}

impl From<&Section> for Name {
    fn from(section: &Section) -> Self {
        section.name()
    }
}

impl From<Section> for Name {
    fn from(section: Section) -> Self {
        section.name()
    }
}

impl fmt::Debug for Section {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Section({})", self.as_str())
    }
}

/// A module's order: `ORDER(READY_TO_CHIP.TIMEOUT, SHARE_FEEDER.TIMEOUT, CHIP_IT, GRASP, ...)`.
///
/// Names are the module's own name (its background code), `PORT.resp` for a response
/// handler, `PORT.TIMEOUT` (or any exception name) for an exception handler, and named
/// sections such as `GRASP`. Code in no named section is background code. Every handler
/// and section of a module must be in its order: a handler (response or exception) left out
/// refuses the module when it starts, and a section left out fails the task that enters it.
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
