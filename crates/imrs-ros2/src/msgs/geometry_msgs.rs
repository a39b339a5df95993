//! `geometry_msgs`: points, orientations, poses and transforms.

use super::std_msgs::Header;
use crate::ros_message;

ros_message! {
    /// `geometry_msgs/msg/Point`, in metres.
    pub struct Point = "geometry_msgs/msg/Point" {
        /// x.
        pub x: f64,
        /// y.
        pub y: f64,
        /// z.
        pub z: f64,
    }
}

ros_message! {
    /// `geometry_msgs/msg/Vector3`.
    pub struct Vector3 = "geometry_msgs/msg/Vector3" {
        /// x.
        pub x: f64,
        /// y.
        pub y: f64,
        /// z.
        pub z: f64,
    }
}

ros_message! {
    /// `geometry_msgs/msg/Quaternion`: an orientation; by default none (w = 1), as in ROS 2.
    pub struct Quaternion = "geometry_msgs/msg/Quaternion" {
        /// x.
        pub x: f64,
        /// y.
        pub y: f64,
        /// z.
        pub z: f64,
        /// w.
        pub w: f64 = 1.0,
    }
}

ros_message! {
    /// `geometry_msgs/msg/Pose`: a position and an orientation.
    pub struct Pose = "geometry_msgs/msg/Pose" {
        /// Where.
        pub position: Point,
        /// Which way.
        pub orientation: Quaternion,
    }
}

ros_message! {
    /// `geometry_msgs/msg/Transform`: from one frame to another.
    pub struct Transform = "geometry_msgs/msg/Transform" {
        /// The translation.
        pub translation: Vector3,
        /// The rotation.
        pub rotation: Quaternion,
    }
}

ros_message! {
    /// `geometry_msgs/msg/TransformStamped`: a transform from `header.frame_id` to
    /// `child_frame_id`, at `header.stamp`.
    pub struct TransformStamped = "geometry_msgs/msg/TransformStamped" {
        /// The parent frame, and when.
        pub header: Header,
        /// The child frame.
        pub child_frame_id: String,
        /// The transform.
        pub transform: Transform,
    }
}
