//! What a policy sees when it chooses, and the progress of a run behind it: apart from the
//! run, so that a policy, which the run asks, reads the state without depending on the run.

use super::cell::{Arrivals, Workcell, distance};
use super::way::{detour, entry};

/// Where a robot is in a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct RobotState {
    pub(super) free_at: f64,
    pub(super) at: [f64; 2],
}

/// What has happened so far in a run: the time, which tasks are done or taken, where the
/// robots are and when they are free, and when the zone is.
#[derive(Debug, Clone)]
pub(super) struct Progress {
    pub(super) now: f64,
    pub(super) done: Vec<Vec<bool>>,
    pub(super) taken: Vec<Vec<bool>>,
    pub(super) robots: Vec<RobotState>,
    /// When each zone is free.
    pub(super) zone_free_at: Vec<f64>,
    /// The task that holds each zone until then: (unit, task).
    pub(super) zone_task: Vec<Option<(usize, usize)>>,
}

/// What a policy sees when it chooses: the time, which tasks are done or taken, the parts
/// that have come, where the robots are and when they are free, and when the zone is.
#[derive(Debug)]
pub struct State<'a> {
    pub(super) cell: &'a Workcell,
    pub(super) arrivals: &'a Arrivals,
    pub(super) progress: &'a Progress,
}

/// How a robot would do a task, worked out ahead: when it would start, how long it would
/// wait at the borders of the zones on its way (their entry points computed), which
/// robots at work it would have to go round, and when it would be done.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// When it would start the task's work.
    pub start: f64,
    /// How long it would wait for zones: those it crosses on its way, and the task's.
    pub zone_wait: f64,
    /// The zones on its way, not the task's, that it would wait to enter.
    pub zones_crossed: usize,
    /// The robots at work that its straight way passes too near: the coordinator would
    /// send it round each, on an alternative trajectory.
    pub in_the_way: usize,
    /// How much longer its way is round them, in metres.
    pub detour: f64,
    /// When it would be done.
    pub finish: f64,
}

impl<'a> State<'a> {
    /// The cell.
    pub fn cell(&self) -> &Workcell {
        self.cell
    }

    /// The time now, in seconds.
    pub fn now(&self) -> f64 {
        self.progress.now
    }

    /// How many units there are.
    pub fn units(&self) -> usize {
        self.progress.done.len()
    }

    /// When robot `robot` is free.
    pub fn free_at(&self, robot: usize) -> f64 {
        self.progress.robots[robot].free_at
    }

    /// Whether task `task` of unit `unit` could start now: not taken, its prerequisite
    /// tasks done, its parts arrived.
    pub fn ready(&self, unit: usize, task: usize) -> bool {
        let spec = &self.cell.tasks[task];
        !self.progress.taken[unit][task]
            && spec
                .after
                .iter()
                .all(|&before| self.progress.done[unit][before])
            && spec
                .parts
                .iter()
                .all(|&part| self.arrivals.at[unit][part] <= self.progress.now)
    }

    /// When part `part` of unit `unit` comes, in seconds.
    pub fn arrived(&self, unit: usize, part: usize) -> f64 {
        self.arrivals.at[unit][part]
    }

    /// Every ready task, unit by unit.
    pub fn ready_tasks(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        (0..self.units())
            .flat_map(move |unit| (0..self.cell.tasks.len()).map(move |task| (unit, task)))
            .filter(|&(unit, task)| self.ready(unit, task))
    }

    /// Whether robot `robot` has the skill task `task` needs.
    pub fn can(&self, robot: usize, task: usize) -> bool {
        self.cell.robots[robot].can(&self.cell.tasks[task])
    }

    /// How robot `robot` would do task `task`, starting from where it is once free.
    pub fn estimate(&self, robot: usize, task: usize) -> Estimate {
        let (spec, who, state) = (
            &self.cell.tasks[task],
            &self.cell.robots[robot],
            &self.progress.robots[robot],
        );
        let (from, to) = (state.at, spec.at);
        let depart = self.progress.now.max(state.free_at);
        let task_zone = self.cell.zone_of(to);
        // Each zone on the way, but the task's and one it starts in, in the order it
        // meets them: entered at its entry point, waited for there if it is taken then.
        let mut entries: Vec<(f64, usize)> = self
            .cell
            .zones
            .iter()
            .enumerate()
            .filter(|&(zone, disc)| Some(zone) != task_zone && !disc.contains(from))
            .filter_map(|(zone, disc)| Some((entry(from, to, disc.centre, disc.radius)?, zone)))
            .collect();
        entries.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut crossing = (0, 0.0);
        for (along, zone) in entries {
            let at = depart + crossing.1 + self.cell.travel_time(along, who.speed);
            let wait = (self.progress.zone_free_at[zone] - at).max(0.0);
            if wait > 0.0 {
                crossing = (crossing.0 + 1, crossing.1 + wait);
            }
        }
        // Each robot still at work, where its tool is, when the way passes too near it.
        let mut in_the_way = (0, 0.0);
        if self.cell.clearance > 0.0 {
            for (other, at_work) in self.progress.robots.iter().enumerate() {
                if other == robot {
                    continue;
                }
                let Some((along, longer)) = detour(from, to, at_work.at, self.cell.clearance)
                else {
                    continue;
                };
                let passing = depart + crossing.1 + self.cell.travel_time(along, who.speed);
                if at_work.free_at > passing {
                    in_the_way = (in_the_way.0 + 1, in_the_way.1 + longer);
                }
            }
        }
        let travel = self
            .cell
            .travel_time(distance(from, to) + in_the_way.1, who.speed);
        let arrive = depart + crossing.1 + travel;
        let start = match task_zone {
            Some(zone) => arrive.max(self.progress.zone_free_at[zone]),
            None => arrive,
        };
        Estimate {
            start,
            zone_wait: start - arrive + crossing.1,
            zones_crossed: crossing.0,
            in_the_way: in_the_way.0,
            detour: in_the_way.1,
            finish: start + spec.work / who.speed,
        }
    }
}
