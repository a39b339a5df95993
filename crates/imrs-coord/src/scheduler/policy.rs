//! Who does what next: the run-time scheduler, and the static assignment it is compared
//! with.

use super::cell::Workcell;
use super::state::State;

/// Chooses, for an idle robot, the task it starts now (or none: it waits).
pub trait Policy {
    /// The task (unit, task) robot `robot` starts now, if any. It must be ready and within
    /// the robot's skills.
    fn choose(&mut self, robot: usize, state: &State<'_>) -> Option<(usize, usize)>;
}

/// A static assignment: each task kind bound to one robot beforehand, balancing the robots'
/// nominal load (the longest tasks first, each to the capable robot least loaded so far).
///
/// Two ways to run it:
/// - [`Static::programs`]: each robot runs its program — its tasks, unit by unit, in a
///   fixed order, each after those it waits for — as an arm programmed in a language that assigns every task to an arm
///   beforehand (the seed's ALMA) does: it waits for its next task's parts and
///   prerequisites rather than take another.
/// - [`Static::dispatching`]: the assignment is fixed but the order is not: a robot takes,
///   of the ready tasks of its kinds, the one of the oldest unit, so it never stands idle
///   while a task of its own is ready.
#[derive(Debug, Clone)]
pub struct Static {
    /// For each robot, its task kinds, in order.
    plan: Vec<Vec<usize>>,
    /// For each robot, where it is in its program: (unit, index into its kinds); `None`
    /// when dispatching.
    programs: Option<Vec<(usize, usize)>>,
}

impl Static {
    /// Each robot runs its program in a fixed order.
    pub fn programs(cell: &Workcell) -> Self {
        let plan = Self::assign(cell);
        Self {
            programs: Some(vec![(0, 0); plan.len()]),
            plan,
        }
    }

    /// The same assignment, each robot taking its oldest ready task.
    pub fn dispatching(cell: &Workcell) -> Self {
        Self {
            plan: Self::assign(cell),
            programs: None,
        }
    }

    /// The longest tasks first, each to the capable robot whose nominal load (work over
    /// speed) is the least so far.
    fn assign(cell: &Workcell) -> Vec<Vec<usize>> {
        let mut order: Vec<usize> = (0..cell.tasks.len()).collect();
        order.sort_by(|&a, &b| cell.tasks[b].work.total_cmp(&cell.tasks[a].work));
        let mut load = vec![0.0; cell.robots.len()];
        let mut plan = vec![Vec::new(); cell.robots.len()];
        for task in order {
            let spec = &cell.tasks[task];
            // A task no robot is capable of is bound to none: no unit completes, and the
            // run's outcome says so.
            let Some(best) = (0..cell.robots.len())
                .filter(|&r| cell.robots[r].can(spec))
                .min_by(|&a, &b| {
                    let after = |r: usize| load[r] + spec.work / cell.robots[r].speed;
                    after(a).total_cmp(&after(b))
                })
            else {
                continue;
            };
            load[best] += spec.work / cell.robots[best].speed;
            plan[best].push(task);
        }
        // Each program in the order its tasks can be done: after every task it waits for,
        // wherever the cell lists them, so that no program waits for one of its own later
        // tasks.
        let depth = depths(cell);
        plan.iter_mut()
            .for_each(|kinds| kinds.sort_unstable_by_key(|&task| (depth[task], task)));
        plan
    }

    /// The task kinds bound to robot `robot`.
    pub fn kinds(&self, robot: usize) -> &[usize] {
        &self.plan[robot]
    }
}

/// For each task, the longest chain of prerequisites before it. A cycle of prerequisites
/// (which no unit can complete) stops at the number of tasks.
fn depths(cell: &Workcell) -> Vec<usize> {
    let count = cell.tasks.len();
    let mut depth = vec![0; count];
    for _ in 0..count {
        let mut changed = false;
        for (task, spec) in cell.tasks.iter().enumerate() {
            let before = spec.after.iter().filter_map(|&b| depth.get(b));
            let deepest = before.map(|d| (d + 1).min(count)).max().unwrap_or(0);
            if deepest > depth[task] {
                depth[task] = deepest;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    depth
}

impl Policy for Static {
    fn choose(&mut self, robot: usize, state: &State<'_>) -> Option<(usize, usize)> {
        let kinds = &self.plan[robot];
        let Some(programs) = &mut self.programs else {
            return state.ready_tasks().find(|(_, task)| kinds.contains(task));
        };
        let (unit, index) = programs[robot];
        if kinds.is_empty() || unit >= state.units() || !state.ready(unit, kinds[index]) {
            return None;
        }
        programs[robot] = if index + 1 == kinds.len() {
            (unit + 1, 0)
        } else {
            (unit, index + 1)
        };
        Some((unit, kinds[index]))
    }
}

/// The run-time scheduler: of the ready tasks within the robot's skills, the one it would
/// finish soonest — its travel, its speed, its waits at the borders of the zones on its way
/// (their entry points computed) and its way round robots at work worked out ahead — unless
/// another robot, free soon, would finish it clearly sooner; older units first among
/// equals. An assignment with no resource or collision conflict scores better (the seed's
/// "favourable score"). Candidates are taken in order of a lower bound on their finish
/// (work alone), and the search stops once that bound passes the best found.
#[derive(Debug, Clone)]
pub struct RunTime {
    /// How much a second of waiting at the zone counts against a candidate, beyond the
    /// delay itself (it also holds the robot idle where another could use the zone).
    pub zone_weight: f64,
    /// How many seconds each robot at work in its way counts against a candidate, beyond
    /// the longer way round it (the coordinator may stop it first, and the other may move).
    /// Not negative: the search prunes by a bound that counts it as nothing or more.
    pub collision_weight: f64,
    /// How much sooner, in seconds, another robot must finish a task for this one to leave
    /// it.
    pub margin: f64,
    /// Whether to stop the search once no candidate left can beat the best (on by
    /// default; off, every candidate is scored — the same choice, found slower).
    pub prune: bool,
}

impl Default for RunTime {
    fn default() -> Self {
        Self {
            zone_weight: 3.0,
            collision_weight: 2.0,
            margin: 2.0,
            prune: true,
        }
    }
}

impl RunTime {
    /// Robot `robot`'s score for `task`: when it would be done, plus what its waits at
    /// the zone and its time in the zone beyond the fastest capable robot's cost the
    /// others. Never below `now + work / speed`, the bound the search prunes by.
    fn score(&self, state: &State<'_>, robot: usize, task: usize) -> f64 {
        let cell = state.cell();
        let own = state.estimate(robot, task);
        // The zone is shared: time a slow robot spends in it is time every other robot
        // may wait at its border.
        let in_zone = if cell.zone_of(cell.tasks[task].at).is_some() {
            let work = cell.tasks[task].work;
            let fastest = (0..cell.robots.len())
                .filter(|&other| state.can(other, task))
                .map(|other| work / cell.robots[other].speed)
                .fold(f64::INFINITY, f64::min);
            work / cell.robots[robot].speed - fastest
        } else {
            0.0
        };
        own.finish
            + self.zone_weight * (own.zone_wait + in_zone)
            + self.collision_weight * own.in_the_way as f64
    }
}

impl Policy for RunTime {
    fn choose(&mut self, robot: usize, state: &State<'_>) -> Option<(usize, usize)> {
        let cell = state.cell();
        let speed = cell.robots[robot].speed;
        let mut candidates: Vec<(f64, usize, usize)> = state
            .ready_tasks()
            .filter(|&(_, task)| state.can(robot, task))
            .map(|(unit, task)| (state.now() + cell.tasks[task].work / speed, unit, task))
            .collect();
        candidates.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut best: Option<(f64, usize, usize)> = None;
        for (bound, unit, task) in candidates {
            // Every score is at least its bound: once the bounds pass the best score, no
            // candidate left can beat it.
            if self.prune && best.is_some_and(|(score, ..)| bound >= score) {
                break;
            }
            let own = self.score(state, robot, task);
            // Leave it to another robot that would do it clearly better, even from later.
            let someone_else_better = (0..cell.robots.len())
                .filter(|&other| other != robot && state.can(other, task))
                .any(|other| self.score(state, other, task) + self.margin < own);
            if someone_else_better {
                continue;
            }
            // Older units first among near-equals: a tenth of a second per unit of age.
            let score = own + 0.1 * unit as f64;
            if best.is_none_or(|(s, ..)| score < s) {
                best = Some((score, unit, task));
            }
        }
        best.map(|(_, unit, task)| (unit, task))
    }
}

/// The part-driven variant the seed weighs: each part comes with its tasks, and the tasks
/// are done in the order their parts came, by whichever capable robot is free first. A task
/// of no single part (one that needs a set of parts assembled) comes with the last part of
/// its prerequisites. No look-ahead: where a robot would wait, or whom it would meet, does
/// not count.
#[derive(Debug, Clone, Copy, Default)]
pub struct PartDriven;

impl PartDriven {
    /// When task `task` of unit `unit` came: with the last of its parts, or of its
    /// prerequisites' parts.
    fn came(state: &State<'_>, unit: usize, task: usize) -> f64 {
        let spec = &state.cell().tasks[task];
        let own = spec
            .parts
            .iter()
            .map(|&part| state.arrived(unit, part))
            .fold(f64::NEG_INFINITY, f64::max);
        spec.after
            .iter()
            .map(|&before| Self::came(state, unit, before))
            .fold(own, f64::max)
    }
}

impl Policy for PartDriven {
    fn choose(&mut self, robot: usize, state: &State<'_>) -> Option<(usize, usize)> {
        state
            .ready_tasks()
            .filter(|&(_, task)| state.can(robot, task))
            .min_by(|&(a_unit, a_task), &(b_unit, b_task)| {
                Self::came(state, a_unit, a_task)
                    .total_cmp(&Self::came(state, b_unit, b_task))
                    .then((a_unit, a_task).cmp(&(b_unit, b_task)))
            })
    }
}
