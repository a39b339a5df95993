//! The feeder policies side by side: one run under each, with the same seed, hours and
//! faults, all at once, each on a thread of its own with its own runtime and world, so that
//! they share the machine's cores. The runs share nothing that decides what happens in them,
//! so each gives what it gives alone.

use std::num::NonZeroUsize;
use std::thread;
use std::time::Duration;

use crate::feeder_policy::FeederPolicy;
use imrs_record::Recorder;

use crate::config::CellConfig;
use crate::run::{refused, run};
use crate::run_error::{RunError, output};
use crate::run_record::RunRecord;

/// The policies in the order the side-by-side table shows them.
pub const POLICIES: [FeederPolicy; 3] = [
    FeederPolicy::Appendix,
    FeederPolicy::Arbiter,
    FeederPolicy::Coordinator,
];

/// The runs of a comparison, and the cores they shared.
#[derive(Debug)]
pub struct Comparison {
    /// Each policy's run, in the order of [`POLICIES`]; or, where the chosen run is refused
    /// before anything runs ([`refused`], or a recording it cannot write), that refusal alone.
    pub runs: Vec<(FeederPolicy, Result<RunRecord, RunError>)>,
    /// How many cores ran them: those there are, at most one per run.
    pub cores: usize,
}

/// Runs `config` under every policy of [`POLICIES`] at once. The run under `config`'s own
/// policy is `config` as it is; the others only make their report: no progress bar,
/// recording, timeline or ROS 2 node. Not for a run across processes ([`CellConfig::processes`]), which
/// needs the machine's cores to itself: [`run`] it alone.
pub fn compare(config: &CellConfig) -> Comparison {
    if let Some(refused) = refused(config).or_else(|| unwritable_record(config)) {
        return Comparison {
            runs: vec![(config.feeder, Err(refused))],
            cores: 1,
        };
    }
    let configs = POLICIES.map(|policy| {
        if policy == config.feeder {
            config.clone()
        } else {
            CellConfig {
                feeder: policy,
                progress: false,
                record: None,
                timeline: None,
                ros2: None,
                ..config.clone()
            }
        }
    });
    // One thread per run rather than a pool of one per core: with three runs on two cores,
    // the scheduler's time slices finish them all at about the same time, where a pool
    // would leave the third run to a core of its own at the end.
    let runs = thread::scope(|scope| {
        let running: Vec<_> = configs
            .iter()
            .map(|config| {
                thread::Builder::new()
                    .name(config.feeder.name().to_string())
                    .spawn_scoped(scope, move || run(config))
                    .expect("the system starts a thread")
            })
            .collect();
        POLICIES
            .into_iter()
            .zip(running)
            .map(|(policy, running)| {
                // A run that panicked panics the comparison, as it would have alone.
                let ran = running
                    .join()
                    .unwrap_or_else(|panic| std::panic::resume_unwind(panic));
                (policy, ran)
            })
            .collect()
    });
    let cores = thread::available_parallelism().map_or(1, NonZeroUsize::get);
    Comparison {
        runs,
        cores: cores.min(POLICIES.len()),
    }
}

/// A recording the chosen run cannot write: that run would fail at its start, and the other
/// policies would run for nothing before the error shows. The file is made and dropped; the
/// chosen run makes it again.
fn unwritable_record(config: &CellConfig) -> Option<RunError> {
    let path = config.record.as_ref()?;
    Recorder::create(path)
        .err()
        .map(|error| output(path, error))
}

impl Comparison {
    /// The run under `policy`.
    pub fn run_of(&self, policy: FeederPolicy) -> Option<&Result<RunRecord, RunError>> {
        self.runs
            .iter()
            .find(|(ran, _)| *ran == policy)
            .map(|(_, result)| result)
    }

    /// The last line of the example's report: see [`speed_line`], over the runs that ran.
    pub fn speed_line(&self, wall: Duration) -> String {
        let ran: Vec<_> = self
            .runs
            .iter()
            .filter_map(|(policy, ran)| Some((*policy, ran.as_ref().ok()?.simulated)))
            .collect();
        speed_line(&ran, wall, self.cores)
    }
}

/// How fast `runs` (each policy with the time it simulated) ran together: their simulated
/// time, the wall time `wall` they took, and on how many cores. It differs from run to run.
pub fn speed_line(runs: &[(FeederPolicy, Duration)], wall: Duration, cores: usize) -> String {
    let total: Duration = runs.iter().map(|(_, simulated)| *simulated).sum();
    let each = match runs {
        [(_, first), rest @ ..]
            if !rest.is_empty() && rest.iter().all(|(_, simulated)| simulated == first) =>
        {
            let names: Vec<_> = runs.iter().map(|(policy, _)| policy.name()).collect();
            format!(
                "{:.0} s under each of {}",
                first.as_secs_f64(),
                listed(&names)
            )
        }
        _ => runs
            .iter()
            .map(|(policy, simulated)| {
                format!("{:.0} s under {}", simulated.as_secs_f64(), policy.name())
            })
            .collect::<Vec<_>>()
            .join(", "),
    };
    let (total, wall) = (total.as_secs_f64(), wall.as_secs_f64());
    let cores = match cores {
        1 => "1 core".to_string(),
        cores => format!("{cores} cores"),
    };
    format!(
        "simulated {total:.0} s ({each}) in {wall:.2} s of wall time on {cores} ({:.0}x real time)",
        total / wall.max(1e-9)
    )
}

/// `a, b and c`.
fn listed(names: &[&str]) -> String {
    match names {
        [] => String::new(),
        [only] => (*only).to_string(),
        [rest @ .., last] => format!("{} and {last}", rest.join(", ")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_speed_line_counts_every_run_and_names_the_cores() {
        let shift = Duration::from_secs(8 * 3600);
        let three = POLICIES.map(|policy| (policy, shift));
        assert_eq!(
            speed_line(&three, Duration::from_secs(8), 2),
            "simulated 86400 s (28800 s under each of appendix, arbiter and coordinator) \
             in 8.00 s of wall time on 2 cores (10800x real time)"
        );
        let uneven = [
            (FeederPolicy::Arbiter, Duration::from_secs(60)),
            (FeederPolicy::Coordinator, Duration::from_secs(30)),
        ];
        assert_eq!(
            speed_line(&uneven, Duration::from_millis(10), 1),
            "simulated 90 s (60 s under arbiter, 30 s under coordinator) in 0.01 s of wall time \
             on 1 core (9000x real time)"
        );
    }
}
