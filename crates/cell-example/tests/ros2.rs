//! `chip_cell --ros2`: a ROS 2 user sees the cell live. zenoh-ros2-sdk (PyPI, a ROS 2 client
//! on `rmw_zenoh`'s conventions, not ours) lists the cell's topics and service, reads the
//! robots' joints, receives the alarm a robot fault raises, and asks the status.

use std::process::{Command, Stdio};

use cell_example::alarms::AlarmKind;
use imrs_testkit::{example_binary, free_endpoint, python_with};

/// The Python package the test drives: a ROS 2 client on `rmw_zenoh`'s conventions.
const ROS2_CLIENT: &str = "zenoh-ros2-sdk==0.1.8";

#[test]
#[cfg_attr(
    not(feature = "ros2"),
    ignore = "needs the `ros2` feature: cargo test --workspace --all-features"
)]
fn a_ros_2_client_lists_the_cell_reads_its_joints_and_alarms_and_asks_its_status() {
    let python = python_with("zenoh_ros2_sdk", ROS2_CLIENT);
    let endpoint = free_endpoint();
    // Twenty seconds on the wall clock, line A's RELEASE dying at 10 s: an alarm.
    let cell = Command::new(example_binary("chip_cell"))
        .args([
            "--ros2",
            &endpoint,
            "--hours",
            "0.0056",
            "--fault",
            "release:A@10s",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the example is built with the tests");
    let messages = concat!(env!("CARGO_MANIFEST_DIR"), "/../imrs-ros2/tests/ros2_msgs");
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/ros2_view.py");
    // Ended by `timeout` if it hangs: a test never waits for ever.
    let viewer = Command::new("timeout")
        .args(["60", python, script, &endpoint, messages])
        .output()
        .expect("the client runs");
    let ended = cell.wait_with_output().expect("the cell ends");
    let (said, why) = (
        String::from_utf8_lossy(&viewer.stdout),
        String::from_utf8_lossy(&viewer.stderr),
    );
    let report = String::from_utf8_lossy(&ended.stdout);
    assert!(
        viewer.status.success(),
        "{said}\n{why}\nthe cell's report:\n{report}"
    );
    assert!(
        ended.status.success(),
        "{}",
        String::from_utf8_lossy(&ended.stderr)
    );
    let said: Vec<&str> = said.lines().collect();
    assert_eq!(said[0], "topic /alarms ['std_msgs/msg/String']");
    assert_eq!(
        said[1],
        "topic /joint_states ['sensor_msgs/msg/JointState']"
    );
    assert_eq!(said[2], "service /status ['std_srvs/srv/Trigger']");
    // Three robots on each line, a shoulder and an elbow each.
    assert_eq!(
        said[3],
        "joints 12 ['chip_robot_a_elbow', 'chip_robot_a_shoulder']"
    );
    // "MODULE: [kind] what", as a module raised it.
    let alarm = said[4].strip_prefix("alarm ").unwrap();
    let (module, message) = alarm.split_once(": ").unwrap();
    assert!(!module.is_empty(), "{alarm}");
    assert!(AlarmKind::of(message).is_some(), "{alarm}");
    assert!(
        said[5].starts_with("status True pallets completed: line A "),
        "{}",
        said[5]
    );
}
