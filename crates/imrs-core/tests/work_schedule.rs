//! Work schedules: perform, more, reinstate, and a failing step that is skipped.

mod common;

use common::paused_runtime;

use std::sync::{Arc, Mutex};
use std::time::Duration;

use imrs_core::prelude::*;
use imrs_core::time::drive;

/// One step of CHIP_IT's schedule: GRASP(feeder), INSERT(x, y).
#[derive(Debug, Clone, PartialEq)]
struct Chip {
    feeder: u32,
    at: (u32, u32),
}

fn schedule() -> WorkSchedule<Chip> {
    WorkSchedule::new()
        .step(
            1,
            Chip {
                feeder: 1,
                at: (10, 10),
            },
        )
        .step(
            2,
            Chip {
                feeder: 4,
                at: (20, 10),
            },
        )
        .step(
            1,
            Chip {
                feeder: 12,
                at: (30, 10),
            },
        )
        .step(
            1,
            Chip {
                feeder: 4,
                at: (40, 10),
            },
        )
}

#[tokio::test]
async fn perform_runs_the_most_urgent_step_first_and_more_counts_down() {
    let mut work = schedule();
    let mut order = Vec::new();
    assert_eq!(work.more(), 4);
    while work.more() > 0 {
        let performed = work
            .perform(|chip| {
                order.push(chip.feeder);
                async { Ok::<(), String>(()) }
            })
            .await;
        assert!(matches!(performed, Some(Performed::Done { .. })));
    }
    // Priority 1 first, in declaration order among equals; then priority 2.
    assert_eq!(order, [1, 12, 4, 4]);
    assert_eq!(work.perform(|_| async { Ok::<(), String>(()) }).await, None);
    work.reinstate();
    assert_eq!(work.more(), 4);
}

#[test]
fn an_empty_feeder_skips_its_step_and_the_others_still_run() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let inserted = Arc::new(Mutex::new(Vec::new()));
        let seen = Arc::clone(&inserted);
        let chip_it = ModuleSpec::new("CHIP_IT", ()).task("CHIP_IT", move |ctx| {
            let seen = Arc::clone(&seen);
            async move {
                let mut work = schedule();
                work.reinstate();
                while work.more() > 0 {
                    let inserted = Arc::clone(&seen);
                    ctx.perform(&mut work, |chip| {
                        let chip = chip.clone();
                        let ctx = ctx.clone();
                        async move {
                            ctx.delay(Duration::from_secs(1)).await;
                            if chip.feeder == 12 {
                                return Err(format!("feeder {} is empty", chip.feeder));
                            }
                            inserted.lock().unwrap().push(chip.at);
                            Ok(())
                        }
                    })
                    .await;
                }
                Ok(())
            }
        });
        let mut chip_it = cell.start(chip_it).unwrap();
        drive(&clock, Instant::from_start(Duration::from_secs(10))).await;
        assert_eq!(chip_it.finished().await, ModuleOutcome::Finished);
        assert_eq!(*inserted.lock().unwrap(), [(10, 10), (40, 10), (20, 10)]);
        let skipped: Vec<_> = cell
            .events()
            .snapshot()
            .into_iter()
            .filter_map(|event| match event.kind {
                EventKind::StepFailed { step, error } => Some((step, error)),
                _ => None,
            })
            .collect();
        assert_eq!(
            skipped,
            [(
                "Chip { feeder: 12, at: (30, 10) }".to_string(),
                "feeder 12 is empty".to_string()
            )]
        );
    });
}
