//! A peer that is gone for good answers at once: whoever waits on a port whose other end was
//! held by a module that finished, failed beyond its restart policy or was killed with no
//! restart coming gets `PeerGone` then, not at its timeout (and never waits for ever); while a
//! restart is coming, it waits for the new copy.

mod common;

use std::future::Future;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use common::{at, multi_thread_runtime, paused_runtime, secs};

use imrs_core::TaskError;
use imrs_core::prelude::*;
use imrs_core::time::drive;
use imrs_ports::{QueryError, RealClock, ReceiveError, SendError};

type Status = Port<(), u32, usage::Response, AnyUser, 2>;

/// What a querier saw: each outcome (`Ok(answer)` or the error's variant and module) and when,
/// in seconds on the cell's clock.
type Seen = Arc<Mutex<Vec<(Result<u32, String>, u64)>>>;

fn describe<T>(error: &QueryError<T>) -> String {
    match error {
        QueryError::PeerGone { module, .. } => format!("PeerGone({module})"),
        other => format!("{other:?}"),
    }
}

/// RESPONDER answers STATUS from its state; its one task runs `work` and then finishes.
fn responder<F, Fut>(status: &Status, work: F) -> ModuleSpec<u32>
where
    F: FnMut(Ctx<u32>) -> Fut + Send + 'static,
    Fut: Future<Output = Result<(), TaskError>> + Send + 'static,
{
    ModuleSpec::new("RESPONDER", 42u32)
        .order(["WORK", "STATUS.ASK", "RESPONDER"])
        .respond(&status.handler("ASK"), |answer: &u32, ()| *answer)
        .task("RESPONDER", work)
}

/// ASKER queries STATUS (with no timeout) at each of `times` seconds, noting what it got.
fn asker(status: &Status, times: &'static [u64], seen: &Seen) -> ModuleSpec<()> {
    let (status, seen) = (status.clone(), Arc::clone(seen));
    ModuleSpec::new("ASKER", ()).task("ASKER", move |ctx| {
        let (status, seen) = (status.clone(), Arc::clone(&seen));
        async move {
            let mut status = status.user_named("ASKER")?;
            let start = ctx.now();
            for &time in times {
                let wait = Instant::from_start(secs(time)).saturating_duration_since(ctx.now());
                ctx.delay(wait).await;
                let outcome = ctx.query(&mut status, ()).await.map_err(|e| describe(&e));
                let now = ctx.now().saturating_duration_since(start).as_secs();
                seen.lock().unwrap().push((outcome, now));
            }
            Ok(())
        }
    })
}

fn declare(cell: &Cell) -> Status {
    // Declared with the cell, as a wired cell does: the declaration lives on, so a port is
    // never "closed" here; only the peer's presence can say it is gone.
    cell.port(PortSpec::new("STATUS", "RESPONDER")).unwrap()
}

#[test]
fn a_query_to_a_finished_module_fails_at_once_and_so_do_later_ones() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let status = declare(&cell);
        cell.start(responder(&status, |ctx| async move {
            ctx.delay(secs(5)).await;
            Ok(())
        }))
        .unwrap();
        let seen = Seen::default();
        let mut asker = cell.start(asker(&status, &[2, 10, 11], &seen)).unwrap();
        drive(&clock, at(400)).await;
        assert_eq!(asker.finished().await, ModuleOutcome::Finished);
        let gone = || Err("PeerGone(RESPONDER)".to_string());
        assert_eq!(
            *seen.lock().unwrap(),
            [(Ok(42), 2), (gone(), 10), (gone(), 11)]
        );
    });
}

#[test]
fn a_pending_query_fails_when_its_responder_is_killed_with_no_restart_coming() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let status = declare(&cell);
        // In WORK, which outranks the handler, for ever: the query at 2 s waits.
        cell.start(responder(&status, |ctx| async move {
            ctx.section(&Section::new("WORK"), std::future::pending::<()>())
                .await;
            Ok(())
        }))
        .unwrap();
        let seen = Seen::default();
        cell.start(asker(&status, &[2], &seen)).unwrap();
        drive(&clock, at(4)).await;
        assert!(seen.lock().unwrap().is_empty(), "the query waits in WORK");
        assert!(cell.kill("RESPONDER"));
        drive(&clock, at(400)).await;
        assert_eq!(
            *seen.lock().unwrap(),
            [(Err("PeerGone(RESPONDER)".to_string()), 4)]
        );
    });
}

#[test]
fn while_a_restart_is_coming_a_query_waits_for_the_new_copy() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let status = declare(&cell);
        let copies = Arc::new(Mutex::new(0));
        let port = status.clone();
        cell.supervise(RestartPolicy::restart(1, secs(3)), move || {
            let copies = Arc::clone(&copies);
            responder(&port, move |ctx| {
                let copy = {
                    let mut copies = copies.lock().unwrap();
                    *copies += 1;
                    *copies
                };
                async move {
                    if copy == 1 {
                        // The first copy works in WORK until it is killed.
                        ctx.section(&Section::new("WORK"), std::future::pending::<()>())
                            .await;
                    }
                    std::future::pending::<()>().await;
                    Ok(())
                }
            })
        })
        .unwrap();
        let seen = Seen::default();
        cell.start(asker(&status, &[2], &seen)).unwrap();
        drive(&clock, at(4)).await;
        assert!(cell.kill("RESPONDER"));
        drive(&clock, at(400)).await;
        // Killed at 4 s, restarted at 7 s: the new copy answers the waiting query.
        assert_eq!(*seen.lock().unwrap(), [(Ok(42), 7)]);
    });
}

#[test]
fn a_send_fails_when_its_receiver_fails_beyond_its_restart_policy() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let card: Port<u32, i32, usage::Send> = cell
            .port(PortSpec::new("CARD_IN_PLACE", "LOAD_CARD"))
            .unwrap();
        let port = card.clone();
        // Each copy attaches, fails after 1 s without receiving; one restart after 3 s.
        cell.supervise(RestartPolicy::restart(1, secs(3)), move || {
            let port = port.clone();
            ModuleSpec::new("SCREW_IN_CARD", ()).task("SCREW_IN_CARD", move |ctx| {
                let port = port.clone();
                async move {
                    let _card = port.user_named("SCREW_IN_CARD")?;
                    ctx.delay(secs(1)).await;
                    Err::<(), TaskError>("the screwdriver jammed".into())
                }
            })
        })
        .unwrap();
        let seen: Arc<Mutex<Option<(String, u64)>>> = Arc::default();
        let noted = Arc::clone(&seen);
        cell.start(
            ModuleSpec::new("LOAD_CARD", ()).task("LOAD_CARD", move |ctx| {
                let (card, noted) = (card.clone(), Arc::clone(&noted));
                async move {
                    let mut card = card.owner()?;
                    ctx.delay(secs(2)).await;
                    let failed = ctx.send(&mut card, 7).await.unwrap_err();
                    let now = ctx.now().since_start().as_secs();
                    let SendError::PeerGone {
                        module, message, ..
                    } = failed
                    else {
                        panic!("{failed:?}");
                    };
                    assert_eq!(message, 7, "the card comes back");
                    *noted.lock().unwrap() = Some((module.to_string(), now));
                    Ok(())
                }
            }),
        )
        .unwrap();
        drive(&clock, at(400)).await;
        // Copy 1 fails at 1 s, copy 2 runs 4-5 s and fails: gone for good at 5 s.
        assert_eq!(
            *seen.lock().unwrap(),
            Some(("SCREW_IN_CARD".to_string(), 5))
        );
    });
}

#[test]
fn a_receive_fails_when_every_sender_has_finished() {
    paused_runtime().block_on(async {
        let (cell, clock) = Cell::virtual_clock();
        let frequency: Port<u32, (), usage::Receive> =
            cell.port(PortSpec::new("FREQUENCY", "GATE")).unwrap();
        let port = frequency.clone();
        cell.start(ModuleSpec::new("SETTER", ()).task("SETTER", move |ctx| {
            let port = port.clone();
            async move {
                let mut frequency = port.user_named("SETTER")?;
                ctx.send(&mut frequency, 10).await?;
                Ok(())
            }
        }))
        .unwrap();
        let got: Arc<Mutex<Vec<Result<u32, ReceiveError>>>> = Arc::default();
        let noted = Arc::clone(&got);
        cell.start(ModuleSpec::new("GATE", ()).task("GATE", move |ctx| {
            let (port, noted) = (frequency.clone(), Arc::clone(&noted));
            async move {
                let mut frequency = port.owner()?;
                for _ in 0..2 {
                    let got = ctx.receive(&mut frequency).await;
                    let got = got.map(|(value, reply)| {
                        reply.reply(());
                        value
                    });
                    noted.lock().unwrap().push(got);
                }
                Ok(())
            }
        }))
        .unwrap();
        drive(&clock, at(10)).await;
        let gone = ReceiveError::PeerGone {
            port: "FREQUENCY".into(),
            module: "SETTER".into(),
        };
        assert_eq!(*got.lock().unwrap(), [Ok(10), Err(gone)]);
    });
}

/// The same promises on the wall clock, on a multi-thread runtime: a wait with no timeout
/// ends when its peer is gone. A guard fails the test instead of hanging it.
#[test]
fn on_real_time_no_wait_without_a_timeout_outlives_its_peer() {
    let runtime = multi_thread_runtime();
    runtime.block_on(async {
        let guarded = tokio::time::timeout(Duration::from_secs(60), async {
            let cell = Cell::new(Arc::new(RealClock::new()));
            let status = declare(&cell);
            // Finished before anyone asks.
            let mut finished = cell
                .start(responder(&status, |_| async { Ok(()) }))
                .unwrap();
            assert_eq!(finished.finished().await, ModuleOutcome::Finished);
            let mut status_user = status.user_named("ASKER").unwrap();
            let failed = status_user.query(()).await.unwrap_err();
            assert!(matches!(failed, QueryError::PeerGone { .. }), "{failed:?}");

            // Killed (not supervised) while a query waits in WORK.
            let mut killed = cell
                .start(responder(&status, |ctx: Ctx<u32>| async move {
                    ctx.section(&Section::new("WORK"), std::future::pending::<()>())
                        .await;
                    Ok(())
                }))
                .unwrap();
            let asking =
                tokio::spawn(async move { status_user.query(()).await.map_err(|e| describe(&e)) });
            tokio::task::yield_now().await;
            killed.kill();
            assert_eq!(killed.finished().await, ModuleOutcome::Killed);
            assert_eq!(
                asking.await.unwrap(),
                Err("PeerGone(RESPONDER)".to_string())
            );
        })
        .await;
        assert!(guarded.is_ok(), "a wait outlived its peer");
    });
}
