//! `builtin_interfaces`.

use crate::ros_message;

ros_message! {
    /// `builtin_interfaces/msg/Time`: a point in time, in seconds and nanoseconds.
    pub struct Time = "builtin_interfaces/msg/Time" {
        /// Whole seconds.
        pub sec: i32,
        /// Nanoseconds past `sec`, below 10⁹.
        pub nanosec: u32,
    }
}
