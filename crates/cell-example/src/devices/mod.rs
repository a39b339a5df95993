//! The cell's devices — robots, gates, freeze relays — as the modules see them: the
//! simulation's own handles when the world runs in the module's process, or ports to the
//! world's process when it runs in another (`chip_cell --processes`). The modules' code is
//! the same either way.

mod device;
mod remote;
mod server;
mod wire;

use std::sync::Arc;

use imrs_sim::{
    DeviceError, FeederId, Gate, Line, PalletId, Relay, Release, Robot, RobotId, Sim, Station,
    Target,
};

pub use device::Device;
pub use remote::{Link, RemoteDevices};
pub use server::{DevicePort, DevicePorts, LineRuns, WORLD, world};
pub use wire::{Answer, DeviceAnswer, DeviceCall, MAX_SWEEP_SAMPLES, Op, Pose};

/// Where the cell's devices are.
#[derive(Debug, Clone)]
pub enum Devices {
    /// In this process: the simulation itself.
    Local(Sim),
    /// In the world's process, reached through ports.
    Remote(Arc<RemoteDevices>),
}

impl Devices {
    /// The robot `id`.
    pub fn robot(&self, id: RobotId) -> RobotDevice {
        match self {
            Devices::Local(sim) => RobotDevice::Local(sim.robot(id)),
            Devices::Remote(remote) => RobotDevice::Remote(id, remote.link(Device::Robot(id))),
        }
    }

    /// The gate of `line`.
    pub fn gate(&self, line: Line) -> GateDevice {
        match self {
            Devices::Local(sim) => GateDevice::Local(sim.gate(line)),
            Devices::Remote(remote) => GateDevice::Remote(remote.link(Device::Gate(line))),
        }
    }

    /// The freeze relay of `line`'s `station`.
    pub fn relay(&self, line: Line, station: Station) -> RelayDevice {
        match self {
            Devices::Local(sim) => RelayDevice::Local(sim.relay(line, station)),
            Devices::Remote(remote) => {
                RelayDevice::Remote(line, station, remote.link(Device::Relay(line, station)))
            }
        }
    }
}

/// A robot.
#[derive(Debug, Clone)]
pub enum RobotDevice {
    /// The simulation's robot.
    Local(Robot),
    /// A robot in the world's process.
    Remote(RobotId, remote::Link),
}

impl RobotDevice {
    /// Which robot it is.
    pub fn id(&self) -> RobotId {
        match self {
            RobotDevice::Local(robot) => robot.id(),
            RobotDevice::Remote(id, _) => *id,
        }
    }

    /// The space the arm's links sweep from `from` (or where the tool is) to `to`: see
    /// [`Robot::sweep`]. Computed where the simulation runs: for a robot of another process,
    /// by a call to the world's, in at most [`MAX_SWEEP_SAMPLES`] steps.
    pub async fn sweep(
        &self,
        from: Option<Target>,
        to: Target,
        samples: usize,
    ) -> Result<Vec<Pose>, DeviceError> {
        match self {
            RobotDevice::Local(robot) => robot.sweep(from, to, samples),
            RobotDevice::Remote(id, link) => link.sweep(*id, from, to, samples).await,
        }
    }

    /// Moves the tool to `target`.
    pub async fn move_to(&self, target: Target) -> Result<(), DeviceError> {
        match self {
            RobotDevice::Local(robot) => robot.move_to(target).await,
            RobotDevice::Remote(id, link) => link.robot(*id, Op::Move(target)).await.map(drop),
        }
    }

    /// Grasps a chip from `feeder`; the chip's number.
    pub async fn grasp(&self, feeder: FeederId) -> Result<u32, DeviceError> {
        match self {
            RobotDevice::Local(robot) => robot.grasp(feeder).await,
            RobotDevice::Remote(id, link) => link.robot(*id, Op::Grasp(feeder)).await,
        }
    }

    /// Inserts the chip held; its number.
    pub async fn insert(&self) -> Result<u32, DeviceError> {
        match self {
            RobotDevice::Local(robot) => robot.insert().await,
            RobotDevice::Remote(id, link) => link.robot(*id, Op::Insert).await,
        }
    }

    /// Picks a card from the magazine.
    pub async fn pick_card(&self) -> Result<(), DeviceError> {
        match self {
            RobotDevice::Local(robot) => robot.pick_card().await,
            RobotDevice::Remote(id, link) => link.robot(*id, Op::PickCard).await.map(drop),
        }
    }

    /// Lays the card held on the pallet.
    pub async fn place_card(&self) -> Result<(), DeviceError> {
        match self {
            RobotDevice::Local(robot) => robot.place_card().await,
            RobotDevice::Remote(id, link) => link.robot(*id, Op::PlaceCard).await.map(drop),
        }
    }

    /// Screws the card down.
    pub async fn screw(&self) -> Result<(), DeviceError> {
        match self {
            RobotDevice::Local(robot) => robot.screw().await,
            RobotDevice::Remote(id, link) => link.robot(*id, Op::Screw).await.map(drop),
        }
    }
}

/// A line's gate.
#[derive(Debug, Clone)]
pub enum GateDevice {
    /// The simulation's gate.
    Local(Gate),
    /// A gate in the world's process.
    Remote(remote::Link),
}

impl GateDevice {
    /// Releases a pallet onto the line, unless the line backed up to the gate (or the
    /// world's process cannot be reached: then nothing was released).
    pub async fn release(&self) -> Release {
        match self {
            GateDevice::Local(gate) => gate.release().await,
            GateDevice::Remote(link) => link
                .call(Op::ReleasePallet)
                .await
                .and_then(|answer| answer.release())
                .unwrap_or(Release::BackedUp),
        }
    }
}

/// A station's freeze relay.
#[derive(Debug, Clone)]
pub enum RelayDevice {
    /// The simulation's relay.
    Local(Relay),
    /// A relay in the world's process.
    Remote(Line, Station, remote::Link),
}

impl RelayDevice {
    /// Waits until a pallet is held in place; which one.
    pub async fn wait_in_place(&self) -> Result<PalletId, DeviceError> {
        match self {
            RelayDevice::Local(relay) => relay.wait_in_place().await,
            RelayDevice::Remote(line, station, link) => link
                .relay(*line, *station, Op::WaitInPlace)
                .await
                .map(PalletId),
        }
    }

    /// Lets the held pallet go; which one.
    pub async fn release(&self) -> Result<PalletId, DeviceError> {
        match self {
            RelayDevice::Local(relay) => relay.release(),
            RelayDevice::Remote(line, station, link) => {
                link.relay(*line, *station, Op::LetGo).await.map(PalletId)
            }
        }
    }

    /// Takes a jammed pallet off the line; which one, if any.
    pub async fn clear_jam(&self) -> Option<PalletId> {
        match self {
            RelayDevice::Local(relay) => relay.clear_jam(),
            RelayDevice::Remote(line, station, link) => link
                .relay(*line, *station, Op::ClearJam)
                .await
                .ok()
                .map(PalletId),
        }
    }
}
