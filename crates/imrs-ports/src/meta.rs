//! What a port declaration says about itself, kept at run time for checks and messages.

use std::time::Duration;

use crate::error::WireError;
pub use crate::name::Name;

use crate::priority::Priority;
use crate::process_type::ProcessType;
use crate::usage::UsageKind;

/// A module known by type, so that user lists can be checked at compile time.
pub trait Named {
    /// The module's name, as the seed writes it (`"LOAD_CARD"`).
    const NAME: &'static str;
}

#[derive(Debug, Clone)]
pub(crate) struct PortMeta {
    pub(crate) name: Name,
    pub(crate) owner: Name,
    pub(crate) usage: UsageKind,
    pub(crate) user_list: Option<Box<[Name]>>,
    /// The port was declared with a typed user list and a named one: refused on every
    /// attach and by the wiring, never resolved silently.
    pub(crate) two_user_lists: bool,
    /// Bounds the owner's end.
    pub(crate) timeout: Option<Duration>,
    /// Bounds every user's end.
    pub(crate) user_timeout: Option<Duration>,
    pub(crate) priority: Priority,
    pub(crate) process_type: ProcessType,
}

impl PortMeta {
    /// Refuses a port declared with two user lists.
    pub(crate) fn check_user_lists(&self) -> Result<(), WireError> {
        if self.two_user_lists {
            return Err(WireError::TwoUserLists {
                port: self.name.clone(),
            });
        }
        Ok(())
    }

    pub(crate) fn admits(&self, module: &str) -> bool {
        self.user_list
            .as_ref()
            .is_none_or(|list| list.iter().any(|name| name.as_str() == module))
    }
}
