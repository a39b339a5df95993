//! `service_msgs`: what every service's event message says (ROS 2 describes each service
//! with its event message, so its type hash needs this one).

use super::builtin_interfaces::Time;
use crate::ros_message;

ros_message! {
    /// `service_msgs/msg/ServiceEventInfo`: a request or response seen, by whom and when.
    pub struct ServiceEventInfo = "service_msgs/msg/ServiceEventInfo" {
        /// Which event: a request sent or received, a response sent or received (0 to 3).
        pub event_type: u8,
        /// When.
        pub stamp: Time,
        /// The client's GID (`char[16]`, which ROS 2 takes as `uint8[16]`).
        pub client_gid: [u8; 16],
        /// The request's sequence number.
        pub sequence_number: i64,
    }
}
