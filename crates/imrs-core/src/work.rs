//! Work schedules (Shin 1985, §5.1): `perform`, `more`, `reinstate`.
//!
//! The statements that change the process environment, gathered in one place: each step has
//! a priority (1 first), `perform` runs the highest-priority step not yet done, and a step
//! that fails — an empty feeder — is skipped and reported, so the other steps still run.

use std::fmt;
use std::future::Future;

/// A schedule of steps `St`, each with a priority: 1 is performed first.
#[derive(Debug, Clone)]
pub struct WorkSchedule<St> {
    steps: Vec<(u32, St)>,
    done: Vec<bool>,
}

/// What `perform` did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Performed<E> {
    /// Step `index` (in declaration order) was performed.
    Done {
        /// The step's place in the schedule.
        index: usize,
    },
    /// Step `index` failed with `error` and was skipped.
    Failed {
        /// The step's place in the schedule.
        index: usize,
        /// Why.
        error: E,
    },
}

impl<St> WorkSchedule<St> {
    /// An empty schedule.
    pub fn new() -> Self {
        Self {
            steps: Vec::new(),
            done: Vec::new(),
        }
    }

    /// Adds `step` with `priority` (`1) GRASP(1), INSERT(X, Y, Z);`).
    pub fn step(mut self, priority: u32, step: St) -> Self {
        self.steps.push((priority, step));
        self.done.push(false);
        self
    }

    /// `REINSTATE`: every step is to be done again.
    pub fn reinstate(&mut self) {
        self.done.iter_mut().for_each(|done| *done = false);
    }

    /// `MORE`: how many steps remain.
    pub fn more(&self) -> usize {
        self.done.iter().filter(|done| !**done).count()
    }

    /// The step `perform` would run next, and its place. Among steps of equal priority the
    /// seed lets any be chosen; this schedule takes the one declared first, so that runs are
    /// reproducible.
    pub fn next(&self) -> Option<(usize, &St)> {
        self.steps
            .iter()
            .enumerate()
            .filter(|(index, _)| !self.done[*index])
            .min_by_key(|(index, (priority, _))| (*priority, *index))
            .map(|(index, (_, step))| (index, step))
    }

    /// The step at `index`.
    pub fn get(&self, index: usize) -> Option<&St> {
        self.steps.get(index).map(|(_, step)| step)
    }

    /// `PERFORM`: runs the next step with `run`. The step counts as done whether it
    /// succeeded or failed; a failure is returned so it can be reported. `None` when no step
    /// remains.
    pub async fn perform<F, Fut, E>(&mut self, run: F) -> Option<Performed<E>>
    where
        F: FnOnce(&St) -> Fut,
        Fut: Future<Output = Result<(), E>>,
    {
        let (index, step) = self.next()?;
        let outcome = run(step).await;
        self.done[index] = true;
        Some(match outcome {
            Ok(()) => Performed::Done { index },
            Err(error) => Performed::Failed { index, error },
        })
    }
}

impl<St> Default for WorkSchedule<St> {
    fn default() -> Self {
        Self::new()
    }
}

impl<E: fmt::Display> fmt::Display for Performed<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Done { index } => write!(f, "step {index} done"),
            Self::Failed { index, error } => write!(f, "step {index} failed: {error}"),
        }
    }
}
