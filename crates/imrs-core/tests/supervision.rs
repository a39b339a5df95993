//! Supervision: killed and failed modules and tasks, restarted copies, and ports that
//! outlive them.

mod common;

use common::{at, paused_runtime, secs};

use std::sync::Arc;
use std::sync::atomic::{AtomicU32, Ordering};

use imrs_core::TaskError;
use imrs_core::prelude::*;
use imrs_core::time::drive;
use imrs_ports::QueryError;

fn kinds_of(cell: &Cell, module: &str) -> Vec<(Instant, EventKind)> {
    cell.events()
        .snapshot()
        .into_iter()
        .filter(|event| event.module == module)
        .map(|event| (event.at, event.kind))
        .collect()
}

#[test]
fn a_module_killed_mid_rendezvous_fails_its_users_and_its_copy_serves_them_after() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        // SCREW_IN_CARD's port: LOAD_CARD sends a card, the screwer replies when done.
        let card_in_place: Port<u32, i32, usage::Send> = cell
            .port(PortSpec::new("CARD_IN_PLACE", "LOAD_CARD"))
            .unwrap();
        let copies = Arc::new(AtomicU32::new(0));
        let screwer_port = card_in_place.clone();
        let screwer_copies = Arc::clone(&copies);
        let screwer = cell
            .supervise(RestartPolicy::restart(3, secs(1)), move || {
                let port = screwer_port.clone();
                let copies = Arc::clone(&screwer_copies);
                ModuleSpec::new("SCREW_IN_CARD", ()).task("SCREW_IN_CARD", move |ctx| {
                    let port = port.clone();
                    let copy = copies.fetch_add(1, Ordering::SeqCst);
                    async move {
                        let mut card_in_place = port.user_named("SCREW_IN_CARD")?;
                        loop {
                            let (card, reply) = match ctx.receive(&mut card_in_place).await {
                                Ok(received) => received,
                                // LOAD_CARD finished for good: no card will ever come again.
                                Err(error) if error.is_peer_gone() => return Ok(()),
                                Err(error) => return Err(error.into()),
                            };
                            // The first copy takes 10 s to screw (and is killed meanwhile).
                            ctx.delay(secs(if copy == 0 { 10 } else { 1 })).await;
                            reply.reply(card as i32);
                        }
                    }
                })
            })
            .unwrap();
        let outcomes = Arc::new(std::sync::Mutex::new(Vec::new()));
        let seen = Arc::clone(&outcomes);
        cell.start(
            ModuleSpec::new("LOAD_CARD", ()).task("LOAD_CARD", move |ctx| {
                let (port, seen) = (card_in_place.clone(), Arc::clone(&seen));
                async move {
                    let mut card_in_place = port.owner()?;
                    for card in 1..=2 {
                        let outcome = ctx.send(&mut card_in_place, card).await;
                        let at = ctx.now().since_start().as_secs();
                        seen.lock().unwrap().push((
                            card,
                            outcome.map_err(|e| format!("{e:?}")),
                            at,
                        ));
                    }
                    Ok(())
                }
            }),
        )
        .unwrap();
        // Kill the screwer while it holds card 1.
        drive(&clock, at(3)).await;
        assert!(cell.kill("SCREW_IN_CARD"));
        drive(&clock, at(30)).await;

        let outcomes = outcomes.lock().unwrap().clone();
        assert_eq!(outcomes.len(), 2, "{outcomes:?}");
        // Card 1 was in flight to the dead copy: the sender got a typed error at the kill.
        let (card, first, when) = &outcomes[0];
        assert_eq!(*card, 1);
        assert!(
            first.as_ref().is_err_and(|e| e.contains("NoReply")),
            "{first:?}"
        );
        assert_eq!(*when, 3);
        // Card 2 was served by the new copy, started 1 s later, through the same port.
        assert_eq!(outcomes[1], (2, Ok(2), 5));
        assert_eq!(copies.load(Ordering::SeqCst), 2);
        let kinds = kinds_of(&cell, "SCREW_IN_CARD");
        assert!(kinds.contains(&(at(3), EventKind::ModuleKilled)));
        assert!(kinds.contains(&(at(4), EventKind::ModuleRestarted { attempt: 1 })));
        drop(screwer);
    });
}

#[test]
fn a_failing_task_is_restarted_with_backoff_until_its_policy_is_spent() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let spec = ModuleSpec::new("FEEDER", ()).task_with_policy(
            "FEED",
            RestartPolicy::restart(2, secs(1)),
            |_ctx| async move { Err::<(), TaskError>("jammed".into()) },
        );
        let mut feeder = cell.start(spec).unwrap();
        drive(&clock, at(10)).await;
        assert_eq!(
            feeder.finished().await,
            ModuleOutcome::Failed("task FEED failed: jammed".into())
        );
        let kinds = kinds_of(&cell, "FEEDER");
        let failures: Vec<_> = kinds
            .iter()
            .filter(|(_, kind)| matches!(kind, EventKind::TaskFailed { .. }))
            .map(|(when, _)| *when)
            .collect();
        // Fails at 0, restarted after 1 s, fails, restarted after 2 s, fails for good.
        assert_eq!(failures, [at(0), at(1), at(3)]);
        assert!(kinds.contains(&(
            at(3),
            EventKind::ModuleFailed {
                reason: "task FEED failed: jammed".into()
            }
        )));
    });
}

#[test]
fn a_panicking_task_is_reported_with_module_and_task_names_and_raises_its_exception() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let spec = ModuleSpec::new("CHIP_IT", Vec::<String>::new())
            .order(["FREEZE_CARD.FAILED", "CHIP_IT"])
            .exception(
                "FREEZE_CARD.FAILED",
                |ctx: Ctx<Vec<String>>, exception| async move {
                    ctx.alarm(format!("operator: {}", exception.detail));
                },
            )
            .task("FREEZE_CARD", |ctx| async move {
                ctx.delay(secs(2)).await;
                panic!("relay stuck open");
            })
            .task("CHIP_IT", |ctx| async move {
                ctx.delay(secs(5)).await;
                Ok(())
            });
        let mut chip_it = cell.start(spec).unwrap();
        drive(&clock, at(10)).await;
        assert_eq!(
            chip_it.finished().await,
            ModuleOutcome::Failed("task FREEZE_CARD failed: relay stuck open".into())
        );
        let events = cell.events().snapshot();
        let failed = events
            .iter()
            .find(|event| matches!(event.kind, EventKind::TaskFailed { .. }))
            .unwrap();
        assert_eq!(
            failed.to_string(),
            "[2.000s] CHIP_IT/FREEZE_CARD: task failed: relay stuck open"
        );
        assert!(events.iter().any(|event| event.kind
            == EventKind::Alarm {
                message: "operator: relay stuck open".into()
            }));
    });
}

#[test]
fn costarted_children_run_under_their_parent_and_answer_its_queries() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let ask_child2: Port<(), i32, usage::Query> = cell
            .port(PortSpec::new("ASK_CHILD2", "LOAD_IT").owner_timeout(secs(2)))
            .unwrap();
        let results = Arc::new(std::sync::Mutex::new(Vec::new()));
        let seen = Arc::clone(&results);
        let load_it = ModuleSpec::new("LOAD_IT", ()).task("LOAD_IT", move |ctx| {
            let (port, seen) = (ask_child2.clone(), Arc::clone(&seen));
            async move {
                let child = ModuleSpec::new("SCREW_IN_CARD", ())
                    .order(["ASK_CHILD2.STATUS", "SCREW_IN_CARD"])
                    .respond(&port.handler("STATUS"), |_: &(), ()| 0)
                    .task("SCREW_IN_CARD", |ctx| async move {
                        ctx.delay(secs(100)).await;
                        Ok(())
                    });
                let child = ctx.costart(child).unwrap();
                let mut ask_child2 = port.owner()?;
                ctx.delay(secs(4)).await;
                let alive = ctx
                    .query(&mut ask_child2, ())
                    .await
                    .map_err(|e| e.to_string());
                seen.lock().unwrap().push(alive);
                child.stop();
                ctx.delay(secs(4)).await;
                let dead: Result<i32, QueryError<()>> = ctx.query(&mut ask_child2, ()).await;
                seen.lock().unwrap().push(dead.map_err(|e| e.to_string()));
                Ok(())
            }
        });
        cell.start(load_it).unwrap();
        drive(&clock, at(20)).await;
        let results = results.lock().unwrap().clone();
        assert_eq!(results[0], Ok(0));
        // The child is gone for good: the parent's query fails at once, not at its timeout.
        assert_eq!(
            results[1],
            Err(
                "module SCREW_IN_CARD, the responder on port ASK_CHILD2, has ended for good".into()
            )
        );
        let started = cell
            .events()
            .snapshot()
            .into_iter()
            .find(|event| event.module == "SCREW_IN_CARD")
            .unwrap();
        assert_eq!(
            started.kind,
            EventKind::ModuleStarted {
                parent: Some("LOAD_IT".into())
            }
        );
    });
}

#[test]
fn a_kill_made_before_the_module_first_runs_is_not_lost() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let mut module = cell
            .start(ModuleSpec::new("GATE", ()).task("GATE", |ctx| async move {
                ctx.delay(secs(100)).await;
                Ok(())
            }))
            .unwrap();
        // Killed before its supervisor was ever polled.
        assert!(cell.kill("GATE"));
        drive(&clock, at(1)).await;
        assert_eq!(module.finished().await, ModuleOutcome::Killed);
    });
}

#[test]
fn a_module_whose_runtime_shuts_down_counts_as_killed_for_whoever_waits_on_it() {
    let runtime = paused_runtime();
    let mut handle = runtime.block_on(async {
        let (cell, _clock) = Cell::virtual_clock();
        let forever = ModuleSpec::new("WAITER", ()).task("WAITER", |ctx| async move {
            loop {
                ctx.delay(secs(60)).await;
            }
        });
        cell.start(forever).unwrap()
    });
    assert_eq!(handle.outcome(), None, "it runs while its runtime does");
    // Someone waits for it on a thread and runtime of their own: whether the wait has begun
    // when the runtime goes or begins after, it ends with the outcome.
    let mut waiting = handle.clone();
    let waiter = std::thread::spawn(move || {
        tokio::runtime::Builder::new_current_thread()
            .build()
            .unwrap()
            .block_on(waiting.finished())
    });
    // The runtime goes, and the module's task with it, before the module could end.
    drop(runtime);
    assert_eq!(waiter.join().unwrap(), ModuleOutcome::Killed);
    assert_eq!(handle.outcome(), Some(ModuleOutcome::Killed));
    let waited = paused_runtime().block_on(handle.finished());
    assert_eq!(waited, ModuleOutcome::Killed);
}
