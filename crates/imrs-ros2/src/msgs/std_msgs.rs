//! `std_msgs`.

use super::builtin_interfaces::Time;
use crate::ros_message;

ros_message! {
    /// `std_msgs/msg/Header`: when, and in which frame, data was taken.
    pub struct Header = "std_msgs/msg/Header" {
        /// When.
        pub stamp: Time,
        /// The frame the data is in.
        pub frame_id: std::string::String,
    }
}

ros_message! {
    /// `std_msgs/msg/String`.
    pub struct String = "std_msgs/msg/String" {
        /// The text.
        pub data: std::string::String,
    }
}
