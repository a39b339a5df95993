//! User lists (Shin 1985, restriction 3), checked at compile time where users are types.

use crate::meta::Named;

/// A port's user list as a type. Declare one with [`user_list!`](crate::user_list).
pub trait UserList: 'static {
    /// The names on the list, or `None` for a port open to every module.
    const NAMES: Option<&'static [&'static str]>;
}

/// Whether the user list `Self` admits the module `M`.
#[diagnostic::on_unimplemented(
    message = "`{M}` is not on the user list `{Self}` of this port",
    label = "this port admits only the modules on `{Self}`",
    note = "add `{M}` to the `user_list!` that declares `{Self}`, or attach a module that is on it"
)]
pub trait Admits<M: Named>: UserList {}

/// The user list of a port without the restriction: every module may use it.
#[derive(Debug, Clone, Copy, Default)]
pub struct AnyUser;

impl UserList for AnyUser {
    const NAMES: Option<&'static [&'static str]> = None;
}

impl<M: Named> Admits<M> for AnyUser {}

/// Declares a user list: a type naming the modules that may use a port.
///
/// ```
/// use imrs_ports::{Named, user_list};
///
/// struct LoadIt;
/// impl Named for LoadIt { const NAME: &'static str = "LOAD_IT"; }
/// struct ChipIt;
/// impl Named for ChipIt { const NAME: &'static str = "CHIP_IT"; }
///
/// user_list! {
///     /// `USERLIST=(LOAD_IT,CHIP_IT)` of GATE's FREQUENCY port.
///     pub FrequencyUsers = [LoadIt, ChipIt];
/// }
/// ```
#[macro_export]
macro_rules! user_list {
    ($(#[$doc:meta])* $vis:vis $list:ident = [$($module:ty),+ $(,)?];) => {
        $(#[$doc])*
        #[derive(Debug, Clone, Copy, Default)]
        $vis struct $list;

        impl $crate::UserList for $list {
            const NAMES: ::core::option::Option<&'static [&'static str]> =
                ::core::option::Option::Some(&[$(<$module as $crate::Named>::NAME),+]);
        }

        $(impl $crate::Admits<$module> for $list {})+
    };
}
