//! Handlers that misbehave: a response handler that panics fails its one query and the module
//! lives on; an exception handler that raises its own exception again cannot starve the other
//! modules of its thread.

mod common;

use std::sync::Arc;
use std::sync::atomic::{AtomicU32, Ordering};

use common::{at, paused_runtime, secs};

use imrs_core::prelude::*;
use imrs_core::time::drive;
use imrs_ports::QueryError;

#[test]
fn a_panicking_response_handler_fails_its_query_and_the_module_answers_the_next() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let status: Port<u32, u32, usage::Response, AnyUser, 2> = cell
            .port(PortSpec::new("STATUS", "WELDER").owner_timeout(secs(5)))
            .unwrap();
        let welder = ModuleSpec::new("WELDER", 7u32)
            .order([status.handler("ASK").name(), "WELDER".into()])
            .respond(&status.handler("ASK"), |seams: &u32, question: u32| {
                assert!(question != 0, "question 0 is a bug in the handler");
                *seams + question
            })
            .task("WELDER", |ctx| async move {
                loop {
                    ctx.delay(secs(1)).await;
                }
            });
        let welder = cell.start(welder).unwrap();
        let port = status.clone();
        let asker = ModuleSpec::new("ASKER", ()).task("ASKER", move |ctx| {
            let port = port.clone();
            async move {
                let mut status = port.user_named("ASKER")?;
                let failed = ctx.query(&mut status, 0).await;
                assert!(
                    matches!(failed, Err(QueryError::NoResponse { .. })),
                    "{failed:?}"
                );
                // The module lives on and answers the next query at once.
                let asked = ctx.now();
                assert_eq!(ctx.query(&mut status, 1).await?, 8);
                assert_eq!(ctx.now(), asked);
                Ok(())
            }
        });
        let mut asker = cell.start(asker).unwrap();
        drive(&clock, at(3)).await;
        assert_eq!(asker.finished().await, ModuleOutcome::Finished);
        assert_eq!(welder.outcome(), None, "the welder still runs");
        let failure = cell
            .events()
            .snapshot()
            .into_iter()
            .find_map(|event| match event.kind {
                EventKind::TaskFailed { reason } if event.module == "WELDER" => {
                    Some((event.task, reason))
                }
                _ => None,
            })
            .expect("the panic is in the log");
        assert_eq!(failure.0.as_ref().map(Name::as_str), Some("STATUS.ASK"));
        assert!(
            failure.1.contains("question 0 is a bug in the handler"),
            "{}",
            failure.1
        );
    });
}

#[test]
fn an_exception_handler_that_raises_itself_again_does_not_starve_its_thread() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let handled = Arc::new(AtomicU32::new(0));
        let count = Arc::clone(&handled);
        let looping = ModuleSpec::new("LOOPING", ())
            .order(["AGAIN", "LOOPING"])
            .raises(["AGAIN"])
            .exception("AGAIN", move |ctx: Ctx<()>, _| {
                let count = Arc::clone(&count);
                async move {
                    if count.fetch_add(1, Ordering::Relaxed) < 20_000 {
                        ctx.raise("AGAIN", "once more");
                    }
                }
            })
            .task("LOOPING", |ctx| async move {
                ctx.raise("AGAIN", "first");
                ctx.delay(secs(3600)).await;
                Ok(())
            });
        cell.start(looping).unwrap();
        // Another task of the same thread notes how many handler runs it had to wait for.
        let seen = Arc::clone(&handled);
        let other = tokio::spawn(async move { seen.load(Ordering::Relaxed) });
        drive(&clock, at(1)).await;
        let waited_for = other.await.unwrap();
        // One poll of a module polls its threads at most 64 times.
        assert!(
            waited_for <= 2 * 64,
            "the other task waited for {waited_for} handler runs"
        );
    });
}
