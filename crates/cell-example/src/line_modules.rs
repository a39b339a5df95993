//! The modules of one line, declared and started the same way in a run in one process and
//! in a line's own process across processes. Apart from both, since each starts them.

use std::sync::Arc;
use std::time::Duration;

use imrs_core::prelude::*;
use imrs_core::{CellErrors, ModuleDecl};
use imrs_sim::Line;

use crate::chip::{SharedWaits, chip_it};
use crate::devices::Devices;
use crate::feeder_policy::FeederPolicy;
use crate::gate::{ReleaseDeath, SharedCycleTimes, gate};
use crate::load::{load_card, load_it, screw_in_card};
use crate::ports::CellPorts;

/// The modules of one line, and what they share with the run: everything needed to
/// declare them for the wiring check and to start them, in one process or in a line's own.
pub(crate) struct LineModules {
    pub(crate) line: Line,
    /// Which run of the line's process this is: 0 in one process, counted by the world
    /// across processes.
    pub(crate) run: u32,
    pub(crate) feeder: FeederPolicy,
    pub(crate) ports: CellPorts,
    pub(crate) devices: Devices,
    pub(crate) death: ReleaseDeath,
    pub(crate) history: SharedCycleTimes,
    pub(crate) waits: SharedWaits,
}

impl LineModules {
    /// GATE, LOAD_IT (with its children LOAD_CARD and SCREW_IN_CARD) and CHIP_IT, declared.
    pub(crate) fn declarations(&self) -> Vec<ModuleDecl> {
        let (line, lines) = (self.line, &self.ports.lines[self.line.index()]);
        let history = Arc::clone(&self.history);
        let waits = Arc::clone(&self.waits);
        vec![
            gate(line, lines, &self.devices, Arc::clone(&self.death), history).declaration(),
            load_it(line, lines, &self.devices).declaration(),
            load_card(line, lines, &self.devices).declaration(),
            screw_in_card(line, lines, &self.devices).declaration(),
            chip_it(
                line,
                self.run,
                self.feeder,
                &self.ports,
                &self.devices,
                waits,
            )
            .declaration(),
        ]
    }

    /// Starts the line's modules in `cell`: GATE and CHIP_IT supervised, restarted as a
    /// cell engineer would want; LOAD_IT starts its own children.
    pub(crate) fn start(self, cell: &Cell) -> Result<(), CellErrors> {
        let policy = RestartPolicy::restart(3, Duration::from_secs(5));
        let (line, lines) = (self.line, self.ports.lines[self.line.index()].clone());
        let (gate_lines, gate_devices) = (lines.clone(), self.devices.clone());
        let (death, history) = (self.death, self.history);
        cell.supervise(policy, move || {
            gate(
                line,
                &gate_lines,
                &gate_devices,
                Arc::clone(&death),
                Arc::clone(&history),
            )
        })?;
        cell.start(load_it(line, &lines, &self.devices))?;
        let (ports, devices, waits, feeder) = (self.ports, self.devices, self.waits, self.feeder);
        let run = self.run;
        cell.supervise(policy, move || {
            chip_it(line, run, feeder, &ports, &devices, Arc::clone(&waits))
        })?;
        Ok(())
    }
}
