//! A module's name, made once as a value.

use std::fmt;

use crate::name::Name;

/// A module's name, made once — a constant where the cell is written — and used wherever the
/// module is meant: its spec, the ports it owns, the user lists that name it, its order's
/// background, its task. A misspelt constant is a compile error, where a misspelt string is
/// a module nobody runs. A cell built from data names its modules with plain strings.
///
/// ```
/// use imrs_ports::{Module, Name, PortSpec};
///
/// const LOAD_IT: Module = Module::new("LOAD_IT");
/// const LOAD_CARD: Module = Module::new("LOAD_CARD");
/// let ask_child1 = PortSpec::new("ASK_CHILD1", LOAD_IT).user_list([LOAD_CARD]);
/// assert_eq!(LOAD_CARD.name(), Name::from("LOAD_CARD"));
/// ```
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct Module(&'static str);

impl Module {
    /// Module `name`.
    pub const fn new(name: &'static str) -> Self {
        Self(name)
    }

    /// The module's name.
    pub fn name(&self) -> Name {
        Name::from(self.0)
    }

    /// The module's name, as written.
    pub const fn as_str(&self) -> &'static str {
        self.0
    }
}

impl From<Module> for Name {
    fn from(module: Module) -> Self {
        module.name()
    }
}

impl From<&Module> for Name {
    fn from(module: &Module) -> Self {
        module.name()
    }
}

impl fmt::Debug for Module {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "Module({})", self.0)
    }
}

impl fmt::Display for Module {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.0)
    }
}
