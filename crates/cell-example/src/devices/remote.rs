//! A line's devices reached through ports to the world's process.

use std::collections::BTreeMap;
use std::fmt;
use std::sync::Arc;

use crate::carrier::{Carrier, Imported};
use imrs_ports::{End, usage};
use imrs_sim::{DeviceError, Line, RobotId, Station, Target};
use tokio::sync::Mutex;

use super::device::Device;
use super::server::WORLD;
use super::wire::{Answer, DeviceAnswer, DeviceCall, MAX_SWEEP_SAMPLES, Op, Pose};

type DeviceEnd = End<DeviceCall, DeviceAnswer, usage::Send>;

/// The end a device's proxies send on, and the run of this line's process its calls are
/// sent from; `None` for a device this process did not import.
#[derive(Clone)]
pub struct Link(Option<(Arc<Mutex<DeviceEnd>>, u32)>);

impl fmt::Debug for Link {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(if self.0.is_some() {
            "Link(imported)"
        } else {
            "Link(none)"
        })
    }
}

impl Link {
    /// Calls the device and waits for its answer; `None` if the world's process could not
    /// be reached or answered with a record that does not decode.
    pub async fn call(&self, op: Op) -> Option<Answer> {
        let (end, run) = self.0.as_ref()?;
        // One call at a time per device, as a device does one thing at a time; a call
        // dropped halfway (its module killed) frees the end with it.
        let mut end = end.lock().await;
        let answer = end.send(DeviceCall::new(op).in_run(*run)).await.ok()?;
        answer.answer()
    }

    /// A robot's call: its value, or its error. A world that cannot be reached is a
    /// faulted robot to the module, which alarms and retries as for any fault.
    pub async fn robot(&self, robot: RobotId, op: Op) -> Result<u32, DeviceError> {
        match self.call(op).await {
            Some(Answer::Done) => Ok(0),
            Some(Answer::Value(value)) => Ok(value),
            Some(Answer::Failed(error)) => Err(error),
            Some(Answer::Malformed | Answer::Stale | Answer::Sweep(_)) | None => {
                Err(DeviceError::RobotFault { robot })
            }
        }
    }

    /// A robot's sweep, computed in the world's process: its poses, or its error. A world
    /// that cannot be reached is a faulted robot, as for any call.
    pub async fn sweep(
        &self,
        robot: RobotId,
        from: Option<Target>,
        to: Target,
        samples: usize,
    ) -> Result<Vec<Pose>, DeviceError> {
        // No more steps than the answer has room for: a coarser sweep, never a cut one.
        let samples = samples.min(MAX_SWEEP_SAMPLES) as u32;
        match self.call(Op::Sweep { from, to, samples }).await {
            Some(Answer::Sweep(poses)) => Ok(poses),
            Some(Answer::Failed(error)) => Err(error),
            Some(_) | None => Err(DeviceError::RobotFault { robot }),
        }
    }

    /// A relay's call: the pallet it names, or its error. A world that cannot be reached
    /// holds no pallet for the module.
    pub async fn relay(&self, line: Line, station: Station, op: Op) -> Result<u32, DeviceError> {
        match self.call(op).await {
            Some(Answer::Value(pallet)) => Ok(pallet),
            Some(Answer::Failed(error)) => Err(error),
            Some(Answer::Done | Answer::Malformed | Answer::Stale | Answer::Sweep(_)) | None => {
                Err(DeviceError::NoPallet { line, station })
            }
        }
    }
}

/// The devices of one line, imported from the world's process.
pub struct RemoteDevices {
    links: BTreeMap<Device, Link>,
    /// The bridges: the ports work while these are held.
    _imported: Vec<Imported<DeviceCall, DeviceAnswer>>,
}

impl fmt::Debug for RemoteDevices {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("RemoteDevices")
            .field("devices", &self.links.keys().collect::<Vec<_>>())
            .finish()
    }
}

impl RemoteDevices {
    /// Imports every device of `line` from the world's process, each for the module that
    /// drives it, whose calls are sent from `run` of the line's process. Call it within the
    /// tokio runtime the line runs on.
    pub async fn import(carrier: &Carrier, line: Line, run: u32) -> Result<Self, String> {
        let mut links = BTreeMap::new();
        let mut imported = Vec::new();
        for device in Device::of_line(line) {
            let user = device.user();
            let port: Imported<DeviceCall, DeviceAnswer> = carrier
                .import(&device.port(), WORLD, &user)
                .await
                .map_err(|error| error.to_string())?;
            let end = port
                .port()
                .user_named(user.as_str())
                .map_err(|error| error.to_string())?;
            links.insert(device, Link(Some((Arc::new(Mutex::new(end)), run))));
            imported.push(port);
        }
        Ok(Self {
            links,
            _imported: imported,
        })
    }

    /// The link to `device`: one that fails every call if this process did not import it.
    pub fn link(&self, device: Device) -> Link {
        self.links.get(&device).cloned().unwrap_or(Link(None))
    }
}
