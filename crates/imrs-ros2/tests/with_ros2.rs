//! A client that is not ours — Python's `eclipse-zenoh`, written only from `rmw_zenoh`'s
//! conventions — sees the cell in the ROS 2 graph, receives its joint states from a
//! `SENDALL` port published as a topic, and calls a `RESPONSE` port served as a service.

use std::net::TcpListener;
use std::process::Command;
use std::time::Duration;

use imrs_ports::{AnyUser, Port, PortSpec, usage};
use imrs_ros2::Node;
use imrs_ros2::graph::NodeName;
use imrs_ros2::msgs::sensor_msgs::JointState;
use imrs_ros2::msgs::std_msgs::Header;
use imrs_ros2::msgs::std_srvs::{Trigger, TriggerRequest, TriggerResponse};
use imrs_zenoh::Host;

/// The Python package the test drives, at the version of the zenoh crate.
const CLIENT: &str = "eclipse-zenoh==1.10.2";

/// Python 3 with `zenoh` importable, installed with pip where it is missing.
fn python_with_zenoh() -> &'static str {
    let has_zenoh = || {
        Command::new("python3")
            .args(["-c", "import zenoh"])
            .status()
            .is_ok_and(|status| status.success())
    };
    if !has_zenoh() {
        let installed = Command::new("python3")
            .args(["-m", "pip", "install", "--quiet", CLIENT])
            .status()
            .expect("python3 runs");
        assert!(installed.success(), "pip could not install {CLIENT}");
    }
    "python3"
}

fn free_endpoint() -> String {
    let listener = TcpListener::bind("127.0.0.1:0").expect("a free port on loopback");
    format!("tcp/{}", listener.local_addr().expect("its address"))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_ros_2_client_lists_the_cell_receives_its_joints_and_calls_its_status() {
    let python = python_with_zenoh();
    let endpoint = free_endpoint();
    let host = Host::builder("ros_cell")
        .listen(&endpoint)
        .open()
        .await
        .unwrap();
    let node = Node::new(&host, NodeName::new(0, "/", "chip_cell").unwrap())
        .await
        .unwrap();

    // A robot's joints, broadcast on a SENDALL port, published as /joint_states.
    let joints: Port<JointState, (), usage::SendAll, AnyUser, 1> =
        Port::new(PortSpec::new("JOINTS", "CHIP_IT"));
    let _joint_states = node
        .publish_port(&joints, "ROS2", "joint_states")
        .await
        .unwrap();
    let mut robot = joints.owner().unwrap();
    tokio::spawn(async move {
        let mut position = 0.0;
        // The robot's controller, at 50 Hz.
        let mut every = tokio::time::interval(Duration::from_millis(20));
        loop {
            every.tick().await;
            position += 0.01;
            let state = JointState {
                header: Header {
                    frame_id: "chip_it_base".into(),
                    ..Header::default()
                },
                name: vec!["shoulder".into(), "elbow".into()],
                position: vec![position, -position],
                ..JointState::default()
            };
            if robot.send_all(state).await.is_err() {
                break;
            }
        }
    });

    // The cell's status: a RESPONSE port answered at CELL's order, served as /status.
    let status: Port<TriggerRequest, TriggerResponse, usage::Response, AnyUser, 1> =
        Port::new(PortSpec::new("STATUS", "CELL"));
    let mut handler = status
        .answer("CELL", |pallets: &u32, _: TriggerRequest| TriggerResponse {
            success: true,
            message: format!("{pallets} pallets done"),
        })
        .unwrap();
    tokio::spawn(async move { while handler.serve(&12).await.is_ok() {} });
    let _status = node
        .serve_port::<Trigger, _, 1>(&status, "ROS2", "status")
        .await
        .unwrap();

    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/ros2_client.py");
    let client = tokio::process::Command::new(python)
        .args([script, &endpoint])
        .output();
    let output = tokio::time::timeout(Duration::from_secs(60), client)
        .await
        .expect("the Python client ended")
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr),
    );
    assert!(output.status.success(), "{stdout}\n{stderr}");
    let said: Vec<&str> = stdout.lines().collect();
    assert_eq!(said[0], "node /chip_cell", "{stdout}");
    assert_eq!(
        said[1],
        "MP /joint_states sensor_msgs::msg::dds_::JointState_ \
         RIHS01_a13ee3a330e346c9d87b5aa18d24e11690752bd33a0350f11c5882bc9179260e",
        "{stdout}"
    );
    assert_eq!(
        said[2],
        "SS /status std_srvs::srv::dds_::Trigger_ \
         RIHS01_eeff2cd6fa5ad9d27cdf4dec64818317839b62f212a91e6b5304b634b2062c5f",
        "{stdout}"
    );
    assert!(
        said[3].starts_with("joint_states chip_it_base ['shoulder', 'elbow'] ["),
        "{stdout}"
    );
    assert_eq!(said[4], "status True 12 pallets done", "{stdout}");
}
