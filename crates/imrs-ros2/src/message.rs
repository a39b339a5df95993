//! A ROS 2 message type, and [`ros_message!`](crate::ros_message) that declares one.

use std::collections::BTreeMap;

use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::{Field, RosElement, TypeDescription, TypeHash};

/// A ROS 2 message type: a `serde` struct (so that it crosses hosts in CDR as ROS 2 lays it
/// out) with its ROS name and fields. Declare one with [`ros_message!`](crate::ros_message).
pub trait RosMessage:
    RosElement + Serialize + DeserializeOwned + Default + Clone + Send + Sync + 'static
{
    /// Its ROS name, `package/msg/Name`.
    const TYPE_NAME: &'static str;

    /// Its fields, in order.
    fn fields() -> Vec<Field>;

    /// Adds to `out` the fields of every message type its fields refer to, and of those
    /// they refer to.
    fn referenced_by_fields(out: &mut BTreeMap<String, Vec<Field>>);

    /// Its description.
    fn description() -> TypeDescription {
        TypeDescription {
            type_name: Self::TYPE_NAME.to_owned(),
            fields: Self::fields(),
        }
    }

    /// Its RIHS01 type hash, computed from its fields as ROS 2 computes it.
    fn type_hash() -> TypeHash {
        let mut referenced = BTreeMap::new();
        Self::referenced_by_fields(&mut referenced);
        Self::description().hash(&referenced)
    }

    /// The name DDS and `rmw_zenoh` give it: `package::msg::dds_::Name_`.
    fn dds_type_name() -> String {
        dds_type_name(Self::TYPE_NAME)
    }
}

/// `package/kind/Name` as `package::kind::dds_::Name_`.
pub(crate) fn dds_type_name(type_name: &str) -> String {
    let (namespace, name) = type_name.rsplit_once('/').unwrap_or(("", type_name));
    format!("{}::dds_::{name}_", namespace.replace('/', "::"))
}

/// Declares a ROS 2 message type: a struct with its ROS name, whose fields are
/// [`RosField`](crate::RosField)s, each with a default value if it has one (`pub w: f64 =
/// 1.0`). It derives `Debug`, `Clone`, `PartialEq` and `serde`'s traits, implements
/// `Default` with those values, and implements [`RosMessage`]. A name that is not
/// `package/msg/Name`, or a field name that is not `[a-z][a-z0-9_]*`, fails to compile.
///
/// ```
/// imrs_ros2::ros_message! {
///     /// A gripper's state.
///     pub struct Gripper = "cell_msgs/msg/Gripper" {
///         pub closed: bool,
///         pub force: f64,
///     }
/// }
/// ```
///
/// A name that is not `package/msg/Name` does not compile:
///
/// ```compile_fail,E0080
/// imrs_ros2::ros_message! {
///     pub struct Gripper = "cell_msgs/Gripper" {
///         pub closed: bool,
///     }
/// }
/// ```
///
/// Nor does a message without fields (ROS 2 gives it one `uint8`, which must be declared):
///
/// ```compile_fail
/// imrs_ros2::ros_message! {
///     pub struct Empty = "cell_msgs/msg/Empty" {}
/// }
/// ```
///
/// Nor does a field of a type ROS 2 has no name for:
///
/// ```compile_fail,E0277
/// imrs_ros2::ros_message! {
///     pub struct Gripper = "cell_msgs/msg/Gripper" {
///         pub closing: std::time::Duration,
///     }
/// }
/// ```
#[macro_export]
macro_rules! ros_message {
    (@default) => { ::std::default::Default::default() };
    (@default $default:expr) => { $default };
    // ROS 2 gives a message without fields one `uint8`, which CDR carries: say it.
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident = $ros_name:literal {}
    ) => {
        compile_error!(concat!(
            $ros_name,
            " has no fields: ROS 2 gives such a message one, as it must be declared here too: \
             `pub structure_needs_at_least_one_member: u8`"
        ));
    };
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident = $ros_name:literal {
            $(
                $(#[$field_meta:meta])*
                $field_vis:vis $field:ident : $ty:ty $(= $default:expr)?
            ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq, $crate::serde::Serialize, $crate::serde::Deserialize)]
        // `$crate` cannot be written in an attribute's string: the crate's own name is, and
        // names it inside the crate too (`extern crate self`).
        #[serde(crate = "imrs_ros2::serde")]
        $vis struct $name {
            $(
                $(#[$field_meta])*
                $field_vis $field: $ty,
            )*
        }

        /// Each field's default value as the message declares it, else its type's.
        impl ::std::default::Default for $name {
            fn default() -> Self {
                Self {
                    $($field: $crate::ros_message!(@default $($default)?),)*
                }
            }
        }

        const _: () = {
            assert!(
                $crate::is_interface_name($ros_name, "msg")
                    || $crate::is_interface_name($ros_name, "srv"),
                concat!("not a ROS 2 message name (package/msg/Name): ", $ros_name)
            );
            $(
                assert!(
                    $crate::is_field_name(stringify!($field)),
                    concat!("not a ROS 2 field name ([a-z][a-z0-9_]*): ", stringify!($field))
                );
            )*
        };

        impl $crate::RosMessage for $name {
            const TYPE_NAME: &'static str = $ros_name;

            fn fields() -> ::std::vec::Vec<$crate::Field> {
                ::std::vec![
                    $($crate::Field::new(
                        stringify!($field),
                        <$ty as $crate::RosField>::field_type(),
                    )),*
                ]
            }

            fn referenced_by_fields(
                out: &mut ::std::collections::BTreeMap<::std::string::String, ::std::vec::Vec<$crate::Field>>,
            ) {
                let _ = &out;
                $(<$ty as $crate::RosField>::referenced(out);)*
            }
        }

        impl $crate::RosField for $name {
            fn field_type() -> $crate::FieldType {
                $crate::FieldType::nested(<Self as $crate::RosMessage>::TYPE_NAME)
            }

            fn referenced(
                out: &mut ::std::collections::BTreeMap<::std::string::String, ::std::vec::Vec<$crate::Field>>,
            ) {
                let name = <Self as $crate::RosMessage>::TYPE_NAME;
                if !out.contains_key(name) {
                    out.insert(name.to_owned(), <Self as $crate::RosMessage>::fields());
                    <Self as $crate::RosMessage>::referenced_by_fields(out);
                }
            }
        }

        impl $crate::RosElement for $name {}
    };
}
