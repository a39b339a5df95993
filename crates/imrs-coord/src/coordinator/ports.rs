//! The coordinator's ports, declared together, and a robot's ends of them.

use std::collections::BTreeMap;

use imrs_core::Cell;
use imrs_ports::{AnyUser, Name, Port, PortSpec, SharedClock, usage};

use super::messages::{Geometry, Message, Seen, Wake};
use super::robot::RobotLink;
use crate::zones::Answer;

/// How many robots a coordinator's ports admit.
pub const MAX_ROBOTS: usize = 16;

/// The coordinator's ports. Declare them, give each robot its [`RobotLink`], and start
/// [`coordinator`](super::coordinator).
#[derive(Clone)]
pub struct CoordinatorPorts {
    /// `TO_COORDINATOR`: requests, positions, releases, trajectory ends.
    pub to_coordinator:
        Port<(Name, Message), Result<Answer, String>, usage::Receive, AnyUser, MAX_ROBOTS>,
    /// `SPACE`: positions, checks of the way ahead, alternative trajectories.
    pub space: Port<(Name, Geometry), Result<Seen, String>, usage::Receive, AnyUser, MAX_ROBOTS>,
    /// `ALARM`.
    pub alarm: Port<(Name, String), (), usage::Receive, AnyUser, MAX_ROBOTS>,
    /// `EMERGENCY`: the emergency stop, to every robot.
    pub emergency: Port<String, (), usage::SendAll, AnyUser, MAX_ROBOTS>,
    /// `WAKE_<ROBOT>`, one per robot.
    pub wake: BTreeMap<Name, Port<Wake, (), usage::Send>>,
}

impl CoordinatorPorts {
    /// The ports of a coordinator named `name` for `robots`, on `clock`.
    pub fn new(name: &str, robots: &[&str], clock: &SharedClock) -> Self {
        let spec = |port: String| PortSpec::new(port, name).clock(clock.clone());
        Self {
            to_coordinator: Port::new(spec("TO_COORDINATOR".into()).priority(2)),
            space: Port::new(spec("SPACE".into()).priority(2)),
            alarm: Port::new(spec("ALARM".into()).priority(1)),
            emergency: Port::new(spec("EMERGENCY".into()).priority(1)),
            wake: robots
                .iter()
                .map(|&robot| {
                    let port = Port::new(spec(format!("WAKE_{robot}")).user_list([robot]));
                    (Name::from(robot), port)
                })
                .collect(),
        }
    }

    /// Declares every port to `cell`, so that the cell checks their wiring and lists them
    /// ([`Cell::ports`]).
    pub fn declare_to(&self, cell: &Cell) -> Result<(), imrs_ports::WireError> {
        cell.declare(&self.to_coordinator)?;
        cell.declare(&self.space)?;
        cell.declare(&self.alarm)?;
        cell.declare(&self.emergency)?;
        self.wake.values().try_for_each(|port| cell.declare(port))
    }

    /// Robot `robot`'s ends of the ports.
    pub fn link(&self, robot: &str) -> Result<RobotLink, imrs_ports::WireError> {
        let wake = self.wake.get(&Name::from(robot)).ok_or_else(|| {
            imrs_ports::WireError::NotOnUserList {
                port: format!("WAKE_{robot}").into(),
                module: robot.into(),
            }
        })?;
        Ok(RobotLink {
            robot: robot.into(),
            to: self.to_coordinator.user_named(robot)?,
            space: self.space.user_named(robot)?,
            alarm: self.alarm.user_named(robot)?,
            wake: wake.user_named(robot)?,
            emergency: self.emergency.user_named(robot)?,
        })
    }
}
