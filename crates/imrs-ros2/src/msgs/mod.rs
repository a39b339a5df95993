//! The ROS 2 messages a cell needs most, with their ROS names: times and headers, poses
//! and transforms, joint states, and the trigger service.

pub mod builtin_interfaces;
pub mod geometry_msgs;
pub mod sensor_msgs;
pub mod service_msgs;
pub mod std_msgs;
pub mod std_srvs;
