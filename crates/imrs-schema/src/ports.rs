//! A schema's ports, `(ip)` and `(op)` of the seed's `[N (ip) (op) (v) (b)]`.

use imrs_ports::Name;
use imrs_ports::synchronous::AnyPort;

/// The ports of a schema or an assemblage, listed by the names they are known by here, so
/// that a connection map given by name can find them.
///
/// Declare a schema's ports with [`ports!`](crate::ports!), which writes this and
/// [`Declare`]. An assemblage's ports are its components' (the seed's *port equivalences*):
/// a struct of clones of the component ports, listed under the assemblage's names.
pub trait Ports: Send + Sync + 'static {
    /// Every port, by its name here.
    fn list(&self) -> Vec<(&'static str, &dyn AnyPort)>;
}

/// Ports made fresh for a new instance, owned by it.
pub trait Declare: Ports + Sized {
    /// The ports of the instance named `owner`.
    fn declare(owner: &Name) -> Self;
}

impl Ports for () {
    fn list(&self) -> Vec<(&'static str, &dyn AnyPort)> {
        Vec::new()
    }
}

impl Declare for () {
    fn declare(_: &Name) -> Self {}
}

/// Declares a schema's ports as a struct: `in` for an input, `out` for an output, each with
/// its field, its message type and the seed's name for it.
///
/// ```
/// imrs_schema::ports! {
///     /// TClosejoint's ports: a tactile input, the joint's position, the desired position.
///     pub struct ClosejointPorts {
///         in tin: bool = "Tin",
///         in pin: f32 = "Pin",
///         out pout: f32 = "Pout",
///     }
/// }
/// ```
#[macro_export]
macro_rules! ports {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $($dir:ident $field:ident : $ty:ty = $port:literal),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Clone, Debug)]
        $vis struct $name {
            $(
                #[doc = concat!("`", $port, "`")]
                pub $field: $crate::ports!(@end $dir $ty),
            )*
        }

        impl $crate::Ports for $name {
            fn list(&self) -> ::std::vec::Vec<(&'static str, &dyn $crate::AnyPort)> {
                ::std::vec![$(($port, &self.$field as &dyn $crate::AnyPort)),*]
            }
        }

        impl $crate::Declare for $name {
            fn declare(owner: &$crate::Name) -> Self {
                Self {
                    $($field: <$crate::ports!(@end $dir $ty)>::new($port, owner.clone()),)*
                }
            }
        }
    };
    (@end in $ty:ty) => { $crate::Input<$ty> };
    (@end out $ty:ty) => { $crate::Output<$ty> };
}
