//! A module's declarations as data, for the wiring check: Shin's (1985) module
//! specification, what [`ModuleSpec::declaration`](crate::ModuleSpec::declaration) gives.

use imrs_ports::{Name, UsageKind, WireError, Wiring};

/// A module's declarations, for the wiring check: the seed's module specification.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ModuleDecl {
    /// The module.
    pub name: Name,
    /// Its order.
    pub order: Vec<Name>,
    /// The ports it uses, with its usage.
    pub uses: Vec<(Name, UsageKind)>,
    /// The ports it filters, with the filter's usage toward the users.
    pub filters: Vec<(Name, UsageKind)>,
    /// Its response handlers (`PORT.resp`), each with the port its end answers.
    pub responses: Vec<(Name, Name)>,
    /// Its exception handlers.
    pub exceptions: Vec<Name>,
    /// Its tasks.
    pub tasks: Vec<Name>,
    /// The exceptions it declares it raises itself ([`ModuleSpec::raises`](crate::ModuleSpec::raises)).
    pub raises: Vec<Name>,
    /// The ends it could not attach when it was declared ([`ModuleSpec::respond`](crate::ModuleSpec::respond)).
    /// (The ports it owns are those declared with it as their owner.)
    pub problems: Vec<WireError>,
}

/// The ports declared to `wiring` whose owner is `module`.
pub(crate) fn owned_by(wiring: &Wiring, module: &Name) -> Vec<Name> {
    wiring.owned_by(module).cloned().collect()
}
