//! Clients that are not ours see the cell in the ROS 2 graph, receive its joint states from
//! a `SENDALL` port published as a topic, and call a `RESPONSE` port served as a service:
//! a Python client written only from `rmw_zenoh`'s conventions, on `eclipse-zenoh`, and
//! `zenoh-ros2-sdk`, a ROS 2 client on those conventions from PyPI that computes the type
//! hashes and keys itself.

use std::time::Duration;

use imrs_ports::{AnyUser, Port, PortSpec, usage};
use imrs_ros2::graph::NodeName;
use imrs_ros2::msgs::sensor_msgs::JointState;
use imrs_ros2::msgs::std_msgs::{self, Header};
use imrs_ros2::msgs::std_srvs::{Trigger, TriggerRequest, TriggerResponse};
use imrs_ros2::{Bridge, Node, ros_message, ros_service};
use imrs_testkit::{free_endpoint, python_with};
use imrs_zenoh::Host;

/// The Python packages the tests drive: zenoh at the version of the zenoh crate, and the
/// ROS 2 client on it.
const ZENOH: &str = "eclipse-zenoh==1.10.2";
const ROS2_CLIENT: &str = "zenoh-ros2-sdk==0.1.8";

/// A host listening on `endpoint`, with node /chip_cell on it.
async fn chip_cell_node(endpoint: &str) -> (Host, Node) {
    let host = Host::builder("ros_cell")
        .listen(endpoint)
        .open()
        .await
        .unwrap();
    let node = Node::new(&host, NodeName::new(0, "/", "chip_cell").unwrap())
        .await
        .unwrap();
    (host, node)
}

/// What the cell holds while a client looks at it.
struct RosCell {
    _host: Host,
    _node: Node,
    _bridges: [Bridge; 3],
}

ros_message! {
    /// `example_interfaces/srv/AddTwoInts`'s request, declared here as a cell declares its own.
    struct AddTwoIntsRequest = "example_interfaces/srv/AddTwoInts_Request" {
        a: i64,
        b: i64,
    }
}

ros_message! {
    /// Its response.
    struct AddTwoIntsResponse = "example_interfaces/srv/AddTwoInts_Response" {
        sum: i64,
    }
}

ros_service! {
    /// `example_interfaces/srv/AddTwoInts`: its hash computed here from these declarations.
    service AddTwoInts = "example_interfaces/srv/AddTwoInts" {
        request: AddTwoIntsRequest,
        response: AddTwoIntsResponse,
    }
}

/// A cell on `endpoint` with node /chip_cell: CHIP_IT's joints broadcast at 50 Hz on a
/// SENDALL port published as /joint_states, and the cell's status, a RESPONSE port answered
/// at CELL's order, served as /status (std_srvs/Trigger); and /add_two_ints, a service of
/// the cell's own declaring.
async fn ros_cell(endpoint: &str) -> RosCell {
    let (host, node) = chip_cell_node(endpoint).await;

    // A robot's joints, broadcast on a SENDALL port, published as /joint_states.
    let joints: Port<JointState, (), usage::SendAll, AnyUser, 1> =
        Port::new(PortSpec::new("JOINTS", "CHIP_IT"));
    let joint_states = node
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
    let served = node
        .serve_port::<Trigger, _, 1>(&status, "ROS2", "status")
        .await
        .unwrap();
    // A service of the cell's own declaring, its hash computed from its fields.
    let adding: Port<AddTwoIntsRequest, AddTwoIntsResponse, usage::Response, AnyUser, 1> =
        Port::new(PortSpec::new("ADD", "CALCULATOR"));
    let mut calculator = adding
        .answer("CALCULATOR", |(): &(), asked: AddTwoIntsRequest| {
            AddTwoIntsResponse {
                sum: asked.a + asked.b,
            }
        })
        .unwrap();
    tokio::spawn(async move { while calculator.serve(&()).await.is_ok() {} });
    let add = node
        .serve_port::<AddTwoInts, _, 1>(&adding, "ROS2", "add_two_ints")
        .await
        .unwrap();
    RosCell {
        _host: host,
        _node: node,
        _bridges: [joint_states, served, add],
    }
}

/// Runs `script` with `args` to its end (60 s at most): what it printed, once it succeeded.
async fn client(python: &str, script: &str, args: &[&str]) -> String {
    let script = format!("{}/tests/{script}", env!("CARGO_MANIFEST_DIR"));
    let run = tokio::process::Command::new(python)
        .arg(script)
        .args(args)
        .output();
    let output = tokio::time::timeout(Duration::from_secs(60), run)
        .await
        .expect("the Python client ended")
        .unwrap();
    let (stdout, stderr) = (
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr),
    );
    assert!(output.status.success(), "{stdout}\n{stderr}");
    stdout.into_owned()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_client_on_rmw_zenohs_conventions_lists_the_cell_receives_its_joints_and_calls_it() {
    let python = python_with("zenoh", ZENOH);
    let endpoint = free_endpoint();
    let _cell = ros_cell(&endpoint).await;
    let stdout = client(python, "ros2_client.py", &[&endpoint]).await;
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

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn zenoh_ros2_sdk_lists_the_cell_receives_its_joints_and_calls_its_status() {
    let python = python_with("zenoh_ros2_sdk", ROS2_CLIENT);
    let endpoint = free_endpoint();
    let _cell = ros_cell(&endpoint).await;
    let messages = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/ros2_msgs");
    let stdout = client(python, "ros2_sdk_client.py", &[&endpoint, messages]).await;
    let said: Vec<&str> = stdout.lines().collect();
    assert_eq!(
        said,
        [
            "topic /joint_states ['sensor_msgs/msg/JointState']",
            "service /status ['std_srvs/srv/Trigger']",
            "joint_states chip_it_base ['shoulder', 'elbow']",
            "status True 12 pallets done",
            "add_two_ints 2 + 40 = 42",
        ],
        "{stdout}"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_module_hears_a_ros_2_topic_and_calls_a_ros_2_service_through_its_ports() {
    let python = python_with("zenoh", ZENOH);
    let endpoint = free_endpoint();
    let (_host, node) = chip_cell_node(&endpoint).await;
    // OPERATOR_DESK receives /commands on a port of its own.
    let commands: Port<std_msgs::String, (), usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("COMMANDS", "OPERATOR_DESK"));
    let _commands = node
        .subscribe_port(&commands, "ROS2", "commands")
        .await
        .unwrap();
    let mut desk = commands.owner().unwrap();
    // CALCULATOR calls /add_two_ints by sending on ADDER, which the bridge owns.
    let adder: Port<AddTwoIntsRequest, AddTwoIntsResponse, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new("ADDER", "ROS2"));
    let _adder = node
        .call_port::<AddTwoInts, _, 1>(&adder, "add_two_ints")
        .await
        .unwrap();
    let mut calculator = adder.user_named("CALCULATOR").unwrap();

    let script = format!("{}/tests/ros2_peer.py", env!("CARGO_MANIFEST_DIR"));
    let mut peer = tokio::process::Command::new(python)
        .args([script.as_str(), endpoint.as_str()])
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .kill_on_drop(true)
        .spawn()
        .unwrap();
    let (command, reply) = tokio::time::timeout(Duration::from_secs(30), desk.receive())
        .await
        .expect("a command within 30 s")
        .unwrap();
    reply.reply(());
    assert!(command.data.starts_with("start "), "{command:?}");
    let sum = tokio::time::timeout(
        Duration::from_secs(30),
        calculator.send(AddTwoIntsRequest { a: 2, b: 40 }),
    )
    .await
    .expect("an answer within 30 s");
    assert_eq!(sum.map(|response| response.sum).ok(), Some(42));

    // The peer is gone: a call has no server, and its sender's wait ends.
    drop(peer.stdin.take());
    peer.wait().await.unwrap();
    let unanswered = tokio::time::timeout(
        Duration::from_secs(30),
        calculator.send(AddTwoIntsRequest { a: 1, b: 1 }),
    )
    .await
    .expect("the call ends");
    assert!(unanswered.is_err(), "{:?}", unanswered.map(|r| r.sum));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_flood_of_requests_is_refused_past_the_room_and_grows_nothing() {
    let endpoint = free_endpoint();
    let (host, node) = chip_cell_node(&endpoint).await;
    // A status nobody answers yet: every request waits.
    let status: Port<TriggerRequest, TriggerResponse, usage::Response, AnyUser, 1> =
        Port::new(PortSpec::new("STATUS", "CELL"));
    let _handler = status
        .answer("CELL", |(): &(), _: TriggerRequest| {
            TriggerResponse::default()
        })
        .unwrap();
    let _status = node
        .serve_port::<Trigger, _, 1>(&status, "ROS2", "status")
        .await
        .unwrap();
    let flooder = Host::builder("ros_cell")
        .connect(endpoint.as_str())
        .open()
        .await
        .unwrap();
    let key = format!(
        "0/status/{}/{}",
        <Trigger as imrs_ros2::RosService>::dds_type_name(),
        <Trigger as imrs_ros2::RosService>::type_hash()
    );
    let request = imrs_zenoh::encode("status", &TriggerRequest::default()).unwrap();
    let mut asked = Vec::new();
    for n in 0..100 {
        let attachment = imrs_ros2::Attachment::now(n + 1, [9; 16])
            .to_bytes()
            .to_vec();
        let replies = flooder
            .session()
            .get(key.as_str())
            .payload(request.clone())
            .attachment(attachment)
            .timeout(Duration::from_secs(5))
            .await
            .unwrap();
        asked.push(replies);
    }
    // A refusal comes at once; a request that waits ends with zenoh's 5 s timeout.
    let refusal = format!("/status: {} requests wait already", imrs_ros2::MOST_WAITING);
    let (mut refused, mut waited) = (0, 0);
    for replies in &asked {
        let reply = replies.recv_async().await.unwrap();
        let why = reply
            .result()
            .unwrap_err()
            .payload()
            .to_bytes()
            .into_owned();
        match String::from_utf8(why).unwrap() {
            why if why == refusal => refused += 1,
            why if why == "Timeout" => waited += 1,
            why => panic!("{why}"),
        }
    }
    assert_eq!(
        (refused, waited),
        (100 - imrs_ros2::MOST_WAITING, imrs_ros2::MOST_WAITING)
    );
    drop(host);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_topic_whose_port_is_closed_for_good_leaves_the_graph() {
    let endpoint = free_endpoint();
    let (host, node) = chip_cell_node(&endpoint).await;
    let joints: Port<JointState, (), usage::SendAll, AnyUser, 1> =
        Port::new(PortSpec::new("JOINTS", "CHIP_IT"));
    let _topic = node
        .publish_port(&joints, "ROS2", "joint_states")
        .await
        .unwrap();
    let publishers = || async {
        let replies = host
            .session()
            .liveliness()
            .get("@ros2_lv/0/**")
            .await
            .unwrap();
        let mut found = 0;
        while let Ok(reply) = replies.recv_async().await {
            found += usize::from(
                reply
                    .result()
                    .is_ok_and(|token| token.key_expr().as_str().contains("/MP/")),
            );
        }
        found
    };
    let robot = joints.owner().unwrap();
    assert_eq!(publishers().await, 1);
    // The port is closed for good: its owner's end and every handle to it dropped (while
    // a handle is left, a restarted owner may attach again, and the topic waits for it).
    drop(robot);
    drop(joints);
    let gone = tokio::time::timeout(Duration::from_secs(30), async {
        while publishers().await > 0 {
            tokio::task::yield_now().await;
        }
    })
    .await;
    assert!(gone.is_ok(), "the topic stayed in the graph");
}
