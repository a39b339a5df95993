//! The discrete-event run of a cell under a policy.

use super::cell::{Arrivals, Workcell, distance};
use super::policy::Policy;

/// Where a robot is in a run.
#[derive(Debug, Clone, Copy, PartialEq)]
struct RobotState {
    free_at: f64,
    at: [f64; 2],
}

/// What a policy sees when it chooses: the time, which tasks are done or taken, the parts
/// that have come, where the robots are and when they are free, and when the zone is.
#[derive(Debug)]
pub struct State<'a> {
    cell: &'a Workcell,
    arrivals: &'a Arrivals,
    now: f64,
    done: Vec<Vec<bool>>,
    taken: Vec<Vec<bool>>,
    robots: Vec<RobotState>,
    zone_free_at: f64,
}

/// How a robot would do a task, worked out ahead: when it would enter, how long it would
/// wait at the zone's border, when it would be done.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Estimate {
    /// When it would start the task's work.
    pub start: f64,
    /// How long it would wait for the zone.
    pub zone_wait: f64,
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
        self.now
    }

    /// How many units there are.
    pub fn units(&self) -> usize {
        self.done.len()
    }

    /// When robot `robot` is free.
    pub fn free_at(&self, robot: usize) -> f64 {
        self.robots[robot].free_at
    }

    /// Whether task `task` of unit `unit` could start now: not taken, its prerequisite
    /// tasks done, its parts arrived.
    pub fn ready(&self, unit: usize, task: usize) -> bool {
        let spec = &self.cell.tasks[task];
        !self.taken[unit][task]
            && spec.after.iter().all(|&before| self.done[unit][before])
            && spec
                .parts
                .iter()
                .all(|&part| self.arrivals.at[unit][part] <= self.now)
    }

    /// Every ready task, unit by unit.
    pub fn ready_tasks(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        (0..self.units())
            .flat_map(move |unit| (0..self.cell.tasks.len()).map(move |task| (unit, task)))
            .filter(|&(unit, task)| self.ready(unit, task))
    }

    /// Whether robot `robot` has the skill task `task` needs.
    pub fn can(&self, robot: usize, task: usize) -> bool {
        self.cell.robots[robot]
            .skills
            .contains(&self.cell.tasks[task].skill)
    }

    /// How robot `robot` would do task `task`, starting from where it is once free.
    pub fn estimate(&self, robot: usize, task: usize) -> Estimate {
        let (spec, who, state) = (
            &self.cell.tasks[task],
            &self.cell.robots[robot],
            &self.robots[robot],
        );
        let travel = distance(state.at, spec.at) / (self.cell.travel * who.speed);
        let arrive = self.now.max(state.free_at) + travel;
        let start = if self.cell.zone.contains(spec.at) {
            arrive.max(self.zone_free_at)
        } else {
            arrive
        };
        Estimate {
            start,
            zone_wait: start - arrive,
            finish: start + spec.work / who.speed,
        }
    }
}

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

/// Runs `cell` on `arrivals` under `policy` until every unit is done, or until nothing can
/// happen any more (a policy that waits for ever).
pub fn simulate(cell: &Workcell, arrivals: &Arrivals, policy: &mut dyn Policy) -> Outcome {
    let units = arrivals.at.len();
    let mut state = State {
        cell,
        arrivals,
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
        zone_free_at: 0.0,
    };
    // Tasks under way: (finish, unit, task).
    let mut running: Vec<(f64, usize, usize)> = Vec::new();
    let mut zone_wait = 0.0;
    let mut makespan = 0.0;
    let mut refused = 0;
    loop {
        for (finish, unit, task) in running.iter().copied().filter(|r| r.0 <= state.now) {
            state.done[unit][task] = true;
            if state.done[unit].iter().all(|&d| d) {
                makespan = f64::max(makespan, finish);
            }
        }
        running.retain(|r| r.0 > state.now);
        for robot in 0..cell.robots.len() {
            if state.robots[robot].free_at > state.now {
                continue;
            }
            let Some((unit, task)) = policy.choose(robot, &state) else {
                continue;
            };
            // A choice the cell cannot carry out is refused; the robot waits.
            if unit >= units
                || task >= cell.tasks.len()
                || !state.ready(unit, task)
                || !state.can(robot, task)
            {
                refused += 1;
                continue;
            }
            let estimate = state.estimate(robot, task);
            state.taken[unit][task] = true;
            state.robots[robot] = RobotState {
                free_at: estimate.finish,
                at: cell.tasks[task].at,
            };
            if cell.zone.contains(cell.tasks[task].at) {
                state.zone_free_at = estimate.finish;
            }
            zone_wait += estimate.zone_wait;
            running.push((estimate.finish, unit, task));
        }
        let next_finish = running.iter().map(|r| r.0).fold(f64::INFINITY, f64::min);
        let next_arrival = arrivals
            .at
            .iter()
            .flatten()
            .copied()
            .filter(|&t| t > state.now)
            .fold(f64::INFINITY, f64::min);
        let next = next_finish.min(next_arrival);
        if !next.is_finite() {
            break;
        }
        state.now = next;
    }
    let units_done = state.done.iter().filter(|u| u.iter().all(|&d| d)).count();
    Outcome {
        units: units_done,
        makespan,
        zone_wait,
        refused,
    }
}
