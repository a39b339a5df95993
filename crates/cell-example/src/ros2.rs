//! `--ros2`: the cell seen from ROS 2, through `rmw_zenoh`'s conventions (`imrs-ros2`).
//!
//! Node `/chip_cell` publishes every robot's joints on `/joint_states`
//! (`sensor_msgs/JointState`, every 50 ms of the cell's time while something moves), the
//! operator's alarms on `/alarms` (`std_msgs/String`), and serves `/status`
//! (`std_srvs/Trigger`): how many pallets each line has completed and how many alarms were
//! raised. Each goes through a port, as a module's would: JOINT_STATES and ALARMS are
//! `SENDALL` ports, STATUS a `RESPONSE` port answered by CELL_STATUS.

use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use imrs_core::EventKind;
use imrs_core::prelude::*;
use imrs_ports::{AnyUser, Port, PortSpec, usage};
use imrs_ros2::graph::NodeName;
use imrs_ros2::msgs::builtin_interfaces::Time;
use imrs_ros2::msgs::sensor_msgs::JointState;
use imrs_ros2::msgs::std_msgs::{self, Header};
use imrs_ros2::msgs::std_srvs::{Trigger, TriggerRequest, TriggerResponse};
use imrs_ros2::{Bridge, Node};
use imrs_sim::{Scene, Sim};
use imrs_zenoh::Host;
use tokio::sync::mpsc::unbounded_channel;
use tokio::task::JoinHandle;

use crate::run_error::RunError;
use crate::tally::Tally;

/// How often the joints are published, on the cell's clock, while something moves.
const JOINTS_PERIOD: Duration = Duration::from_millis(50);

/// What keeps the cell visible to ROS 2: dropped at the end of the run.
pub struct Ros2Cell {
    _bridges: [Bridge; 3],
    _node: Node,
    /// The session: it closes with its last handle, and ROS 2 sees the node go.
    _host: Host,
    tasks: Vec<JoinHandle<()>>,
}

impl Drop for Ros2Cell {
    fn drop(&mut self) {
        for task in &self.tasks {
            task.abort();
        }
    }
}

/// Makes the cell of `sim` and `cell` visible to ROS 2 on `endpoint`; `tally` is what the
/// report counts so far.
pub async fn serve(
    endpoint: &str,
    sim: &Sim,
    cell: &Cell,
    tally: Arc<Mutex<Tally>>,
) -> Result<Ros2Cell, RunError> {
    let failed = |error: &dyn std::fmt::Display| RunError::Ros2(error.to_string());
    let host = Host::builder("chip_cell")
        .listen(endpoint)
        .open()
        .await
        .map_err(|error| failed(&error))?;
    let name = NodeName::new(0, "/", "chip_cell").map_err(|error| failed(&error))?;
    let node = Node::new(&host, name)
        .await
        .map_err(|error| failed(&error))?;
    let mut tasks = Vec::new();

    // The joints, as rapier has the arms.
    let joints: Port<JointState, (), usage::SendAll, AnyUser, 1> =
        Port::new(PortSpec::new("JOINT_STATES", "SIM"));
    let joints_bridge = node
        .publish_port(&joints, "ROS2", "joint_states")
        .await
        .map_err(|error| failed(&error))?;
    let (seen, mut scenes) = unbounded_channel();
    sim.watch(JOINTS_PERIOD, move |scene| {
        let _ = seen.send(joint_state(scene));
    });
    let mut broadcaster = joints.owner().map_err(|error| failed(&error))?;
    tasks.push(tokio::spawn(async move {
        while let Some(state) = scenes.recv().await {
            if broadcaster.send_all(state).await.is_err() {
                break;
            }
        }
    }));

    // The alarms, as modules raise them.
    let alarms: Port<std_msgs::String, (), usage::SendAll, AnyUser, 1> =
        Port::new(PortSpec::new("ALARMS", "OPERATOR"));
    let alarms_bridge = node
        .publish_port(&alarms, "ROS2", "alarms")
        .await
        .map_err(|error| failed(&error))?;
    let (raised, mut raising) = unbounded_channel();
    cell.events().subscribe(move |event| {
        if let EventKind::Alarm { message } = &event.kind {
            let _ = raised.send(format!("{}: {message}", event.module));
        }
    });
    let mut operator = alarms.owner().map_err(|error| failed(&error))?;
    tasks.push(tokio::spawn(async move {
        while let Some(data) = raising.recv().await {
            if operator.send_all(std_msgs::String { data }).await.is_err() {
                break;
            }
        }
    }));

    // The status, answered at CELL_STATUS's turn.
    let status: Port<TriggerRequest, TriggerResponse, usage::Response, AnyUser, 1> =
        Port::new(PortSpec::new("STATUS", "CELL_STATUS"));
    let mut answering = status
        .answer(
            "CELL_STATUS",
            |tally: &Arc<Mutex<Tally>>, _: TriggerRequest| {
                let tally = tally.lock().unwrap_or_else(PoisonError::into_inner);
                TriggerResponse {
                    success: true,
                    message: format!(
                        "pallets completed: line A {}, line B {}; alarms: {}",
                        tally.lines[0].completed, tally.lines[1].completed, tally.alarms
                    ),
                }
            },
        )
        .map_err(|error| failed(&error))?;
    tasks.push(tokio::spawn(async move {
        while answering.serve(&tally).await.is_ok() {}
    }));
    let status_bridge = node
        .serve_port::<Trigger, _, 1>(&status, "ROS2", "status")
        .await
        .map_err(|error| failed(&error))?;
    Ok(Ros2Cell {
        _bridges: [joints_bridge, alarms_bridge, status_bridge],
        _node: node,
        _host: host,
        tasks,
    })
}

/// Every arm's shoulder and elbow, from its links as rapier places them: the shoulder
/// turned as the first link, the elbow as the second against the first. Stamped with the
/// wall clock, as ROS 2 stamps (the cell runs on it under `--ros2`).
fn joint_state(scene: &Scene) -> JointState {
    let now = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .unwrap_or_default();
    let mut state = JointState {
        header: Header {
            stamp: Time {
                sec: i32::try_from(now.as_secs()).unwrap_or(i32::MAX),
                nanosec: now.subsec_nanos(),
            },
            frame_id: "cell".into(),
        },
        ..JointState::default()
    };
    for arm in &scene.arms {
        let robot = arm.robot.to_string().replace('-', "_").to_lowercase();
        let [upper, fore] = arm.links;
        state.name.push(format!("{robot}_shoulder"));
        state.position.push(f64::from(upper.yaw));
        state.name.push(format!("{robot}_elbow"));
        state.position.push(f64::from(fore.yaw - upper.yaw));
    }
    state
}
