//! The run-time task scheduler as a module: an idle arm asks it for work (telling it what it
//! finished), and it answers from the live run's [`Dispatch`] under the cell's policy.

use std::sync::{Arc, Mutex};
use std::time::Duration;

use imrs_core::prelude::*;
use imrs_ports::{AnyUser, End, Instant, Port, PortSpec, SharedClock, usage};

use super::lock;
use imrs_coord::scheduler::{Dispatch, Policy};

/// The scheduler module's name.
pub const SCHEDULER: &str = "SCHEDULER";

/// Work for an arm: a task of a unit, where it is done, for how long, and whether it
/// needs the screwdriver.
#[derive(Debug, Clone, PartialEq)]
pub struct Job {
    /// The unit.
    pub unit: usize,
    /// The task, an index into the unit's tasks.
    pub task: usize,
    /// Where it is done, in metres.
    pub at: [f32; 2],
    /// How long the work takes this arm.
    pub work: Duration,
    /// Whether it needs the screwdriver.
    pub tool: bool,
}

/// What an arm tells the scheduler when it asks for work: its index, what it finished, if
/// anything, and where its tool is.
pub type Asking = (usize, Option<(usize, usize)>, [f32; 2]);

/// `NEXT_JOB`: an arm tells what it finished and where it is, and is given its next job,
/// or none for now.
pub type JobPort = Port<Asking, Option<Job>, usage::Receive, AnyUser, 8>;

/// An arm's end of [`JobPort`].
pub type JobAsker = End<Asking, Option<Job>, usage::Send>;

/// The port, owned by the scheduler.
pub(super) fn job_port(clock: &SharedClock) -> JobPort {
    Port::new(
        PortSpec::new("NEXT_JOB", SCHEDULER)
            .clock(clock.clone())
            .priority(2),
    )
}

/// When each unit was completed.
pub(super) type Completions = Arc<Mutex<Vec<Instant>>>;

/// The scheduler module: `policy` choosing over `dispatch`, answering on `port`.
pub(super) fn scheduler(
    port: &JobPort,
    dispatch: Dispatch,
    policy: Box<dyn Policy + Send>,
    done: Completions,
) -> ModuleSpec<()> {
    let port = port.clone();
    let run = Arc::new(Mutex::new((dispatch, policy)));
    ModuleSpec::new(SCHEDULER, ()).task(SCHEDULER, move |ctx| {
        let (port, run, done) = (port.clone(), Arc::clone(&run), Arc::clone(&done));
        async move {
            let mut jobs = port.owner()?;
            loop {
                let ((robot, finished, at), reply) = jobs.receive().await?;
                let now = ctx.now();
                let seconds = now.since_start().as_secs_f64();
                let mut run = lock(&run);
                let (dispatch, policy) = &mut *run;
                if let Some((unit, task)) = finished
                    && dispatch.finished(robot, unit, task, seconds)
                {
                    lock(&done).push(now);
                }
                // Its next way starts where it is, not where its last task was.
                dispatch.moved(robot, at.map(f64::from));
                // A refused choice leaves the arm without work this time; it asks again.
                let job = dispatch
                    .next(robot, seconds, policy.as_mut())
                    .ok()
                    .flatten()
                    .map(|(unit, task, _)| {
                        let cell = dispatch.cell();
                        let spec = &cell.tasks[task];
                        Job {
                            unit,
                            task,
                            at: spec.at.map(|x| x as f32),
                            work: Duration::from_secs_f64(spec.work / cell.robots[robot].speed),
                            tool: super::layout::needs_tool(spec),
                        }
                    });
                drop(run);
                reply.reply(job);
            }
        }
    })
}
