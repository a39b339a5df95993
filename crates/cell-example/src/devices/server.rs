//! The world's side: a module that owns a port per device and carries out each call on the
//! simulation, for the lines' modules in other processes.

use std::sync::Arc;
use std::sync::atomic::{AtomicU32, Ordering};

use imrs_core::prelude::*;
use imrs_ports::{AnyUser, Port, PortSpec, SharedClock, usage};
use imrs_sim::{Line, Sim};

use crate::names::LINE_SUPERVISOR;

use super::device::Device;
use super::wire::{Answer, DeviceAnswer, DeviceCall, MAX_SWEEP_SAMPLES, Op};
use super::{Devices, GateDevice, RelayDevice, RobotDevice};

/// The module of the world's process that serves the devices.
pub const WORLD: &str = "WORLD";

/// A device's port: the world receives calls from the one module that drives it, and from
/// the world's supervision of the lines, which drives a dead line's chip robot home.
pub type DevicePort = Port<DeviceCall, DeviceAnswer, usage::Receive, AnyUser, 2>;

/// The ports of every device of the cell, owned by [`WORLD`].
#[derive(Debug, Clone)]
pub struct DevicePorts {
    ports: Vec<(Device, DevicePort)>,
}

impl DevicePorts {
    /// Declares a port per device of both lines on `clock`, each for the module that
    /// drives the device only.
    pub fn declare(clock: &SharedClock) -> Self {
        let ports = Line::ALL
            .into_iter()
            .flat_map(Device::of_line)
            .map(|device| {
                let spec = PortSpec::new(device.port(), WORLD)
                    .clock(clock.clone())
                    .user_list([device.user(), LINE_SUPERVISOR.to_owned()]);
                (device, DevicePort::new(spec))
            })
            .collect();
        Self { ports }
    }

    /// Every port, with the device it serves.
    pub fn iter(&self) -> impl Iterator<Item = &DevicePort> {
        self.ports.iter().map(|(_, port)| port)
    }

    /// The port of `device`.
    pub fn of(&self, device: Device) -> Option<&DevicePort> {
        self.ports
            .iter()
            .find(|(served, _)| *served == device)
            .map(|(_, port)| port)
    }
}

/// The run of each line's process whose calls WORLD carries out (A, then B): raised by the
/// world's supervision when a line's process dies, before anything else is done for it, so
/// that no call the dead run left on its way is carried out after.
pub type LineRuns = Arc<[AtomicU32; 2]>;

/// WORLD: carries out each device call on the simulation and answers with its outcome. A
/// call the world cannot read is answered as such, and one of a run of its line's process
/// that has died ([`LineRuns`]) is not carried out; the world goes on serving.
pub fn world(ports: &DevicePorts, sim: &Sim, runs: &LineRuns) -> ModuleSpec<()> {
    let devices = Devices::Local(sim.clone());
    let mut spec = ModuleSpec::new(WORLD, ());
    for (device, port) in &ports.ports {
        let (device, port, devices) = (*device, port.clone(), devices.clone());
        let runs = Arc::clone(runs);
        spec = spec.task(device.port(), move |ctx| {
            let (port, devices, runs) = (port.clone(), devices.clone(), Arc::clone(&runs));
            async move {
                let mut calls = port.owner()?;
                let line = device.line().index();
                loop {
                    // One call at a time: a device does one thing at a time.
                    let (call, reply) = ctx.receive(&mut calls).await?;
                    if call.run() < runs[line].load(Ordering::Acquire) {
                        reply.reply(DeviceAnswer::new(&Answer::Stale));
                        continue;
                    }
                    let answer = match call.op() {
                        Some(op) => carry_out(&devices, device, op).await,
                        None => DeviceAnswer::new(&Answer::Malformed),
                    };
                    reply.reply(answer);
                }
            }
        });
    }
    spec
}

async fn carry_out(devices: &Devices, device: Device, op: Op) -> DeviceAnswer {
    match device {
        Device::Robot(id) => robot(&devices.robot(id), op).await,
        Device::Gate(line) => gate(&devices.gate(line), op).await,
        Device::Relay(line, station) => relay(&devices.relay(line, station), op).await,
    }
}

async fn robot(robot: &RobotDevice, op: Op) -> DeviceAnswer {
    match op {
        Op::Move(target) => DeviceAnswer::of(robot.move_to(target).await.map(|()| None)),
        Op::Grasp(feeder) => DeviceAnswer::of(robot.grasp(feeder).await),
        Op::Insert => DeviceAnswer::of(robot.insert().await),
        Op::PickCard => DeviceAnswer::of(robot.pick_card().await.map(|()| None)),
        Op::PlaceCard => DeviceAnswer::of(robot.place_card().await.map(|()| None)),
        Op::Screw => DeviceAnswer::of(robot.screw().await.map(|()| None)),
        Op::Sweep { from, to, samples } => {
            // No more steps than the answer has room for, whatever the call asks.
            let samples = (samples as usize).min(MAX_SWEEP_SAMPLES);
            DeviceAnswer::new(&match robot.sweep(from, to, samples).await {
                Ok(poses) => Answer::Sweep(poses),
                Err(error) => Answer::Failed(error),
            })
        }
        // A gate's or relay's call on a robot's port: a call the world cannot carry out.
        _ => DeviceAnswer::new(&Answer::Malformed),
    }
}

async fn gate(gate: &GateDevice, op: Op) -> DeviceAnswer {
    match op {
        Op::ReleasePallet => DeviceAnswer::of_release(gate.release().await),
        _ => DeviceAnswer::new(&Answer::Malformed),
    }
}

async fn relay(relay: &RelayDevice, op: Op) -> DeviceAnswer {
    match op {
        Op::WaitInPlace => DeviceAnswer::of(relay.wait_in_place().await.map(|pallet| pallet.0)),
        Op::LetGo => DeviceAnswer::of(relay.release().await.map(|pallet| pallet.0)),
        Op::ClearJam => DeviceAnswer::new(&match relay.clear_jam().await {
            Some(pallet) => Answer::Value(pallet.0),
            None => Answer::Done,
        }),
        _ => DeviceAnswer::new(&Answer::Malformed),
    }
}
