//! `sensor_msgs`.

use super::std_msgs::Header;
use crate::ros_message;

ros_message! {
    /// `sensor_msgs/msg/JointState`: a robot's joints, by name; each list empty or as long
    /// as `name`.
    pub struct JointState = "sensor_msgs/msg/JointState" {
        /// When, and in which frame.
        pub header: Header,
        /// The joints' names.
        pub name: Vec<String>,
        /// Their positions (radians, or metres for a prismatic joint).
        pub position: Vec<f64>,
        /// Their velocities.
        pub velocity: Vec<f64>,
        /// Their efforts (torque or force).
        pub effort: Vec<f64>,
    }
}
