//! GATE: lets a pallet onto the conveyor every CYCLE_TIME, which it keeps at half the faster
//! workcell's reported cycle time (Appendix, MODULE GATE).

use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use imrs_core::prelude::*;
use imrs_ports::{BoundedBuffer, Instant};
use imrs_sim::Line;

use crate::devices::Devices;

use crate::alarms::{AlarmKind, alarm};
use crate::names::LineNames;
use crate::ports::LinePorts;

/// GATE's variables.
#[derive(Debug)]
pub struct GateState {
    /// CYCLE_TIME: the delay between pallets, in seconds.
    pub cycle_time: f64,
    /// SPEEDS: the cycle times LOAD_IT (0) and CHIP_IT (1) reported.
    pub speeds: [f64; 2],
    /// NUM_RELEASED.
    pub num_released: u32,
    /// How many cycles in a row the line was backed up to the gate.
    backed_up: u32,
}

/// When RELEASE is to die (the `--fault release@T` injection), taken by the copy it kills.
pub type ReleaseDeath = Arc<Mutex<Option<Instant>>>;

/// The history of a GATE's CYCLE_TIME, kept for the report: its first and latest values,
/// its range, how often it changed, and the most recent changes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CycleTimeHistory {
    /// The value it started with, in seconds.
    pub first: Option<f64>,
    /// Its value now.
    pub now: Option<f64>,
    /// The least and the greatest value it took.
    pub range: Option<(f64, f64)>,
    /// How often it changed.
    pub changes: u32,
    /// The most recent changes: when (simulated seconds) and to what.
    pub recent: Vec<(f64, f64)>,
}

impl CycleTimeHistory {
    /// How many recent changes are kept.
    pub const RECENT: usize = 8;

    /// Folds in the history of a later run of the same GATE (its line's process started
    /// again): its first value stays, the rest is the later run's, added to this one's.
    pub fn follow(&mut self, later: CycleTimeHistory) {
        self.first = self.first.or(later.first);
        self.now = later.now.or(self.now);
        self.range = match (self.range, later.range) {
            (Some((low, high)), Some((l, h))) => Some((low.min(l), high.max(h))),
            (range, None) | (None, range) => range,
        };
        self.changes += later.changes;
        self.recent.extend(later.recent);
        let surplus = self.recent.len().saturating_sub(Self::RECENT);
        self.recent.drain(..surplus);
    }

    fn set(&mut self, at: f64, value: f64) {
        self.first.get_or_insert(value);
        let (low, high) = self.range.unwrap_or((value, value));
        self.range = Some((low.min(value), high.max(value)));
        if self.now.is_some_and(|now| now != value) {
            self.changes += 1;
            if self.recent.len() == Self::RECENT {
                self.recent.remove(0);
            }
            self.recent.push((at, value));
        }
        self.now = Some(value);
    }
}

/// A line's GATE's CYCLE_TIME history, shared with the run that reports it.
pub type SharedCycleTimes = Arc<Mutex<CycleTimeHistory>>;

/// The GATE module of `line`.
pub fn gate(
    line: Line,
    ports: &LinePorts,
    devices: &Devices,
    death: ReleaseDeath,
    history: SharedCycleTimes,
) -> ModuleSpec<GateState> {
    let n = LineNames::of(line);
    let timeout = ports.let_1_go.handler("TIMEOUT").name();
    let state = GateState {
        cycle_time: 10.0,
        speeds: [20.0, 40.0],
        num_released: 0,
        backed_up: 0,
    };
    let (let_1_go, frequency) = (ports.let_1_go.clone(), ports.frequency.clone());
    let (release_port, buffer_port) = (ports.let_1_go.clone(), ports.frequency.clone());
    let device = devices.gate(line);
    let release_failed = imrs_core::Exception::failure_of("RELEASE");
    ModuleSpec::new(n.gate.clone(), state)
        // RELEASE.FAILED first: a failed RELEASE is reported before anything else runs.
        .order([
            release_failed.clone(),
            timeout.clone(),
            n.gate.as_str().into(),
        ])
        .hardware([format!("gate relay and photocell of line {line:?}")])
        .filters(n.frequency.clone(), UsageKind::Receive)
        .task(n.gate.clone(), move |ctx| {
            let (let_1_go, frequency) = (let_1_go.clone(), frequency.clone());
            let history = Arc::clone(&history);
            async move {
                let mut let_1_go = let_1_go.owner()?;
                let mut frequency = frequency.owner()?;
                let first = ctx.state().read(|gate| gate.cycle_time);
                record(&history, ctx.now(), first);
                loop {
                    let cycle = ctx.state().read(|gate| gate.cycle_time);
                    ctx.delay(Duration::from_secs_f64(cycle)).await;
                    match ctx.send(&mut let_1_go, ()).await {
                        Ok(0) => ctx.state().update(|gate| {
                            gate.num_released += 1;
                            gate.backed_up = 0;
                        }),
                        Ok(_) => {
                            let cycles = ctx.state().update(|gate| {
                                gate.backed_up += 1;
                                gate.backed_up
                            });
                            if cycles % 10 == 0 {
                                alarm(
                                    &ctx,
                                    AlarmKind::BackedUp,
                                    format!("line backed up to the gate for {cycles} cycles"),
                                );
                            }
                        }
                        // A timeout is the handler's business; a RELEASE that died holding
                        // the message is restarted here.
                        Err(error) if !error.is_timeout() => {
                            alarm(
                                &ctx,
                                AlarmKind::TaskFailed,
                                format!("RELEASE failed: {error}; restarting it"),
                            );
                            ctx.restart_task("RELEASE");
                        }
                        Err(_) => {}
                    }
                    // SEND FREQUENCY(TASK_NUM, TEMP_TIME): the buffer's oldest report, if any.
                    if let Ok(Some((task_num, time))) = ctx.send(&mut frequency, ()).await {
                        let cycle = ctx.state().update(|gate| {
                            gate.speeds[task_num as usize] = time;
                            gate.cycle_time = gate.speeds[0].min(gate.speeds[1]) / 2.0;
                            gate.cycle_time
                        });
                        record(&history, ctx.now(), cycle);
                    }
                }
            }
        })
        .task("RELEASE", move |ctx| {
            let (port, device, death) = (release_port.clone(), device.clone(), Arc::clone(&death));
            async move {
                let mut let_1_go = ctx.task_user(&port)?;
                let dies_at = *death.lock().unwrap_or_else(PoisonError::into_inner);
                loop {
                    let dying = async {
                        match dies_at {
                            Some(at) => ctx.clock().sleep_until(at).await,
                            None => std::future::pending().await,
                        }
                    };
                    tokio::select! {
                        biased;
                        () = dying => {
                            death.lock().unwrap_or_else(PoisonError::into_inner).take();
                            return Err("RELEASE died (injected fault)".into());
                        }
                        received = ctx.receive(&mut let_1_go) => {
                            let ((), rc) = received?;
                            rc.reply(device.release().await.rc());
                        }
                    }
                }
            }
        })
        .task("BOUNDED_BUFFER", move |_ctx| {
            let port = buffer_port.clone();
            async move {
                BoundedBuffer::<(i32, f64), 20>::new()
                    .run(port.filter()?)
                    .await;
                Ok(())
            }
        })
        .exception(timeout, |ctx: Ctx<GateState>, _| async move {
            // {Signal for help. Perhaps reset timer, perhaps kill and restart RELEASE}
            alarm(
                &ctx,
                AlarmKind::NoAnswer,
                "RELEASE did not answer within 2 s: killing it and starting a new copy",
            );
            ctx.restart_task("RELEASE");
        })
        .exception(
            release_failed,
            |ctx: Ctx<GateState>, exception| async move {
                // The next LET_1_GO times out and restarts it (the Appendix's note 2).
                alarm(
                    &ctx,
                    AlarmKind::TaskFailed,
                    format!("RELEASE failed: {}", exception.detail),
                );
            },
        )
}

fn record(history: &SharedCycleTimes, at: Instant, cycle: f64) {
    history
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .set(at.since_start().as_secs_f64(), cycle);
}
