//! The order scheduler against the Appendix's CHIP_IT and GATE orders, on a scripted
//! virtual clock.

mod common;

use common::{CHIP_IT_ORDER, at, paused_runtime, secs};

use imrs_core::prelude::*;
use imrs_core::time::drive;
use imrs_ports::AnyUser;

/// The events of `module`, in order.
fn events_of(cell: &Cell, module: &str) -> Vec<Event> {
    cell.events()
        .snapshot()
        .into_iter()
        .filter(|event| event.module == module)
        .collect()
}

#[test]
fn crit_section_is_served_in_insert_never_in_grasp_or_background_and_timeouts_outrank_all() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        // The test reads the primitives that succeed from the log: logged while observed.
        cell.observe(true);
        // SHARE_FEEDER1, answered by CHIP_IT's CRIT_SECTION handler. (In the Appendix CHIP_IT2
        // owns it; here CHIP_IT owns it so that four queriers can ask at overlapping times.)
        let share_feeder1: Port<(), i32, usage::Response, AnyUser, 4> = cell
            .port(PortSpec::new("SHARE_FEEDER1", "CHIP_IT"))
            .unwrap();
        // SHARE_FEEDER, owned by CHIP_IT (TIMEOUT=3 SEC); its responder never answers here.
        let share_feeder: Port<(), i32, usage::Query> = cell
            .port(PortSpec::new("SHARE_FEEDER", "CHIP_IT").owner_timeout(secs(3)))
            .unwrap();
        // READY_TO_CHIP, owned by CHIP_IT (TIMEOUT=60 SEC): its timeout is in the order.
        let _ready_to_chip: Port<(), (), usage::Receive> = cell
            .port(PortSpec::new("READY_TO_CHIP", "CHIP_IT").owner_timeout(secs(60)))
            .unwrap();
        let _silent_chip_it2 = share_feeder.answer("CHIP_IT2", |_: &(), ()| 1).unwrap();

        // CHIP_IT's script: background 0-10 s, GRASP 10-20 s (asking SHARE_FEEDER at 12 s,
        // which times out at 15 s), INSERT 20-30 s, background again 30-40 s.
        let chip_it = ModuleSpec::new("CHIP_IT", ())
            .order(CHIP_IT_ORDER)
            .respond(&share_feeder1.handler("CRIT_SECTION"), |_: &(), ()| 1)
            .exception("SHARE_FEEDER.TIMEOUT", |ctx: Ctx<()>, _| async move {
                ctx.alarm("SHARE_FEEDER timed out");
            })
            .task("CHIP_IT", move |ctx| {
                let share_feeder = share_feeder.clone();
                async move {
                    let mut share_feeder = share_feeder.owner()?;
                    ctx.delay(secs(10)).await;
                    ctx.section(&Section::new("GRASP"), async {
                        ctx.delay(secs(2)).await;
                        let refused = ctx.query(&mut share_feeder, ()).await;
                        assert!(refused.is_err_and(|error| error.is_timeout()));
                        ctx.delay(secs(5)).await;
                    })
                    .await;
                    ctx.section(&Section::new("INSERT"), ctx.delay(secs(10)))
                        .await;
                    ctx.delay(secs(10)).await;
                    Ok(())
                }
            });

        // Queriers ask CRIT_SECTION at 5 s (CHIP_IT in background), 12 s (in GRASP), 25 s (in
        // INSERT) and 33 s (background again).
        let mut askers = Vec::new();
        for asked in [5, 12, 25, 33] {
            let port = share_feeder1.clone();
            let asker = ModuleSpec::new(format!("ASK{asked}"), ())
                .uses_named("SHARE_FEEDER1", UsageKind::Query)
                .task("ASK", move |ctx| {
                    let port = port.clone();
                    async move {
                        let mut share_feeder1 = port.user_named(ctx.module().clone())?;
                        ctx.delay(secs(asked)).await;
                        assert_eq!(ctx.query(&mut share_feeder1, ()).await?, 1);
                        Ok(())
                    }
                });
            askers.push(asker);
        }
        cell.start(chip_it).unwrap();
        let askers: Vec<_> = askers
            .into_iter()
            .map(|asker| cell.start(asker).unwrap())
            .collect();
        drive(&clock, at(60)).await;
        for asker in &askers {
            assert_eq!(
                asker.outcome(),
                Some(ModuleOutcome::Finished),
                "{}",
                asker.name()
            );
        }

        let answered: Vec<_> = cell
            .events()
            .snapshot()
            .into_iter()
            .filter(|event| matches!(event.kind, EventKind::Queried { .. }))
            .map(|event| (event.module.to_string(), event.at))
            .collect();
        // Asked at 5 and 12: held back until INSERT begins at 20. Asked at 25, in INSERT:
        // at once. Asked at 33, in the background: only when CHIP_IT's task ends at 40.
        assert_eq!(
            answered,
            [
                ("ASK5".to_string(), at(20)),
                ("ASK12".to_string(), at(20)),
                ("ASK25".to_string(), at(25)),
                ("ASK33".to_string(), at(40)),
            ]
        );
        // Walk CHIP_IT's log: every CRIT_SECTION ran inside INSERT; the timeout handler ran
        // inside GRASP, as soon as the timeout came.
        let mut section = None;
        let mut responded_in = Vec::new();
        let mut timeout_handled = None;
        for event in events_of(&cell, "CHIP_IT") {
            match &event.kind {
                EventKind::SectionEntered { section: entered } => section = Some(entered.clone()),
                EventKind::SectionLeft { .. } => section = None,
                EventKind::Responded { .. } => responded_in.push(section.clone()),
                EventKind::ExceptionHandled { exception }
                    if exception == "SHARE_FEEDER.TIMEOUT" =>
                {
                    timeout_handled = Some((event.at, section.clone()));
                }
                _ => {}
            }
        }
        let insert = Some(Name::from("INSERT"));
        // The fourth ran after the task ended, outside any section of a live thread.
        assert_eq!(responded_in, [insert.clone(), insert.clone(), insert, None]);
        assert_eq!(timeout_handled, Some((at(15), Some(Name::from("GRASP")))));
    });
}

#[test]
fn a_let_1_go_timeout_interrupts_gates_background_which_restarts_release() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        // The test reads the primitives that succeed from the log: logged while observed.
        cell.observe(true);
        // LET_1_GO: USAGE=SEND, #USERS=1, TIMEOUT=2 sec.
        let let_1_go: Port<(), i32, usage::Send> = cell.port(
            PortSpec::new("LET_1_GO", "GATE")
                .owner_timeout(secs(2)),
        ).unwrap();
        let release_port = let_1_go.clone();
        let first_copy = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(true));
        let gate = ModuleSpec::new("GATE", 0u32)
            .order(["LET_1_GO.TIMEOUT", "GATE"])
            .exception("LET_1_GO.TIMEOUT", |ctx: Ctx<u32>, _| async move {
                // {Signal for help. Perhaps reset timer, perhaps kill and restart RELEASE}
                ctx.alarm("RELEASE does not answer");
                ctx.restart_task("RELEASE");
            })
            .task("GATE", move |ctx| {
                let let_1_go = let_1_go.clone();
                async move {
                    let mut let_1_go = let_1_go.owner()?;
                    for _ in 0..3 {
                        ctx.delay(secs(10)).await;
                        if let Ok(0) = ctx.send(&mut let_1_go, ()).await {
                            ctx.state().update(|released| *released += 1);
                        }
                    }
                    Ok(())
                }
            })
            .task("RELEASE", move |ctx| {
                let port = release_port.clone();
                // The first copy hangs with the pallet; a restarted copy works.
                let hangs = first_copy.swap(false, std::sync::atomic::Ordering::SeqCst);
                async move {
                    let mut let_1_go = port.user_named("RELEASE")?;
                    loop {
                        let ((), rc) = ctx.receive(&mut let_1_go).await?;
                        if hangs {
                            std::future::pending::<()>().await;
                        }
                        rc.reply(0);
                    }
                }
            });
        let gate = cell.start(gate).unwrap();
        drive(&clock, at(40)).await;
        assert_eq!(gate.outcome(), None, "RELEASE loops forever, so GATE runs on");

        let events = events_of(&cell, "GATE");
        let handled = events
            .iter()
            .find(|event| matches!(&event.kind, EventKind::ExceptionHandled { exception } if exception == "LET_1_GO.TIMEOUT"))
            .expect("the timeout was handled");
        assert_eq!(handled.at, at(12));
        let restarted = events
            .iter()
            .find(|event| matches!(event.kind, EventKind::TaskRestarted { .. }))
            .expect("RELEASE was restarted");
        assert_eq!(restarted.task.as_ref().map(Name::as_str), Some("RELEASE"));
        let sent: Vec<_> = events
            .iter()
            .filter(|event| matches!(event.kind, EventKind::Sent { .. }))
            .map(|event| event.at)
            .collect();
        // The first pallet timed out at 12 s; the next ones go at 22 s and 32 s.
        assert_eq!(sent, [at(22), at(32)]);
    });
}

#[test]
fn a_high_rank_handler_waiting_on_a_low_rank_task_of_its_module_is_not_blocked() {
    // Priority inversion: the rank 1 handler sends on a port that only the module's own
    // background task receives. Order gates only when handlers start, never a running
    // thread's progress, so the background task serves the handler.
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        // The test reads the primitives that succeed from the log: logged while observed.
        cell.observe(true);
        let help: Port<&'static str, u8, usage::Send> =
            cell.port(PortSpec::new("HELP", "GATE")).unwrap();
        let dead: Port<(), (), usage::Send> = cell
            .port(PortSpec::new("DEAD", "GATE").owner_timeout(secs(1)))
            .unwrap();
        let _nobody = dead.user_named("NOBODY").unwrap();
        let operator_port = help.clone();
        let gate = ModuleSpec::new("GATE", Vec::<u8>::new())
            .order(["DEAD.TIMEOUT", "GATE"])
            .exception("DEAD.TIMEOUT", move |ctx: Ctx<Vec<u8>>, _| {
                let help = help.clone();
                async move {
                    let mut help = help.owner().expect("one handler at a time");
                    let answer = ctx.send(&mut help, "pallet stuck").await.expect("answered");
                    ctx.state().update(|answers| answers.push(answer));
                }
            })
            .task("GATE", move |ctx| {
                let dead = dead.clone();
                async move {
                    let mut dead = dead.owner()?;
                    let _ = ctx.send(&mut dead, ()).await;
                    ctx.delay(secs(5)).await;
                    assert_eq!(ctx.state().read(Vec::clone), [42]);
                    Ok(())
                }
            })
            .task("OPERATOR", move |ctx| {
                let port = operator_port.clone();
                async move {
                    let mut help = port.user_named("OPERATOR")?;
                    let (_, reply) = ctx.receive(&mut help).await?;
                    reply.reply(42);
                    Ok(())
                }
            });
        let mut gate = cell.start(gate).unwrap();
        drive(&clock, at(10)).await;
        assert_eq!(gate.finished().await, ModuleOutcome::Finished);
    });
}
