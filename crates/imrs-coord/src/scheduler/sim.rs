//! The discrete-event run of a cell under a policy.

use super::cell::{Arrivals, Workcell};
use super::policy::Policy;
use super::state::{Estimate, Progress, RobotState, State};

/// What a run achieved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Outcome {
    /// Units completed.
    pub units: usize,
    /// When the last one was, in seconds.
    pub makespan: f64,
    /// The seconds robots spent waiting at the zone's border.
    pub zone_wait: f64,
    /// Choices the policy made that the cell could not carry out (a task not ready, or
    /// beyond the robot's skills): refused, the robot left waiting.
    pub refused: usize,
}

impl Outcome {
    /// Units per hour, over the run.
    pub fn per_hour(&self) -> f64 {
        if self.makespan > 0.0 {
            self.units as f64 * 3600.0 / self.makespan
        } else {
            0.0
        }
    }
}

/// A run in progress, for a cell that carries the tasks out itself (a simulated or a real
/// one): it asks [`Dispatch::next`] what an idle robot does, and reports each task done with
/// [`Dispatch::finished`]. [`simulate`] is such a cell, with the estimates for durations.
#[derive(Debug, Clone)]
pub struct Dispatch {
    cell: Workcell,
    arrivals: Arrivals,
    progress: Progress,
}

impl Dispatch {
    /// A run of `cell` on `arrivals`, at time 0, every robot idle at home.
    pub fn new(cell: Workcell, arrivals: Arrivals) -> Self {
        let units = arrivals.at.len();
        let progress = Progress {
            now: 0.0,
            done: vec![vec![false; cell.tasks.len()]; units],
            taken: vec![vec![false; cell.tasks.len()]; units],
            robots: cell
                .robots
                .iter()
                .map(|r| RobotState {
                    free_at: 0.0,
                    at: r.home,
                })
                .collect(),
            zone_free_at: vec![0.0; cell.zones.len()],
            zone_task: vec![None; cell.zones.len()],
        };
        Self {
            cell,
            arrivals,
            progress,
        }
    }

    /// The cell.
    pub fn cell(&self) -> &Workcell {
        &self.cell
    }

    /// What a policy sees now.
    pub fn state(&self) -> State<'_> {
        State {
            cell: &self.cell,
            arrivals: &self.arrivals,
            progress: &self.progress,
        }
    }

    /// Asks `policy` what robot `robot`, idle at `now` (seconds), starts: the task
    /// (unit, task) and how it is expected to go, now taken; or `Ok(None)`: it waits. A
    /// choice the cell cannot carry out (not ready, beyond the robot's skills) is refused.
    pub fn next(
        &mut self,
        robot: usize,
        now: f64,
        policy: &mut dyn Policy,
    ) -> Result<Option<(usize, usize, Estimate)>, Refusal> {
        if robot >= self.cell.robots.len() {
            return Err(Refusal::NoSuchRobot(robot));
        }
        self.progress.now = self.progress.now.max(now);
        let Some((unit, task)) = policy.choose(robot, &self.state()) else {
            return Ok(None);
        };
        let state = self.state();
        if unit >= state.units()
            || task >= self.cell.tasks.len()
            || !state.ready(unit, task)
            || !state.can(robot, task)
        {
            return Err(Refusal::NotReady { robot, unit, task });
        }
        let estimate = state.estimate(robot, task);
        self.progress.taken[unit][task] = true;
        self.progress.robots[robot] = RobotState {
            free_at: estimate.finish,
            at: self.cell.tasks[task].at,
        };
        if let Some(zone) = self.cell.zone_of(self.cell.tasks[task].at) {
            self.progress.zone_free_at[zone] = estimate.finish;
            self.progress.zone_task[zone] = Some((unit, task));
        }
        Ok(Some((unit, task, estimate)))
    }

    /// Robot `robot` has done task `task` of unit `unit` at `now`: it is free there, and
    /// so is the zone if the task was in it. Whether the unit is now complete.
    pub fn finished(&mut self, robot: usize, unit: usize, task: usize, now: f64) -> bool {
        let (Some(done), Some(state)) = (
            self.progress.done.get_mut(unit),
            self.progress.robots.get_mut(robot),
        ) else {
            return false;
        };
        let Some(spec) = self.cell.tasks.get(task) else {
            return false;
        };
        done[task] = true;
        state.free_at = now;
        state.at = spec.at;
        // The zone is free when the last task given it ends, whenever that really is.
        if let Some(zone) = self.cell.zone_of(spec.at)
            && self.progress.zone_task[zone] == Some((unit, task))
        {
            self.progress.zone_free_at[zone] = now;
            self.progress.zone_task[zone] = None;
        }
        done.iter().all(|&d| d)
    }

    /// Robot `robot` is at `at` now, wherever its last task was (it went home, or out of
    /// the way): its next way starts there.
    pub fn moved(&mut self, robot: usize, at: [f64; 2]) {
        if let Some(state) = self.progress.robots.get_mut(robot) {
            state.at = at;
        }
    }

    /// Units whose every task is done.
    pub fn units_done(&self) -> usize {
        self.progress
            .done
            .iter()
            .filter(|unit| unit.iter().all(|&d| d))
            .count()
    }

    /// The first part arrival after `now`, if any is still to come.
    pub fn next_arrival(&self, now: f64) -> Option<f64> {
        self.arrivals
            .at
            .iter()
            .flatten()
            .copied()
            .filter(|&t| t > now)
            .min_by(f64::total_cmp)
    }
}

/// A choice a policy made that the cell cannot carry out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Refusal {
    /// There is no robot of this index.
    NoSuchRobot(usize),
    /// The task is not ready, or beyond the robot's skills.
    NotReady {
        /// The robot it was chosen for.
        robot: usize,
        /// Its unit.
        unit: usize,
        /// The task.
        task: usize,
    },
}

impl std::fmt::Display for Refusal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::NoSuchRobot(robot) => write!(f, "no robot {robot} in the cell"),
            Self::NotReady { robot, unit, task } => write!(
                f,
                "task {task} of unit {unit} is not ready, or beyond robot {robot}'s skills"
            ),
        }
    }
}

impl std::error::Error for Refusal {}

/// Runs `cell` on `arrivals` under `policy` until every unit is done, or until nothing can
/// happen any more (a policy that waits for ever). Every task takes its estimate.
pub fn simulate(cell: &Workcell, arrivals: &Arrivals, policy: &mut dyn Policy) -> Outcome {
    let mut run = Dispatch::new(cell.clone(), arrivals.clone());
    // Tasks under way: (finish, robot, unit, task).
    let mut running: Vec<(f64, usize, usize, usize)> = Vec::new();
    let (mut now, mut zone_wait, mut makespan, mut refused) = (0.0, 0.0, 0.0_f64, 0);
    loop {
        for &(finish, robot, unit, task) in running.iter().filter(|r| r.0 <= now) {
            if run.finished(robot, unit, task, finish) {
                makespan = makespan.max(finish);
            }
        }
        running.retain(|r| r.0 > now);
        for robot in 0..cell.robots.len() {
            if run.state().free_at(robot) > now {
                continue;
            }
            match run.next(robot, now, policy) {
                Ok(Some((unit, task, estimate))) => {
                    zone_wait += estimate.zone_wait;
                    running.push((estimate.finish, robot, unit, task));
                }
                Ok(None) => {}
                // A choice the cell cannot carry out is refused; the robot waits.
                Err(_) => refused += 1,
            }
        }
        let next_finish = running.iter().map(|r| r.0).fold(f64::INFINITY, f64::min);
        let next = next_finish.min(run.next_arrival(now).unwrap_or(f64::INFINITY));
        if !next.is_finite() {
            break;
        }
        now = next;
    }
    Outcome {
        units: run.units_done(),
        makespan,
        zone_wait,
        refused,
    }
}
