//! The running fold of a run's events into what the report needs: fed by subscribing to the
//! cell's and the simulation's logs, so that its memory depends on the pallets in flight and
//! the ports of the cell, never on the length of the run.

use std::collections::{BTreeMap, BTreeSet};

use imrs_sim::imrs_core::{Event, EventKind};
use imrs_sim::{Line, PalletId, RobotId, SimEvent, SimEventKind};

use crate::report::LineFigures;

/// At most this many offending pallets are named per broken invariant; the rest are counted
/// in the invariant's verdict all the same.
const NAMED_OFFENDERS: usize = 16;

/// The gaps between completed pallets of one line: their sum (added gap by gap, in order),
/// their number and the worst.
#[derive(Debug, Clone, Default)]
pub(crate) struct Cycles {
    last_done: Option<f64>,
    sum: f64,
    count: u32,
    worst: f64,
}

impl Cycles {
    fn done(&mut self, at: f64) {
        if let Some(last) = self.last_done {
            let gap = at - last;
            self.sum += gap;
            self.count += 1;
            self.worst = self.worst.max(gap);
        }
        self.last_done = Some(at);
    }

    /// The mean and worst gap, once there is one.
    pub(crate) fn mean_and_worst(&self) -> Option<(f64, f64)> {
        (self.count > 0).then(|| (self.sum / f64::from(self.count), self.worst))
    }
}

/// Everything the report counts, folded as the events come.
#[derive(Debug, Clone, Default)]
pub struct Tally {
    pub(crate) lines: [LineFigures; 2],
    pub(crate) cycles: [Cycles; 2],
    /// Cards placed and screwed on pallets still on the line: forgotten when the pallet
    /// leaves it.
    placed: BTreeSet<(Line, PalletId)>,
    screwed: BTreeSet<(Line, PalletId)>,
    pub(crate) early_screw: Vec<PalletId>,
    pub(crate) early_chip: Vec<PalletId>,
    inside: BTreeMap<RobotId, f64>,
    pub(crate) zone_entries: [u32; 2],
    pub(crate) zone_conflicts: u32,
    shared_since: Option<f64>,
    pub(crate) zone_shared: f64,
    pub(crate) collisions: u32,
    pub(crate) chips_inserted_after: [Option<f64>; 2],
    pub(crate) timeouts: BTreeMap<String, u32>,
    pub(crate) restarts: u32,
    pub(crate) alarms: u32,
    pub(crate) deadlocks: u32,
    pub(crate) last_deadlock: Option<f64>,
}

fn name(offenders: &mut Vec<PalletId>, pallet: PalletId) {
    if offenders.len() < NAMED_OFFENDERS {
        offenders.push(pallet);
    }
}

impl Tally {
    /// Folds one physical fact of the simulation.
    pub fn sim(&mut self, event: &SimEvent) {
        let at = event.at.since_start().as_secs_f64();
        match &event.kind {
            SimEventKind::PalletReleased { line, .. } => self.lines[line.index()].released += 1,
            SimEventKind::PalletDone {
                line,
                pallet,
                chips,
                ..
            } => {
                let figures = &mut self.lines[line.index()];
                figures.completed += 1;
                figures.chips += chips;
                self.cycles[line.index()].done(at);
                self.left_the_line(*line, *pallet);
            }
            SimEventKind::PalletScrapped { line, pallet, .. } => {
                self.lines[line.index()].scrapped += 1;
                self.left_the_line(*line, *pallet);
            }
            SimEventKind::CardPlaced { line, pallet } => {
                self.placed.insert((*line, *pallet));
            }
            SimEventKind::CardScrewed { line, pallet } => {
                if !self.placed.contains(&(*line, *pallet)) {
                    name(&mut self.early_screw, *pallet);
                }
                self.screwed.insert((*line, *pallet));
            }
            SimEventKind::ChipInserted { line, pallet, .. } => {
                if !self.screwed.contains(&(*line, *pallet)) {
                    name(&mut self.early_chip, *pallet);
                }
                self.chips_inserted_after[line.index()] = Some(at);
            }
            SimEventKind::ZoneEntered { robot } => {
                self.zone_entries[robot.line.index()] += 1;
                if !self.inside.is_empty() {
                    self.zone_conflicts += 1;
                    self.shared_since = Some(at);
                }
                self.inside.insert(*robot, at);
            }
            SimEventKind::ZoneLeft { robot } => {
                self.inside.remove(robot);
                if let Some(since) = self.shared_since.take() {
                    self.zone_shared += at - since;
                }
            }
            SimEventKind::Collision { .. } => self.collisions += 1,
            _ => {}
        }
    }

    /// Folds one event of the cell's modules.
    pub fn cell(&mut self, event: &Event) {
        match &event.kind {
            EventKind::ExceptionRaised { exception } => {
                if let Some(port) = exception.as_str().strip_suffix(".TIMEOUT") {
                    *self.timeouts.entry(port.to_string()).or_insert(0) += 1;
                }
            }
            EventKind::TaskRestarted { .. } | EventKind::ModuleRestarted { .. } => {
                self.restarts += 1;
            }
            EventKind::Alarm { .. } => self.alarms += 1,
            EventKind::Deadlock { .. } => {
                self.deadlocks += 1;
                self.last_deadlock = Some(event.at.since_start().as_secs_f64());
            }
            _ => {}
        }
    }

    fn left_the_line(&mut self, line: Line, pallet: PalletId) {
        self.placed.remove(&(line, pallet));
        self.screwed.remove(&(line, pallet));
    }

    /// How many entries the tally holds that grow with pallets in flight: for tests that
    /// check its memory stays flat.
    pub fn in_flight(&self) -> usize {
        self.placed.len() + self.screwed.len()
    }
}
