//! The running fold of a run's events into what the report needs: fed by subscribing to the
//! cell's and the simulation's logs, so that its memory depends on the pallets in flight and
//! the ports of the cell, never on the length of the run.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::{Mutex, MutexGuard, PoisonError};

use imrs_core::{Event, EventKind};
use imrs_ports::Name;
use imrs_sim::{Line, PalletId, RobotId, SimEvent, SimEventKind, Station};

use crate::alarms::AlarmKind;
use crate::chip::{chips_per_card, place_of_chip};

/// How far a chip may lie from its work-schedule place, in metres.
pub const PLACE_TOLERANCE: f32 = 0.001;

/// At most this many offending pallets are named per broken invariant; the rest are counted
/// in the invariant's verdict all the same.
const NAMED_OFFENDERS: usize = 16;

/// One line's figures: counted here as the events come, but for the pallets in progress and
/// the cycle, which the report adds at the end.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LineFigures {
    /// Pallets the gate released.
    pub released: u32,
    /// Pallets that left the line done.
    pub completed: u32,
    /// Of them, cards with every chip of the work schedule.
    pub good: u32,
    /// Of them, cards that left with a chip missing (a step failed: Shin 1985, note 5).
    pub short: u32,
    /// Pallets still on the conveyor at the end.
    pub in_progress: u32,
    /// Pallets taken off the line (jams).
    pub scrapped: u32,
    /// Chips on the completed cards.
    pub chips: u32,
    /// Seconds between completed pallets: mean and worst.
    pub cycle: Option<(f64, f64)>,
}

/// The gaps between completed pallets of one line: their sum (added gap by gap, in order),
/// their number and the worst.
#[derive(Debug, Clone, Default)]
pub struct Cycles {
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
    pub fn mean_and_worst(&self) -> Option<(f64, f64)> {
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
    /// Alarms per kind; `None` for an alarm raised without one (by the core itself).
    pub(crate) alarm_kinds: BTreeMap<Option<AlarmKind>, u32>,
    pub(crate) deadlocks: u32,
    pub(crate) last_deadlock: Option<f64>,
    /// The (module, port) waits of the deadlocks not yet broken.
    stuck: Vec<(Name, Name)>,
    /// Robot-seconds the members of deadlocks spent blocked in them.
    pub(crate) deadlock_lost: f64,
    /// Per line and station, the gaps between pallets held in place.
    pub(crate) stations: [[Cycles; 2]; 2],
    /// Chips whose place on the card was checked, the worst distance from the work
    /// schedule's place (metres), and the pallets with a chip beyond the tolerance.
    pub(crate) chips_checked: u32,
    pub(crate) worst_place: f32,
    pub(crate) misplaced: u32,
    pub(crate) misplaced_on: Vec<PalletId>,
    /// Per feeder, how often it was found empty and refilled.
    pub(crate) feeder_empties: [u32; 4],
    pub(crate) feeder_refills: [u32; 4],
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
                // Note 5: a card that missed a step leaves all the same, short.
                if *chips >= chips_per_card() {
                    figures.good += 1;
                } else {
                    figures.short += 1;
                }
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
            SimEventKind::ChipInserted {
                line,
                pallet,
                chip,
                on_card,
            } => {
                if !self.screwed.contains(&(*line, *pallet)) {
                    name(&mut self.early_chip, *pallet);
                }
                self.chips_checked += 1;
                let off = place_of_chip(*chip).map_or(f32::INFINITY, |place| {
                    ((on_card[0] - place[0]).powi(2) + (on_card[1] - place[1]).powi(2)).sqrt()
                });
                self.worst_place = self.worst_place.max(off);
                if off > PLACE_TOLERANCE {
                    self.misplaced += 1;
                    name(&mut self.misplaced_on, *pallet);
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
            SimEventKind::PalletInPlace { line, station, .. } => {
                let index = match station {
                    Station::Load => 0,
                    Station::Chip => 1,
                };
                self.stations[line.index()][index].done(at);
            }
            SimEventKind::FeederEmptied { feeder } => {
                if let Some(count) = self.feeder_empties.get_mut(usize::from(feeder.0)) {
                    *count += 1;
                }
            }
            SimEventKind::FeederRefilled { feeder, .. } => {
                if let Some(count) = self.feeder_refills.get_mut(usize::from(feeder.0)) {
                    *count += 1;
                }
            }
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
            EventKind::Alarm { message } => {
                self.alarms += 1;
                *self.alarm_kinds.entry(AlarmKind::of(message)).or_insert(0) += 1;
            }
            EventKind::Deadlock { cycle } => {
                self.deadlocks += 1;
                self.last_deadlock = Some(event.at.since_start().as_secs_f64());
                // A wait already counted (the same cycle reported again) is counted once.
                for member in cycle {
                    if !self.stuck.contains(member) {
                        self.stuck.push(member.clone());
                    }
                }
            }
            // A member of a deadlock is freed when its wait ends, by a reply or a timeout:
            // the whole wait was lost to the deadlock.
            EventKind::Sent { port, observed }
            | EventKind::Queried { port, observed }
            | EventKind::PortError { port, observed, .. } => {
                let member = (event.module.clone(), port.clone());
                if let Some(index) = self.stuck.iter().position(|stuck| *stuck == member) {
                    self.stuck.swap_remove(index);
                    // The chip cell observes its primitives, so every wait is measured.
                    self.deadlock_lost += observed
                        .as_ref()
                        .map_or(0.0, |observed| observed.waited.as_secs_f64());
                }
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

pub(crate) fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    // A fold is one call; a panic in it leaves the tally as the last whole event left it.
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
}
