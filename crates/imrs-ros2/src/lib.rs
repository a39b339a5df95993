//! ROS 2 messages for IMRS ports.
//!
//! A ROS 2 message here is a Rust struct with its ROS name (`sensor_msgs/msg/JointState`)
//! and its fields, declared once with [`ros_message!`]: from that declaration come the
//! struct, its `serde` shape (so that it crosses hosts on `imrs-zenoh` in the CDR ROS 2
//! uses, byte for byte), its type description and its RIHS01 type hash, computed as ROS 2
//! computes it (REP 2016), never typed by hand. Services pair two messages
//! ([`RosService`]).
//!
//! The common messages a cell needs are in [`msgs`]: `builtin_interfaces`, `std_msgs`,
//! `geometry_msgs` poses and transforms, `sensor_msgs/JointState`, `std_srvs/Trigger`.
//! A cell declares its own the same way:
//!
//! ```
//! use imrs_ros2::{RosMessage, ros_message};
//! use imrs_ros2::msgs::std_msgs::Header;
//!
//! ros_message! {
//!     /// A pallet seen at a station.
//!     pub struct PalletSeen = "cell_msgs/msg/PalletSeen" {
//!         pub header: Header,
//!         pub pallet: u32,
//!         pub chips: Vec<u8>,
//!     }
//! }
//!
//! assert_eq!(PalletSeen::dds_type_name(), "cell_msgs::msg::dds_::PalletSeen_");
//! assert!(PalletSeen::type_hash().to_string().starts_with("RIHS01_"));
//! ```
//!
//! A name that is not `package/msg/Name`, and a field of a type ROS 2 has no name for (see
//! [`RosField`]), do not compile.

// The declaration macros name `serde` through this crate, by its name, here too.
extern crate self as imrs_ros2;

mod attachment;
mod bridge;
mod description;
mod error;
mod field;
pub mod graph;
mod message;
pub mod msgs;
mod node;
mod service;

pub use attachment::Attachment;
pub use bridge::Bridge;
pub use description::{Field, FieldType, TypeDescription, TypeHash};
pub use error::Ros2Error;
pub use field::{RosElement, RosField};
pub use message::RosMessage;
pub use node::{MOST_WAITING, Node, Publisher, ServiceServer};
pub use service::RosService;

// What the declaration macros use.
#[doc(hidden)]
pub use description::{is_field_name, is_interface_name};
#[doc(hidden)]
pub use serde;
#[doc(hidden)]
pub use service::is_part_of;
