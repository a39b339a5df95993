//! Everything a run measured and logged, as a run in one process and the world of a run
//! across processes both hand it back. Apart from the running, since the report is made from
//! it and the runs across processes make one too.

use std::time::Duration;

use imrs_core::{Cell, Event, ModuleTree};
use imrs_sim::{FeederId, Line, PalletId, RobotId, RobotTimes, Sim, SimEvent};

use crate::chip::ZoneWaits;
use crate::config::CellConfig;
use crate::gate::CycleTimeHistory;
use crate::outage::Outage;
use crate::tally::Tally;

/// Everything a run measured and logged.
#[derive(Debug, Clone)]
pub struct RunRecord {
    /// The configuration it ran with.
    pub config: CellConfig,
    /// Everything the report counts, folded from every event of the run.
    pub tally: Tally,
    /// The most recent physical facts from the simulation (at most
    /// [`CellConfig::kept_events`]; all of a short run).
    pub sim_events: Vec<SimEvent>,
    /// The most recent events of the modules (at most [`CellConfig::kept_events`]).
    pub cell_events: Vec<Event>,
    /// The pallets still on the conveyors at the end.
    pub pallets_left: Vec<(Line, PalletId, [f32; 3])>,
    /// The chip robots' waits for the zone.
    pub waits: [ZoneWaits; 2],
    /// The module tree at the end of the run, with its vertical and horizontal links.
    pub tree: ModuleTree,
    /// Each feeder at the end: its id, chip number and stock.
    pub feeders: Vec<(FeederId, u32, u32)>,
    /// How each robot spent its time, measured by the simulation.
    pub robot_times: Vec<(RobotId, RobotTimes)>,
    /// The closest two arms came while both were in the feeder zone (rapier), in metres.
    pub closest_in_zone: Option<f32>,
    /// Each line's GATE's CYCLE_TIME over the run.
    pub cycle_times: [CycleTimeHistory; 2],
    /// Simulated time.
    pub simulated: Duration,
    /// Wall time the run took.
    pub wall: Duration,
    /// Across processes: how late each process's timer woke at worst, in wall time (see
    /// [`crate::lateness`]). Empty in one process, on virtual time.
    pub lateness: Vec<(String, Duration)>,
    /// Across processes: each line's process that died, and its return.
    pub outages: Vec<Outage>,
    /// Across processes over zenoh: where the lines' hosts were.
    pub hosts: Option<String>,
}

impl RunRecord {
    /// The record of a run that simulated `simulated` with `sim`, its modules in `cell` (or,
    /// across processes, the world's), and what was folded from both; its wall time is set
    /// by the caller.
    pub(crate) fn measured(
        config: &CellConfig,
        tally: Tally,
        sim: &Sim,
        cell: &Cell,
        waits: [ZoneWaits; 2],
        cycle_times: [CycleTimeHistory; 2],
        simulated: Duration,
    ) -> Self {
        Self {
            config: config.clone(),
            tally,
            sim_events: sim.log().snapshot(),
            cell_events: cell.events().snapshot(),
            pallets_left: sim.pallets(),
            waits,
            tree: cell.tree(),
            feeders: sim.feeders(),
            robot_times: sim.robot_times(),
            closest_in_zone: sim.closest_in_zone(),
            cycle_times,
            simulated,
            wall: Duration::ZERO,
            lateness: Vec::new(),
            outages: Vec::new(),
            hosts: None,
        }
    }
}
