//! The RIHS01 type hashes computed from the messages' fields equal those ROS 2 publishes:
//! the values rosidl generates into each type's `*__description.c` (ROS 2 Kilted; the same
//! in Jazzy), and those `rmw_zenoh`'s design document shows in its key expressions.

use imrs_ros2::msgs::builtin_interfaces::Time;
use imrs_ros2::msgs::geometry_msgs::{
    Point, Pose, Quaternion, Transform, TransformStamped, Vector3,
};
use imrs_ros2::msgs::sensor_msgs::JointState;
use imrs_ros2::msgs::service_msgs::ServiceEventInfo;
use imrs_ros2::msgs::std_msgs::{self, Header};
use imrs_ros2::msgs::std_srvs::{Trigger, TriggerRequest, TriggerResponse};
use imrs_ros2::{RosMessage, RosService};

fn hash_of<M: RosMessage>() -> String {
    M::type_hash().to_string()
}

#[test]
fn the_common_messages_hash_as_ros_2_publishes() {
    let published = [
        (
            hash_of::<std_msgs::String>(),
            "RIHS01_df668c740482bbd48fb39d76a70dfd4bd59db1288021743503259e948f6b1a18",
        ),
        (
            hash_of::<Header>(),
            "RIHS01_f49fb3ae2cf070f793645ff749683ac6b06203e41c891e17701b1cb597ce6a01",
        ),
        (
            hash_of::<Time>(),
            "RIHS01_b106235e25a4c5ed35098aa0a61a3ee9c9b18d197f398b0e4206cea9acf9c197",
        ),
        (
            hash_of::<Point>(),
            "RIHS01_6963084842a9b04494d6b2941d11444708d892da2f4b09843b9c43f42a7f6881",
        ),
        (
            hash_of::<Quaternion>(),
            "RIHS01_8a765f66778c8ff7c8ab94afcc590a2ed5325a1d9a076ffff38fbce36f458684",
        ),
        (
            hash_of::<Pose>(),
            "RIHS01_d501954e9476cea2996984e812054b68026ae0bfae789d9a10b23daf35cc90fa",
        ),
        (
            hash_of::<Vector3>(),
            "RIHS01_cc12fe83e4c02719f1ce8070bfd14aecd40f75a96696a67a2a1f37f7dbb0765d",
        ),
        (
            hash_of::<Transform>(),
            "RIHS01_beb83fbe698636351461f6f35d1abb20010c43d55374d81bd041f1ba2581fddc",
        ),
        (
            hash_of::<TransformStamped>(),
            "RIHS01_0a241f87d04668d94099cbb5ba11691d5ad32c2f29682e4eb5653424bd275206",
        ),
        (
            hash_of::<JointState>(),
            "RIHS01_a13ee3a330e346c9d87b5aa18d24e11690752bd33a0350f11c5882bc9179260e",
        ),
        (
            hash_of::<ServiceEventInfo>(),
            "RIHS01_41bcbbe07a75c9b52bc96bfd5c24d7f0fc0a08c0cb7921b3373c5732345a6f45",
        ),
        (
            hash_of::<TriggerRequest>(),
            "RIHS01_d010825374ce8918e72bfd826c82603e60f45419e932ea976f807b74a863a199",
        ),
        (
            hash_of::<TriggerResponse>(),
            "RIHS01_2d946c21e2fc3f1e9ca6986a8191d85fcc70097a8bb7771a053564bc47009cdf",
        ),
    ];
    for (computed, published) in published {
        assert_eq!(computed, published);
    }
}

#[test]
fn a_service_hashes_with_its_request_response_and_event_as_ros_2_publishes() {
    assert_eq!(
        Trigger::type_hash().to_string(),
        "RIHS01_eeff2cd6fa5ad9d27cdf4dec64818317839b62f212a91e6b5304b634b2062c5f"
    );
    assert_eq!(Trigger::dds_type_name(), "std_srvs::srv::dds_::Trigger_");
}

#[test]
fn the_names_are_those_of_ros_2_and_of_dds() {
    assert_eq!(JointState::TYPE_NAME, "sensor_msgs/msg/JointState");
    assert_eq!(
        JointState::dds_type_name(),
        "sensor_msgs::msg::dds_::JointState_"
    );
    assert_eq!(
        std_msgs::String::dds_type_name(),
        "std_msgs::msg::dds_::String_"
    );
}

#[test]
fn a_quaternion_is_none_by_default_as_in_ros_2() {
    assert_eq!(Quaternion::default().w, 1.0);
    assert_eq!(Pose::default().orientation.w, 1.0);
}
