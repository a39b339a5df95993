//! The messages, written and read as the ports write and read them (`imrs_zenoh::encode`
//! and `decode`), are the CDR ROS 2 writes: the payloads below were written by an
//! independent CDR implementation (pycdr2) from the same ROS 2 definitions.

use imrs_ros2::RosMessage;
use imrs_ros2::msgs::builtin_interfaces::Time;
use imrs_ros2::msgs::sensor_msgs::JointState;
use imrs_ros2::msgs::std_msgs::{self, Header};
use imrs_ros2::msgs::std_srvs::{TriggerRequest, TriggerResponse};

fn round_trip<M: RosMessage + PartialEq + std::fmt::Debug>(message: &M, bytes: &[u8]) {
    assert_eq!(
        imrs_zenoh::encode("TOPIC", message).unwrap(),
        bytes,
        "{message:?}"
    );
    let back: M = imrs_zenoh::decode("TOPIC", bytes).unwrap();
    assert_eq!(&back, message);
}

#[test]
fn messages_are_the_cdr_ros_2_writes() {
    round_trip(
        &std_msgs::String {
            data: "hello".into(),
        },
        b"\x00\x01\x00\x00\x06\x00\x00\x00hello\x00",
    );
    round_trip(&TriggerRequest::default(), b"\x00\x01\x00\x00\x00");
    round_trip(
        &TriggerResponse {
            success: true,
            message: "ok".into(),
        },
        b"\x00\x01\x00\x00\x01\x00\x00\x00\x03\x00\x00\x00ok\x00",
    );
    round_trip(
        &JointState {
            header: Header {
                stamp: Time { sec: 1, nanosec: 2 },
                frame_id: "f".into(),
            },
            name: vec!["j".into()],
            position: vec![1.0],
            velocity: vec![],
            effort: vec![],
        },
        &[
            0x00, 0x01, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00, 0x02, 0x00,
            0x00, 0x00, 0x66, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x02, 0x00, 0x00, 0x00,
            0x6a, 0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
            0xf0, 0x3f, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
        ],
    );
}
