//! The gate that releases pallets, and the freeze relays that hold them at the stations.

use crate::error::DeviceError;
use crate::event::{SimEvent, SimEventKind};
use crate::ids::{Line, PalletId, Station};
use crate::layout::RELEASE_TIME;
use crate::sim::Sim;

/// A line's gate: a relay that lets one pallet onto the conveyor, and a photocell that says
/// whether the line is backed up to it.
#[derive(Debug, Clone)]
pub struct Gate {
    sim: Sim,
    line: Line,
}

/// What the gate did: the Appendix's return code (`RC=0` means a pallet was released).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Release {
    /// A pallet is on its way.
    Released(PalletId),
    /// The line is backed up to the gate: no pallet released.
    BackedUp,
}

impl Release {
    /// The Appendix's `RC`: 0 when a pallet was released.
    pub fn rc(self) -> i32 {
        match self {
            Release::Released(_) => 0,
            Release::BackedUp => 1,
        }
    }
}

// The simulation hands out its gates and relays here, beside what they are: each holds
// the simulation, so the simulation's own file names no device.
impl Sim {
    /// The gate of `line`.
    pub fn gate(&self, line: Line) -> Gate {
        Gate::new(self.clone(), line)
    }

    /// The freeze relay of `station` on `line`.
    pub fn relay(&self, line: Line, station: Station) -> Relay {
        Relay::new(self.clone(), line, station)
    }
}

impl Gate {
    fn new(sim: Sim, line: Line) -> Self {
        Self { sim, line }
    }

    /// Whether the photocell past the gate sees a pallet.
    pub fn photocell(&self) -> bool {
        let line = self.line;
        self.sim
            .with(|world, _| world.conveyor(line).photocell_blocked())
    }

    /// Lets one pallet go, unless the line is backed up.
    pub async fn release(&self) -> Release {
        self.sim.clock().sleep(RELEASE_TIME).await;
        let line = self.line;
        let released = self.sim.with(|world, now| {
            if world.conveyor(line).photocell_blocked() {
                return None;
            }
            let pallet = world.release_pallet(line);
            Some(SimEvent {
                at: now,
                kind: SimEventKind::PalletReleased { line, pallet },
            })
        });
        let Some(event) = released else {
            return Release::BackedUp;
        };
        let SimEventKind::PalletReleased { pallet, .. } = event.kind else {
            unreachable!("built just above");
        };
        self.sim.record(event);
        self.sim.wake_stepper();
        Release::Released(pallet)
    }
}

/// A station's freeze relay: it stops the next pallet in a known place, and frees it.
#[derive(Debug, Clone)]
pub struct Relay {
    sim: Sim,
    line: Line,
    station: Station,
}

impl Relay {
    fn new(sim: Sim, line: Line, station: Station) -> Self {
        Self { sim, line, station }
    }

    /// Waits until a pallet is held in place, and says which. A jammed pallet fails the wait.
    pub async fn wait_in_place(&self) -> Result<PalletId, DeviceError> {
        let (line, station) = (self.line, self.station);
        loop {
            let mut stepped = std::pin::pin!(self.sim.next_step());
            // Registered before looking, so that a step in between is not missed.
            stepped.as_mut().enable();
            match self.sim.with(|world, _| world.station_state(line, station)) {
                Some((pallet, false)) => return Ok(pallet),
                Some((_, true)) => return Err(DeviceError::Jam { line, station }),
                None => {}
            }
            stepped.await;
        }
    }

    /// Whether a pallet is held here now.
    pub fn holds(&self) -> Option<PalletId> {
        let (line, station) = (self.line, self.station);
        match self.sim.with(|world, _| world.station_state(line, station)) {
            Some((pallet, false)) => Some(pallet),
            _ => None,
        }
    }

    /// Frees the pallet held here, which rolls on.
    pub fn release(&self) -> Result<PalletId, DeviceError> {
        let (line, station) = (self.line, self.station);
        let freed = self.sim.with(|world, _| {
            if let Some((_, true)) = world.station_state(line, station) {
                return Err(DeviceError::Jam { line, station });
            }
            world
                .conveyor(line)
                .free(station)
                .ok_or(DeviceError::NoPallet { line, station })
        })?;
        self.sim.wake_stepper();
        Ok(freed)
    }

    /// Takes a jammed pallet off the line (an operator's hand); returns it, if there was one.
    pub fn clear_jam(&self) -> Option<PalletId> {
        let (line, station) = (self.line, self.station);
        let scrapped = self.sim.with(|world, _| world.scrap(line, station))?;
        let at = self.sim.now();
        self.sim.record(SimEvent {
            at,
            kind: SimEventKind::PalletScrapped {
                line,
                pallet: scrapped,
            },
        });
        self.sim.wake_stepper();
        Some(scrapped)
    }
}
