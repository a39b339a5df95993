//! A type's description and its RIHS01 hash, as ROS 2 makes them (REP 2016;
//! `rosidl_generator_type_description`): the type's fields and those of every type it
//! refers to, sorted by name, written as JSON without default values, hashed with SHA-256.

use std::collections::BTreeMap;
use std::fmt::{self, Write as _};

use sha2::{Digest, Sha256};

/// A field's type, as `type_description_interfaces/msg/FieldType` says it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FieldType {
    /// The type's id: a primitive's, or [`FieldType::NESTED_TYPE`], plus
    /// [`FieldType::ARRAY`], [`FieldType::BOUNDED_SEQUENCE`] or
    /// [`FieldType::UNBOUNDED_SEQUENCE`] for a collection of them.
    pub type_id: u8,
    /// An array's length, or a bounded sequence's bound; else 0.
    pub capacity: u64,
    /// A bounded string's bound; else 0.
    pub string_capacity: u64,
    /// The message type a nested field (or a collection of them) holds; else empty.
    pub nested_type_name: String,
}

impl FieldType {
    /// A message of another type.
    pub const NESTED_TYPE: u8 = 1;
    /// `int8`.
    pub const INT8: u8 = 2;
    /// `uint8` (and `.msg`'s `char`).
    pub const UINT8: u8 = 3;
    /// `int16`.
    pub const INT16: u8 = 4;
    /// `uint16`.
    pub const UINT16: u8 = 5;
    /// `int32`.
    pub const INT32: u8 = 6;
    /// `uint32`.
    pub const UINT32: u8 = 7;
    /// `int64`.
    pub const INT64: u8 = 8;
    /// `uint64`.
    pub const UINT64: u8 = 9;
    /// `float32`.
    pub const FLOAT: u8 = 10;
    /// `float64`.
    pub const DOUBLE: u8 = 11;
    /// `bool`.
    pub const BOOLEAN: u8 = 15;
    /// `byte`.
    pub const BYTE: u8 = 16;
    /// `string`, unbounded.
    pub const STRING: u8 = 17;
    /// Added to an element's id: a fixed-size array of it.
    pub const ARRAY: u8 = 48;
    /// Added to an element's id: a sequence of it with a bound.
    pub const BOUNDED_SEQUENCE: u8 = 96;
    /// Added to an element's id: a sequence of it without a bound.
    pub const UNBOUNDED_SEQUENCE: u8 = 144;

    /// A primitive or a string: the type `type_id` names, alone.
    pub fn plain(type_id: u8) -> Self {
        Self {
            type_id,
            capacity: 0,
            string_capacity: 0,
            nested_type_name: String::new(),
        }
    }

    /// A message of type `type_name`.
    pub fn nested(type_name: &str) -> Self {
        Self {
            nested_type_name: type_name.to_owned(),
            ..Self::plain(Self::NESTED_TYPE)
        }
    }
}

/// A field of a message: its name and its type.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Field {
    /// Its name, as the `.msg` file writes it.
    pub name: String,
    /// Its type.
    pub field_type: FieldType,
}

impl Field {
    /// Field `name` of type `field_type`.
    pub fn new(name: &str, field_type: FieldType) -> Self {
        Self {
            name: name.to_owned(),
            field_type,
        }
    }
}

/// The name a message without fields is given one of, as ROS 2 gives it: a `uint8` that
/// CDR carries too.
pub(crate) const EMPTY_STRUCTURE_MEMBER: &str = "structure_needs_at_least_one_member";

/// A message type's description: its ROS name and its fields, in order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TypeDescription {
    /// `package/msg/Name` (or `package/srv/Name_Request`, and so on).
    pub type_name: String,
    /// Its fields, in order.
    pub fields: Vec<Field>,
}

impl TypeDescription {
    /// The RIHS01 hash of this type, `referenced` holding the fields of every type it
    /// refers to (and they to), by name.
    pub fn hash(&self, referenced: &BTreeMap<String, Vec<Field>>) -> TypeHash {
        let mut json = String::from("{\"type_description\": ");
        write_type(&mut json, &self.type_name, &self.fields);
        json.push_str(", \"referenced_type_descriptions\": [");
        for (at, (type_name, fields)) in referenced.iter().enumerate() {
            if at > 0 {
                json.push_str(", ");
            }
            write_type(&mut json, type_name, fields);
        }
        json.push_str("]}");
        TypeHash(Sha256::digest(json.as_bytes()).into())
    }
}

/// One type, as `json.dumps(…, separators=(", ", ": "))` writes it; names are checked
/// to be identifiers and paths when declared, so none needs escaping.
fn write_type(json: &mut String, type_name: &str, fields: &[Field]) {
    let placeholder;
    let fields = if fields.is_empty() {
        placeholder = [Field::new(
            EMPTY_STRUCTURE_MEMBER,
            FieldType::plain(FieldType::UINT8),
        )];
        &placeholder[..]
    } else {
        fields
    };
    let _ = write!(json, "{{\"type_name\": \"{type_name}\", \"fields\": [");
    for (at, field) in fields.iter().enumerate() {
        if at > 0 {
            json.push_str(", ");
        }
        let FieldType {
            type_id,
            capacity,
            string_capacity,
            nested_type_name,
        } = &field.field_type;
        let _ = write!(
            json,
            "{{\"name\": \"{}\", \"type\": {{\"type_id\": {type_id}, \"capacity\": {capacity}, \
             \"string_capacity\": {string_capacity}, \"nested_type_name\": \"{nested_type_name}\"}}}}",
            field.name
        );
    }
    json.push_str("]}");
}

/// A RIHS01 type hash: the SHA-256 of a type's description. Shown as ROS 2 shows it,
/// `RIHS01_` and 64 hex digits.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
pub struct TypeHash(pub [u8; 32]);

impl fmt::Display for TypeHash {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("RIHS01_")?;
        self.0.iter().try_for_each(|byte| write!(f, "{byte:02x}"))
    }
}

impl fmt::Debug for TypeHash {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

/// Whether `name` is a ROS 2 interface name of `kind` (`msg` or `srv`): `package/kind/Name`,
/// the package in lower case, the name starting with a capital. Checked when a type is
/// declared, at compile time.
pub const fn is_interface_name(name: &str, kind: &str) -> bool {
    let (name, kind) = (name.as_bytes(), kind.as_bytes());
    // The package: [a-z][a-z0-9_]*.
    let mut at = 0;
    if name.is_empty() || !name[0].is_ascii_lowercase() {
        return false;
    }
    while at < name.len() && name[at] != b'/' {
        if !(name[at].is_ascii_lowercase() || name[at].is_ascii_digit() || name[at] == b'_') {
            return false;
        }
        at += 1;
    }
    // "/kind/".
    if at + kind.len() + 2 >= name.len() || name[at] != b'/' {
        return false;
    }
    at += 1;
    let mut k = 0;
    while k < kind.len() {
        if name[at + k] != kind[k] {
            return false;
        }
        k += 1;
    }
    at += kind.len();
    if name[at] != b'/' {
        return false;
    }
    at += 1;
    // The type: [A-Z][A-Za-z0-9_]*.
    if !name[at].is_ascii_uppercase() {
        return false;
    }
    while at < name.len() {
        if !(name[at].is_ascii_alphanumeric() || name[at] == b'_') {
            return false;
        }
        at += 1;
    }
    true
}

/// Whether `name` is a ROS 2 field name: `[a-z][a-z0-9_]*`.
pub const fn is_field_name(name: &str) -> bool {
    let name = name.as_bytes();
    if name.is_empty() || !name[0].is_ascii_lowercase() {
        return false;
    }
    let mut at = 1;
    while at < name.len() {
        if !(name[at].is_ascii_lowercase() || name[at].is_ascii_digit() || name[at] == b'_') {
            return false;
        }
        at += 1;
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interface_names_are_checked() {
        assert!(is_interface_name("std_msgs/msg/String", "msg"));
        assert!(is_interface_name("std_srvs/srv/Trigger_Request", "srv"));
        for bad in [
            "",
            "String",
            "std_msgs/String",
            "std_msgs/msg/",
            "std_msgs/msg/string",
            "Std_msgs/msg/String",
            "std_msgs/srv/String",
            "std_msgs/msg/Str\"ing",
            "std msgs/msg/String",
        ] {
            assert!(!is_interface_name(bad, "msg"), "{bad:?}");
        }
        assert!(is_field_name("joint_2"));
        for bad in ["", "Joint", "2joint", "joint-2"] {
            assert!(!is_field_name(bad), "{bad:?}");
        }
    }
}
