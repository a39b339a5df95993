//! waitfor and getmess: n-way rendezvous of named tasks.

mod common;

use common::{at, paused_runtime, secs};

use std::sync::{Arc, Mutex};
use std::time::Duration;

use imrs_core::prelude::*;
use imrs_core::time::drive;
use imrs_core::{Pool, WaitFor, WaitForError};
use imrs_testkit::poll_once;

/// `n` tasks named T0..Tn each pool their number after `i` seconds; each combines the pool
/// its own way (its number times 1000 plus the sum of all). Returns, for each task, its
/// result and the second it went on.
fn rendezvous_of(n: usize) -> Vec<(u64, u64)> {
    paused_runtime().block_on(async move {
        let (cell, clock) = Cell::virtual_clock();
        let names: Vec<String> = (0..n).map(|i| format!("T{i}")).collect();
        let barrier = WaitFor::<u64>::new("MEET", names.clone(), cell.clock().clone()).unwrap();
        let results = Arc::new(Mutex::new(vec![(0, 0); n]));
        let mut spec = ModuleSpec::new("TEAM", ());
        for (i, name) in names.iter().enumerate() {
            let (barrier, results) = (barrier.clone(), Arc::clone(&results));
            spec = spec.task(name.clone(), move |ctx| {
                let (barrier, results) = (barrier.clone(), Arc::clone(&results));
                async move {
                    ctx.delay(Duration::from_secs(i as u64)).await;
                    let mine = i as u64;
                    let combine = |pool: &Pool<u64>| {
                        assert_eq!(pool.getmess(&format!("T{i}")), Some(&mine));
                        mine * 1000 + pool.iter().map(|(_, m)| m).sum::<u64>()
                    };
                    let result = ctx.waitfor(&barrier, mine, combine, None).await?;
                    results.lock().unwrap()[i] = (result, ctx.now().since_start().as_secs());
                    Ok(())
                }
            });
        }
        let mut team = cell.start(spec).unwrap();
        drive(
            &clock,
            Instant::from_start(Duration::from_secs(n as u64 + 1)),
        )
        .await;
        assert_eq!(team.finished().await, ModuleOutcome::Finished);
        results.lock().unwrap().clone()
    })
}

#[test]
fn everyone_waits_for_the_last_and_then_each_combines_the_pool() {
    for n in [2, 3, 40] {
        let sum: u64 = (0..n as u64).sum();
        let expected: Vec<_> = (0..n as u64)
            .map(|i| (i * 1000 + sum, n as u64 - 1))
            .collect();
        // The last task arrives at n-1 seconds; nobody goes on before.
        assert_eq!(rendezvous_of(n), expected, "n = {n}");
    }
}

#[test]
fn each_task_gets_its_own_combination_of_the_same_pool() {
    paused_runtime().block_on(async {
        let clock: SharedClock = Arc::new(VirtualClock::new());
        let barrier = WaitFor::<&'static str>::new("TRIO", ["A", "B", "C"], clock).unwrap();
        let mut joins = Vec::new();
        for (task, message) in [("A", "a"), ("B", "b"), ("C", "c")] {
            let barrier = barrier.clone();
            joins.push(tokio::spawn(async move {
                barrier
                    .waitfor(
                        task,
                        message,
                        |pool| {
                            // Each task reads the others' messages with getmess.
                            let others: String = ["A", "B", "C"]
                                .iter()
                                .filter(|other| **other != task)
                                .map(|other| *pool.getmess(other).unwrap())
                                .collect();
                            format!("{task}:{others}")
                        },
                        None,
                    )
                    .await
                    .unwrap()
            }));
        }
        let mut results = Vec::new();
        for join in joins {
            results.push(join.await.unwrap());
        }
        assert_eq!(results, ["A:bc", "B:ac", "C:ab"]);
        // The rendezvous is reusable: a second round works the same way.
        let again: Vec<_> = ["A", "B", "C"]
            .into_iter()
            .map(|task| {
                let barrier = barrier.clone();
                tokio::spawn(
                    async move { barrier.waitfor(task, task, |pool| pool.len(), None).await },
                )
            })
            .collect();
        for join in again {
            assert_eq!(join.await.unwrap().unwrap(), 3);
        }
    });
}

#[test]
fn a_late_task_makes_the_others_time_out_and_they_get_their_messages_back() {
    paused_runtime().block_on(async {
        let clock = VirtualClock::new();
        let shared: SharedClock = Arc::new(clock.clone());
        let barrier = WaitFor::<u32>::new("SYNC", ["EARLY", "LATE"], shared).unwrap();
        let early = {
            let barrier = barrier.clone();
            tokio::spawn(async move {
                barrier
                    .waitfor("EARLY", 7, |pool| pool.len(), Some(Duration::from_secs(5)))
                    .await
            })
        };
        drive(&clock, Instant::from_start(Duration::from_secs(6))).await;
        match early.await.unwrap() {
            Err(WaitForError::Timeout {
                barrier,
                missing,
                message,
            }) => {
                assert_eq!(barrier, "SYNC");
                assert_eq!(missing, [Name::from("LATE")]);
                assert_eq!(message, 7);
            }
            other => panic!("expected a timeout, got {other:?}"),
        }
        // The withdrawn message is gone: when both come later, the round is a fresh one.
        let late = {
            let barrier = barrier.clone();
            tokio::spawn(async move {
                barrier
                    .waitfor("LATE", 2, |pool| *pool.getmess("EARLY").unwrap(), None)
                    .await
            })
        };
        let early = barrier
            .waitfor("EARLY", 1, |pool| *pool.getmess("LATE").unwrap(), None)
            .await;
        assert_eq!(early.unwrap(), 2);
        assert_eq!(late.await.unwrap().unwrap(), 1);
    });
}

#[test]
fn a_stranger_is_refused_with_its_message() {
    paused_runtime().block_on(async {
        let clock: SharedClock = Arc::new(VirtualClock::new());
        let barrier = WaitFor::<u8>::new("PAIR", ["A", "B"], clock).unwrap();
        let refused = barrier.waitfor("Z", 9, |_| (), None).await;
        assert_eq!(
            refused,
            Err(WaitForError::NotAMember {
                barrier: "PAIR".into(),
                task: "Z".into(),
                message: 9
            })
        );
        assert_eq!(
            refused.unwrap_err().to_string(),
            "task Z is not named in waitfor PAIR"
        );
    });
}

#[test]
fn a_task_named_twice_is_refused_when_the_rendezvous_is_made() {
    let clock: SharedClock = Arc::new(VirtualClock::new());
    let refused = WaitFor::<u8>::new("PAIR", ["A", "B", "A"], clock).unwrap_err();
    assert_eq!(refused.barrier, "PAIR");
    assert_eq!(refused.task, "A");
    assert_eq!(
        refused.to_string(),
        "waitfor PAIR names task A twice: it could never complete"
    );
}

#[test]
fn a_dropped_waiter_withdraws_its_message_and_may_wait_again() {
    paused_runtime().block_on(async {
        let clock = VirtualClock::new();
        let shared: SharedClock = Arc::new(clock.clone());
        let barrier = WaitFor::<&'static str>::new("PAIR", ["A", "B"], shared.clone()).unwrap();
        // A waits, but an outer timeout drops its wait before B comes.
        let a = {
            let barrier = barrier.clone();
            let clock = shared.clone();
            tokio::spawn(async move {
                let first = tokio::select! {
                    met = barrier.waitfor("A", "stale", |_| (), None) => Some(met),
                    () = clock.sleep(secs(1)) => None,
                };
                assert!(first.is_none(), "B never came in the first second");
                clock.sleep(secs(4)).await;
                barrier
                    .waitfor("A", "fresh", |pool| *pool.getmess("B").unwrap(), None)
                    .await
            })
        };
        let b = {
            let barrier = barrier.clone();
            let clock = shared.clone();
            tokio::spawn(async move {
                clock.sleep(secs(2)).await;
                barrier
                    .waitfor("B", "b", |pool| *pool.getmess("A").unwrap(), None)
                    .await
            })
        };
        imrs_core::time::drive(&clock, at(10)).await;
        // B met A's second call, not the message of the dropped one.
        assert_eq!(b.await.unwrap().unwrap(), "fresh");
        assert_eq!(a.await.unwrap().unwrap(), "b");
    });
}

#[test]
fn rounds_across_threads_never_mix_and_lose_no_message() {
    // Eight tasks on four worker threads meet for 300 rounds; each pools its round's number,
    // so a pool holding a message of another round, or one missing, fails the combination.
    const TASKS: usize = 8;
    const ROUNDS: u64 = 300;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(4)
        .build()
        .unwrap();
    runtime.block_on(async {
        let clock: SharedClock = Arc::new(VirtualClock::new());
        let names: Vec<String> = (0..TASKS).map(|i| format!("T{i}")).collect();
        let barrier = WaitFor::<u64>::new("MEET", names.clone(), clock).unwrap();
        let tasks: Vec<_> = names
            .into_iter()
            .map(|name| {
                let barrier = barrier.clone();
                tokio::spawn(async move {
                    for round in 0..ROUNDS {
                        let seen = barrier
                            .waitfor(
                                &name,
                                round,
                                |pool| pool.iter().map(|(_, m)| *m).collect::<Vec<_>>(),
                                None,
                            )
                            .await
                            .unwrap();
                        assert_eq!(seen, vec![round; TASKS], "{name} in round {round}");
                    }
                })
            })
            .collect();
        for task in tasks {
            task.await.unwrap();
        }
    });
}

#[test]
fn a_waiter_dropped_after_its_round_was_released_takes_nothing_from_the_next() {
    paused_runtime().block_on(async {
        let clock: SharedClock = Arc::new(VirtualClock::new());
        let barrier = WaitFor::<&'static str>::new("PAIR", ["A", "B"], clock).unwrap();
        let mut a = Box::pin(barrier.waitfor("A", "a1", |_| (), None));
        // A arrives and waits; B completes the round; A's wait is dropped unread.
        assert!(poll_once(a.as_mut()).is_pending());
        let b = barrier
            .waitfor("B", "b1", |pool| *pool.getmess("A").unwrap(), None)
            .await;
        assert_eq!(b, Ok("a1"));
        drop(a);
        // The next round meets with the next messages, none withdrawn by the dropped wait.
        let (a, b) = tokio::join!(
            barrier.waitfor("A", "a2", |pool| *pool.getmess("B").unwrap(), None),
            barrier.waitfor("B", "b2", |pool| *pool.getmess("A").unwrap(), None),
        );
        assert_eq!((a, b), (Ok("b2"), Ok("a2")));
    });
}
