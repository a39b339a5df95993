//! A response handler whose querier gave up while it ran: the answer reaches nobody, and the
//! module's log says so, rather than a `Responded` that no querier saw.

mod common;

use std::sync::mpsc;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use common::{multi_thread_runtime, secs};
use imrs_core::prelude::*;

#[test]
fn an_answer_to_a_querier_that_timed_out_is_logged_as_late() {
    multi_thread_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        // The test reads the primitives that succeed from the log: logged while observed.
        cell.observe(true);
        // The asker's query is bounded by 1 s of the cell's (virtual) clock.
        let status: Port<(), u32, usage::Response> = cell
            .port(PortSpec::new("STATUS", "PALLETIZER").user_timeout(secs(1)))
            .unwrap();
        let ask = status.handler("ASK");
        let (gave_up, seen) = mpsc::channel::<()>();
        let seen = Arc::new(Mutex::new(seen));
        // The handler takes 2 s of the cell's clock: it moves the clock on from a thread of
        // its own (a wake from there reaches the other worker), then waits until the asker
        // has given up before it answers.
        let palletizer = ModuleSpec::new("PALLETIZER", 7u32)
            .order([ask.name(), "PALLETIZER".into()])
            .respond(&ask, move |placed: &u32, ()| {
                let clock = clock.clone();
                std::thread::spawn(move || clock.advance(secs(2)))
                    .join()
                    .unwrap();
                let seen = seen.lock().unwrap();
                // Bounded only so that a broken build fails instead of hanging.
                seen.recv_timeout(Duration::from_secs(60))
                    .expect("the asker gives up");
                *placed
            })
            .task("PALLETIZER", |ctx| async move {
                ctx.delay(secs(3600)).await;
                Ok(())
            });
        let asker = ModuleSpec::new("ASKER", ())
            .uses(&status)
            .task("ASKER", move |ctx| {
                let (status, gave_up) = (ctx.user(&status), gave_up.clone());
                async move {
                    let mut status = status?;
                    let failed = ctx.query(&mut status, ()).await.unwrap_err();
                    assert!(failed.is_timeout(), "{failed}");
                    gave_up.send(()).unwrap();
                    Ok(())
                }
            });
        cell.start(palletizer).unwrap();
        let mut asker = cell.start(asker).unwrap();
        assert_eq!(asker.finished().await, ModuleOutcome::Finished);
        // The handler's answer lands on the other worker just after the asker ends: look a
        // bounded number of times, so that a missing event fails the test rather than hangs it.
        let mut late = Vec::new();
        for _ in 0..1_000_000 {
            late = cell
                .events()
                .snapshot()
                .into_iter()
                .filter(|event| matches!(event.kind, EventKind::RespondedLate { .. }))
                .collect();
            if !late.is_empty() {
                break;
            }
            tokio::task::yield_now().await;
        }
        assert_eq!(late.len(), 1);
        assert_eq!(late[0].module, "PALLETIZER");
        let line = late[0].to_string();
        assert!(
            line.contains("responded STATUS.ASK after its querier gave up"),
            "{line}"
        );
        let answered = cell
            .events()
            .snapshot()
            .into_iter()
            .filter(|event| matches!(event.kind, EventKind::Responded { .. }))
            .count();
        assert_eq!(answered, 0, "no querier read an answer");
    });
}
