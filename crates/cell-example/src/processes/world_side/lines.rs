//! The lines' processes as the world sees them: started, heard on their standard output,
//! and stopped.

use super::*;

/// What a line's process said on its standard output.
#[derive(Debug)]
pub(super) enum Said {
    /// Its ports are imported and its modules started.
    Ready,
    /// Its figures so far, once a minute of the cell's time.
    Snapshot(Value),
    /// Its figures, at the end of the run.
    Figures(Value),
    /// It could not run, and why.
    Failed(String),
    /// Its output closed: it ended, with this status if known.
    Ended(Option<ExitStatus>),
    /// Over zenoh: its host is gone from the world's sight (killed, or cut off), as the
    /// world watches it, whatever run it is in.
    #[cfg_attr(
        not(feature = "zenoh"),
        expect(
            dead_code,
            reason = "told only by the watch of a line's host over zenoh"
        )
    )]
    Unseen,
    /// A line the world does not understand.
    Garbled(String),
}

impl Said {
    pub(super) fn refusal(self, line: Line, expected: &str) -> RunError {
        let why = match self {
            Said::Failed(why) => why,
            Said::Ended(status) => format!(
                "ended ({}) before it sent {expected}",
                status.map_or("status unknown".into(), |status| status.to_string())
            ),
            Said::Garbled(text) => format!("said {text:?} where {expected} was due"),
            Said::Ready | Said::Snapshot(_) | Said::Figures(_) => {
                format!("answered out of turn, before {expected}")
            }
            Said::Unseen => format!("was cut off before it sent {expected}"),
        };
        refused(process_name(line), why)
    }
}

/// What a line's process said, with its line and run.
pub(super) type Heard = (Line, u32, Said);

/// The run of what the world's watch of a line's host says: whichever run is up.
#[cfg_attr(
    not(feature = "zenoh"),
    expect(
        dead_code,
        reason = "told only by the watch of a line's host over zenoh"
    )
)]
pub(super) const UNSEEN: u32 = u32::MAX;

pub(super) async fn hear_from(hear: &mut UnboundedReceiver<Heard>) -> Result<Heard, RunError> {
    match tokio::time::timeout(PATIENCE, hear.recv()).await {
        Ok(Some(said)) => Ok(said),
        Ok(None) => Err(refused("world", "the lines' processes are gone")),
        Err(_) => Err(refused(
            "world",
            format!("no line's process said anything for {PATIENCE:?}"),
        )),
    }
}

/// The lines' processes: killed if the world gives up on them.
pub(super) struct Lines(pub(super) Vec<(Line, u32, Child)>);

impl Lines {
    /// Kills `line`'s process of `run`, if it still runs, and waits for its end.
    pub(super) fn stop(&mut self, line: Line, run: u32) {
        for (_, _, child) in self
            .0
            .iter_mut()
            .filter(|(l, r, _)| (*l, *r) == (line, run))
        {
            if let Ok(None) = child.try_wait() {
                let _ = child.kill();
            }
            // Killed: its end is at hand, and the runtime's other workers go on meanwhile.
            tokio::task::block_in_place(|| {
                let _ = child.wait();
            });
        }
    }

    /// Gives the lines, which have sent their figures, the world's patience to end on
    /// their own (so that they let go of their shared memory); any still running then is
    /// killed when `self` drops. The world never hangs on a line that does not end.
    pub(super) async fn ended(&mut self) {
        let deadline = std::time::Instant::now() + PATIENCE;
        while std::time::Instant::now() < deadline
            && self
                .0
                .iter_mut()
                .any(|(_, _, child)| matches!(child.try_wait(), Ok(None)))
        {
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    }
}

impl Drop for Lines {
    fn drop(&mut self) {
        for (_, _, child) in &mut self.0 {
            if let Ok(None) = child.try_wait() {
                let _ = child.kill();
                let _ = child.wait();
            }
        }
    }
}

/// Where a line's process runs: the cell's name, and over zenoh its host's namespace (if
/// made) and the world's endpoint as it reaches it.
pub(super) struct LinePlace<'a> {
    pub(super) cell: &'a str,
    pub(super) netns: Option<&'a Netns>,
    pub(super) connect: Option<&'a str>,
}

/// Starts `line`'s process — this same program, told which line it is — and a thread that
/// hands on what it says.
pub(super) fn start_line(
    config: &CellConfig,
    line: Line,
    run: u32,
    place: &LinePlace<'_>,
    epoch: SystemTime,
    faults: &[CellFault],
    said: UnboundedSender<Heard>,
) -> Result<Child, RunError> {
    let name = process_name(line);
    let program = std::env::current_exe()
        .map_err(|error| refused(name, format!("this program cannot be found: {error}")))?;
    let epoch_ns = epoch
        .duration_since(UNIX_EPOCH)
        .map_err(|_| refused(name, "the epoch lies before 1970"))?
        .as_nanos();
    let mut command = match place.netns {
        Some(netns) => netns.command(program),
        None => Command::new(program),
    };
    command
        .args(["--processes", "--line-process", &format!("{line:?}")])
        .args(["--run", &run.to_string()])
        .args(["--remote", place.cell, "--epoch", &epoch_ns.to_string()])
        .args(["--speed", &config.speed.to_string()])
        .args(["--hours", &config.hours.to_string()])
        .args(["--seed", &config.seed.to_string()])
        .args(["--feeder", config.feeder.name()]);
    for fault in faults {
        command.arg(format!("--fault={fault}"));
    }
    if let Some(endpoint) = place.connect {
        command.args(["--transport", "zenoh", "--connect", endpoint]);
    }
    let mut child = command
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .map_err(|error| refused(name, format!("cannot be started: {error}")))?;
    let Some(out) = child.stdout.take() else {
        return Err(refused(name, "has no standard output"));
    };
    std::thread::spawn(move || {
        for text in BufReader::new(out).lines() {
            let Ok(text) = text else { break };
            let heard = match text.split_once(' ') {
                _ if text == "ready" => Said::Ready,
                Some(("snapshot", json)) => match serde_json::from_str(json) {
                    Ok(figures) => Said::Snapshot(figures),
                    Err(_) => Said::Garbled(text),
                },
                Some(("figures", json)) => match serde_json::from_str(json) {
                    Ok(figures) => Said::Figures(figures),
                    Err(_) => Said::Garbled(text),
                },
                Some(("failed", why)) => Said::Failed(why.into()),
                _ => Said::Garbled(text),
            };
            if said.send((line, run, heard)).is_err() {
                return;
            }
        }
        let _ = said.send((line, run, Said::Ended(None)));
    });
    Ok(child)
}
