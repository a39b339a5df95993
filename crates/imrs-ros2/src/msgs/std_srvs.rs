//! `std_srvs`.

use crate::{ros_message, ros_service};

ros_message! {
    /// What `std_srvs/srv/Trigger` asks: nothing. ROS 2 gives a message without fields one
    /// `uint8`, which CDR carries.
    pub struct TriggerRequest = "std_srvs/srv/Trigger_Request" {
        /// Always 0.
        pub structure_needs_at_least_one_member: u8,
    }
}

ros_message! {
    /// What `std_srvs/srv/Trigger` answers.
    pub struct TriggerResponse = "std_srvs/srv/Trigger_Response" {
        /// Whether it went well.
        pub success: bool,
        /// What happened.
        pub message: String,
    }
}

ros_service! {
    /// `std_srvs/srv/Trigger`: do something, say whether it went well.
    pub service Trigger = "std_srvs/srv/Trigger" {
        request: TriggerRequest,
        response: TriggerResponse,
    }
}
