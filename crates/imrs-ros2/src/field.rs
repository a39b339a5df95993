//! The Rust types a ROS 2 field can have, and the ROS 2 type each stands for.

use std::collections::BTreeMap;

use crate::{Field, FieldType};

/// A Rust type a field of a ROS 2 message can have: a primitive, `String`, a message
/// declared with [`ros_message!`](crate::ros_message), a `Vec` of one of those (an unbounded
/// sequence) or an array of one (a fixed-size array, of at most 32, as far as `serde` goes).
#[diagnostic::on_unimplemented(
    message = "`{Self}` has no ROS 2 type",
    label = "not a type a ROS 2 field can have",
    note = "a field is a primitive (bool, i8…u64, f32, f64), String, a message declared with \
            `ros_message!`, or a `Vec` or array of one of those"
)]
pub trait RosField {
    /// The field's type.
    fn field_type() -> FieldType;

    /// Adds to `out`, by name, the fields of every message type it refers to, and of those
    /// they refer to.
    fn referenced(out: &mut BTreeMap<String, Vec<Field>>) {
        let _ = out;
    }
}

/// A type a sequence or an array can hold: anything a field can be but a sequence or an
/// array (ROS 2 has no sequences of sequences).
#[diagnostic::on_unimplemented(
    message = "`{Self}` cannot be held in a ROS 2 sequence or array",
    label = "ROS 2 has no sequences of sequences"
)]
pub trait RosElement: RosField {}

macro_rules! primitive {
    ($($rust:ty => $id:ident),* $(,)?) => {
        $(
            impl RosField for $rust {
                fn field_type() -> FieldType {
                    FieldType::plain(FieldType::$id)
                }
            }

            impl RosElement for $rust {}
        )*
    };
}

primitive! {
    bool => BOOLEAN,
    i8 => INT8,
    u8 => UINT8,
    i16 => INT16,
    u16 => UINT16,
    i32 => INT32,
    u32 => UINT32,
    i64 => INT64,
    u64 => UINT64,
    f32 => FLOAT,
    f64 => DOUBLE,
    String => STRING,
}

impl<T: RosElement> RosField for Vec<T> {
    fn field_type() -> FieldType {
        let element = T::field_type();
        FieldType {
            type_id: element.type_id + FieldType::UNBOUNDED_SEQUENCE,
            ..element
        }
    }

    fn referenced(out: &mut BTreeMap<String, Vec<Field>>) {
        T::referenced(out);
    }
}

impl<T: RosElement, const N: usize> RosField for [T; N] {
    fn field_type() -> FieldType {
        let element = T::field_type();
        FieldType {
            type_id: element.type_id + FieldType::ARRAY,
            capacity: N as u64,
            ..element
        }
    }

    fn referenced(out: &mut BTreeMap<String, Vec<Field>>) {
        T::referenced(out);
    }
}
