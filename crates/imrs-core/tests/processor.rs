//! Modules co-scheduled on one processor: they rendezvous, keep their order and timing on
//! virtual time, survive a neighbour's panic, and leave the runtime its turn.

mod common;

use common::{at, paused_runtime, secs};

use std::future::Future;
use std::pin::Pin;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::task::{Context, Poll};

use imrs_core::JobLost;
use imrs_core::prelude::*;
use imrs_core::time::drive;

/// A feeder that answers each request after a second of work, and a robot that asks
/// `rounds` times, both on one processor. Returns the cell's event log.
fn feeder_and_robot(rounds: u32) -> Vec<Event> {
    paused_runtime().block_on(async move {
        let (cell, clock) = Cell::virtual_clock();
        let processor = Processor::new("CPU1");
        let port: Port<u32, u32, usage::Receive> =
            cell.port(PortSpec::new("FEED", "FEEDER")).unwrap();
        let serving = port.clone();
        let feeder = ModuleSpec::new("FEEDER", ()).task("FEEDER", move |ctx| {
            let port = serving.clone();
            async move {
                let mut feed = port.owner()?;
                for _ in 0..rounds {
                    let (chip, reply) = ctx.receive(&mut feed).await?;
                    ctx.delay(secs(1)).await;
                    reply.reply(chip + 1);
                }
                Ok(())
            }
        });
        let robot = ModuleSpec::new("ROBOT", ()).task("ROBOT", move |ctx| {
            let port = port.clone();
            async move {
                let mut feed = port.user_named("ROBOT")?;
                for chip in 0..rounds {
                    let next = ctx.send(&mut feed, chip).await?;
                    assert_eq!(next, chip + 1, "the feeder answers this robot's request");
                }
                Ok(())
            }
        });
        let mut feeder = cell.start_on(&processor, feeder).unwrap();
        let mut robot = cell.start_on(&processor, robot).unwrap();
        drive(&clock, at(u64::from(rounds) + 1)).await;
        assert_eq!(robot.finished().await, ModuleOutcome::Finished);
        assert_eq!(feeder.finished().await, ModuleOutcome::Finished);
        cell.events().snapshot()
    })
}

#[test]
fn modules_on_one_processor_rendezvous_on_virtual_time() {
    let events = feeder_and_robot(5);
    let finished = |module: &str| {
        events
            .iter()
            .find(|event| {
                event.module.as_str() == module && event.kind == EventKind::ModuleFinished
            })
            .map(|event| event.at)
    };
    // Five requests, one second of feeder work each: both finish at 5 s.
    assert_eq!(finished("ROBOT"), Some(at(5)), "{events:#?}");
    assert_eq!(finished("FEEDER"), Some(at(5)), "{events:#?}");
}

#[test]
fn modules_on_one_processor_run_the_same_way_every_time() {
    assert_eq!(feeder_and_robot(20), feeder_and_robot(20));
}

#[test]
fn a_job_that_panics_leaves_the_others_running() {
    paused_runtime().block_on(async {
        let processor = Processor::new("CPU1");
        let failing = processor.spawn(async { panic!("a job fails") });
        let sleeping = processor.spawn(async {
            tokio::time::sleep(secs(1)).await;
            7
        });
        assert_eq!(
            failing.await,
            Err(JobLost {
                processor: "CPU1".into()
            })
        );
        assert_eq!(
            sleeping.await,
            Ok(7),
            "the second job finishes after the first panicked"
        );
    });
}

/// A busy loop without `.await`s that suspend: a job that wakes itself at every poll,
/// `LIMIT` times, then waits for nothing. It counts its polls.
struct Busy(Arc<AtomicU64>);

impl Busy {
    const LIMIT: u64 = 100_000;
}

impl Future for Busy {
    type Output = ();

    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<()> {
        if self.0.fetch_add(1, Ordering::Relaxed) + 1 < Self::LIMIT {
            cx.waker().wake_by_ref();
        }
        Poll::Pending
    }
}

#[test]
fn a_job_that_keeps_waking_itself_does_not_starve_the_runtime() {
    let polls = Arc::new(AtomicU64::new(0));
    let counted = Arc::clone(&polls);
    let seen = paused_runtime().block_on(async move {
        let processor = Processor::new("CPU1");
        let _busy = processor.spawn(Busy(counted));
        // Another task on the same thread gets its turn while the busy job still wants to
        // run: it sees fewer than all of the busy job's polls. A processor that kept the
        // thread until no job was woken would let it in only after all of them.
        tokio::spawn(async move { polls.load(Ordering::Relaxed) })
            .await
            .unwrap()
    });
    assert!(
        0 < seen && seen < Busy::LIMIT,
        "the other task ran after {seen} of the busy job's polls"
    );
}

#[test]
fn jobs_woken_from_other_threads_are_not_lost() {
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .build()
        .unwrap();
    runtime.block_on(async {
        let processor = Processor::new("CPU1");
        let (to_job, mut job_inbox) = tokio::sync::mpsc::channel::<u64>(1);
        let (to_thread, thread_inbox) = std::sync::mpsc::channel::<u64>();
        let summing = processor.spawn(async move {
            let mut sum = 0;
            while let Some(n) = job_inbox.recv().await {
                sum += n;
                to_thread.send(n).unwrap();
            }
            sum
        });
        // An OS thread that answers each message with the next: every wake of the job
        // comes from outside the processor's task, racing its parking.
        let echo = std::thread::spawn(move || {
            for n in 1..=2_000 {
                to_job.blocking_send(n).unwrap();
                assert_eq!(thread_inbox.recv().unwrap(), n);
            }
        });
        assert_eq!(summing.await.unwrap(), (1..=2_000).sum::<u64>());
        echo.join().unwrap();
    });
}
