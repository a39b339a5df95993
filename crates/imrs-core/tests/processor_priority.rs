//! The processor as the seed's message handler: the most urgent woken job goes first, a
//! message on a port of higher priority lifts its receiver, and nobody starves.

mod common;

use common::paused_runtime;

use std::future::Future;
use std::pin::Pin;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::task::{Context, Poll};

use imrs_core::prelude::*;
use imrs_ports::Priority;

/// One step of busy work: wakes itself and yields once, so that the processor chooses again.
struct Step(bool);

impl Future for Step {
    type Output = ();

    fn poll(mut self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<()> {
        if self.0 {
            return Poll::Ready(());
        }
        self.0 = true;
        cx.waker().wake_by_ref();
        Poll::Pending
    }
}

fn step() -> Step {
    Step(false)
}

#[test]
fn the_most_urgent_woken_job_is_polled_first() {
    paused_runtime().block_on(async {
        let processor = Processor::new("CPU1");
        let polled: Arc<Mutex<Vec<&str>>> = Arc::default();
        let jobs = [
            ("routine", Priority::DEFAULT),
            ("low", Priority::declared(3)),
            ("urgent", Priority::declared(1)),
            ("middle", Priority::declared(2)),
            ("also low", Priority::declared(3)),
        ]
        .map(|(name, priority)| {
            let polled = Arc::clone(&polled);
            processor.spawn_with_priority(priority, async move {
                polled.lock().unwrap().push(name);
            })
        });
        for job in jobs {
            job.await.unwrap();
        }
        // Equals keep the order they were placed in.
        assert_eq!(
            *polled.lock().unwrap(),
            ["urgent", "middle", "low", "also low", "routine"]
        );
    });
}

/// What the emergency-stop run saw: the welder's step count when the stop was sent, when
/// the safety module received it, and when the welder stopped.
#[derive(Debug, PartialEq)]
struct Stopped {
    sent_at: u64,
    seen_at: u64,
    welder_steps: u64,
    events: Vec<Event>,
}

/// Seed 000 §5.1's case on one processor: a routine module (least urgent) sends an emergency
/// stop on port ESTOP to SAFETY (priority 4) while WELDER (priority 2) is busy and always
/// ready. SAFETY stops the welder when the message arrives.
fn emergency_stop(estop: PortSpec) -> Stopped {
    paused_runtime().block_on(async move {
        let (cell, _clock) = Cell::virtual_clock();
        let processor = Processor::new("CPU1");
        let estop: Port<&'static str, (), usage::Receive> = cell.port(estop).unwrap();
        let steps = Arc::new(AtomicU64::new(0));
        let halt = Arc::new(AtomicBool::new(false));
        let sent_at = Arc::new(AtomicU64::new(u64::MAX));
        let seen_at = Arc::new(AtomicU64::new(u64::MAX));

        let (welding, halted) = (Arc::clone(&steps), Arc::clone(&halt));
        let welder = ModuleSpec::new("WELDER", ())
            .priority(2)
            .task("WELDER", move |_ctx| {
                let (steps, halt) = (Arc::clone(&welding), Arc::clone(&halted));
                async move {
                    while !halt.load(Ordering::SeqCst) {
                        steps.fetch_add(1, Ordering::SeqCst);
                        step().await;
                    }
                    Ok(())
                }
            });
        let (port, watching, halting, seen) = (
            estop.clone(),
            Arc::clone(&steps),
            Arc::clone(&halt),
            Arc::clone(&seen_at),
        );
        let safety = ModuleSpec::new("SAFETY", ())
            .priority(4)
            .task("SAFETY", move |ctx| {
                let owner = ctx.owner(&port);
                let (steps, halt, seen) = (
                    Arc::clone(&watching),
                    Arc::clone(&halting),
                    Arc::clone(&seen),
                );
                async move {
                    let mut estop = owner?;
                    let (_why, reply) = ctx.receive(&mut estop).await?;
                    seen.store(steps.load(Ordering::SeqCst), Ordering::SeqCst);
                    halt.store(true, Ordering::SeqCst);
                    reply.reply(());
                    Ok(())
                }
            });
        let (port, counting, sent) = (estop.clone(), Arc::clone(&steps), Arc::clone(&sent_at));
        let routine = ModuleSpec::new("CONVEYOR", ())
            .uses(&estop)
            .task("CONVEYOR", move |ctx| {
                let user = ctx.user(&port);
                let (steps, sent) = (Arc::clone(&counting), Arc::clone(&sent));
                async move {
                    let mut estop = user?;
                    // A few routine steps first, so that the welder is well under way.
                    for _ in 0..3 {
                        step().await;
                    }
                    sent.store(steps.load(Ordering::SeqCst), Ordering::SeqCst);
                    ctx.send(&mut estop, "jam on the conveyor").await?;
                    Ok(())
                }
            });
        let mut welder = cell.start_on(&processor, welder).unwrap();
        let mut safety = cell.start_on(&processor, safety).unwrap();
        let mut routine = cell.start_on(&processor, routine).unwrap();
        for module in [&mut welder, &mut safety, &mut routine] {
            assert_eq!(module.finished().await, ModuleOutcome::Finished);
        }
        Stopped {
            sent_at: sent_at.load(Ordering::SeqCst),
            seen_at: seen_at.load(Ordering::SeqCst),
            welder_steps: steps.load(Ordering::SeqCst),
            events: cell.events().snapshot(),
        }
    })
}

#[test]
fn an_emergency_stop_on_an_urgent_port_goes_ahead_of_a_more_urgent_module() {
    let stopped = emergency_stop(PortSpec::new("ESTOP", "SAFETY").priority(1));
    assert!(stopped.sent_at > 0, "the welder was busy: {stopped:?}");
    assert_eq!(
        stopped.seen_at, stopped.sent_at,
        "SAFETY got the stop before the welder took another step"
    );
    assert_eq!(
        stopped.welder_steps, stopped.sent_at,
        "the welder stopped at the step where the alarm was raised"
    );
}

#[test]
fn without_the_port_priority_the_stop_waits_behind_the_more_urgent_module() {
    // The same cell with ESTOP declared without a priority: SAFETY ranks below WELDER, so the
    // stop is served only when SAFETY has aged. This is what the lift above saves.
    let stopped = emergency_stop(PortSpec::new("ESTOP", "SAFETY"));
    assert!(
        stopped.seen_at > stopped.sent_at,
        "the welder went on while the stop waited: {stopped:?}"
    );
    assert!(
        stopped.seen_at - stopped.sent_at <= Processor::AGING * TURN_STEPS,
        "yet SAFETY was served within the aging bound: {stopped:?}"
    );
}

/// How many steps a module may take in one poll by the processor: a module polls its own
/// woken threads again, up to its budget, before it yields.
const TURN_STEPS: u64 = 64;

#[test]
fn the_emergency_stop_runs_the_same_way_every_time() {
    let spec = || PortSpec::new("ESTOP", "SAFETY").priority(1);
    assert_eq!(emergency_stop(spec()), emergency_stop(spec()));
}

/// `hogs` jobs of the highest priority that are always ready, and one of no priority that
/// waits five times for a wake of its own: how many polls of the hogs each wait lasted.
fn waits_behind_hogs(hogs: usize) -> Vec<u64> {
    paused_runtime().block_on(async {
        let processor = Processor::new("CPU1");
        let hog_polls = Arc::new(AtomicU64::new(0));
        let done = Arc::new(AtomicBool::new(false));
        let running: Vec<_> = (0..hogs)
            .map(|_| {
                let (polls, stop) = (Arc::clone(&hog_polls), Arc::clone(&done));
                // Always ready, and as urgent as a job can be.
                processor.spawn_with_priority(Priority::declared(1), async move {
                    // Bounded, so that a processor that starved the low job would show it in
                    // the waits below rather than hang the test.
                    while !stop.load(Ordering::SeqCst) && polls.load(Ordering::SeqCst) < 100_000 {
                        polls.fetch_add(1, Ordering::SeqCst);
                        step().await;
                    }
                })
            })
            .collect();
        let (polls, stop) = (Arc::clone(&hog_polls), Arc::clone(&done));
        let low = processor.spawn(async move {
            let mut waits = Vec::new();
            for _ in 0..5 {
                let before = polls.load(Ordering::SeqCst);
                step().await;
                waits.push(polls.load(Ordering::SeqCst) - before);
            }
            stop.store(true, Ordering::SeqCst);
            waits
        });
        let waits = low.await.unwrap();
        for hog in running {
            hog.await.unwrap();
        }
        waits
    })
}

#[test]
fn a_ready_job_of_low_priority_is_polled_within_the_aging_bound() {
    for hogs in [1, 3, 7] {
        let waits = waits_behind_hogs(hogs);
        // n jobs on the processor: the bound is AGING + n - 1 polls of the others.
        let bound = Processor::AGING + hogs as u64;
        assert!(
            waits.iter().all(|&wait| wait <= bound),
            "{hogs} hogs: waits {waits:?} within {bound}"
        );
        assert!(
            waits.iter().all(|&wait| wait >= Processor::AGING - 1),
            "{hogs} hogs, more urgent, went first each time: {waits:?}"
        );
    }
}

/// Two idle jobs on a processor: ROUTINE (priority 2) receiving on ROUTINE_IN (no priority)
/// and SAFETY (priority 4) receiving on `estop`. Another thread, with the processor held
/// still, posts to ROUTINE first and then to SAFETY, so that both are woken from outside the
/// processor's thread before it looks. Returns the order in which they received.
fn served_after_wakes_from_another_thread(estop: PortSpec) -> Vec<&'static str> {
    paused_runtime().block_on(async move {
        let processor = Processor::new("CPU1");
        let routine_in =
            Port::<u8, (), usage::Receive>::new(PortSpec::new("ROUTINE_IN", "ROUTINE"));
        let estop = Port::<u8, (), usage::Receive>::new(estop);
        let served: Arc<Mutex<Vec<&'static str>>> = Arc::default();
        let mut jobs = Vec::new();
        for (name, priority, port) in [("ROUTINE", 2, &routine_in), ("SAFETY", 4, &estop)] {
            let (mut owner, served) = (port.owner().unwrap(), Arc::clone(&served));
            jobs.push(
                processor.spawn_with_priority(Priority::declared(priority), async move {
                    let (_, reply) = owner.receive().await.unwrap();
                    served.lock().unwrap().push(name);
                    reply.reply(());
                }),
            );
        }
        // Both jobs run once and park in their receive.
        for _ in 0..4 {
            tokio::task::yield_now().await;
        }
        assert!(served.lock().unwrap().is_empty());
        let (mut to_routine, mut to_safety) = (
            routine_in.user_named("CONVEYOR").unwrap(),
            estop.user_named("CONVEYOR").unwrap(),
        );
        let (posted, both_posted) = std::sync::mpsc::channel();
        let sender = std::thread::spawn(move || {
            tokio::runtime::Builder::new_current_thread()
                .build()
                .unwrap()
                .block_on(async move {
                    let routine = tokio::spawn(async move { to_routine.send(1).await });
                    let safety = tokio::spawn(async move { to_safety.send(2).await });
                    // One yield: each send has run once, posted, and woken its receiver.
                    tokio::task::yield_now().await;
                    posted.send(()).unwrap();
                    routine.await.unwrap().unwrap();
                    safety.await.unwrap().unwrap();
                });
        });
        // Held still (this thread runs the processor) until both wakes have come in.
        both_posted.recv().unwrap();
        for job in jobs {
            job.await.unwrap();
        }
        sender.join().unwrap();
        served.lock().unwrap().clone()
    })
}

#[test]
fn a_lift_carried_by_a_wake_from_another_thread_is_honoured() {
    let order =
        served_after_wakes_from_another_thread(PortSpec::new("ESTOP", "SAFETY").priority(1));
    assert_eq!(order, ["SAFETY", "ROUTINE"]);
}

#[test]
fn without_the_lift_the_more_urgent_job_goes_first_whoever_was_woken_first() {
    let order = served_after_wakes_from_another_thread(PortSpec::new("ESTOP", "SAFETY"));
    assert_eq!(order, ["ROUTINE", "SAFETY"]);
}
