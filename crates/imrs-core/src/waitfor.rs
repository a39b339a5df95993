//! `waitfor` and `getmess` (Shin 1985, §4.2 and §5.2): an n-way rendezvous of named tasks.
//!
//! Each named task calls [`WaitFor::waitfor`] with a message. It blocks until every named
//! task has called it; then each runs its own combining function over all pooled messages,
//! read-only, and goes on with the result. Inside the function, [`Pool::getmess`] reads one
//! task's message. The same rendezvous can be used again for the next round.

use std::collections::HashMap;
use std::fmt;
use std::future::poll_fn;
use std::pin::pin;
use std::sync::{Arc, Mutex, MutexGuard, OnceLock, PoisonError};
use std::task::{Poll, Waker};
use std::time::Duration;

use imrs_ports::{Name, SharedClock};

/// The named tasks of a rendezvous, and each one's place, found by name in O(1): every
/// arrival and every `getmess` looks one up, so a scan would make a round of n tasks O(n²).
#[derive(Debug)]
struct Members {
    names: Vec<Name>,
    places: HashMap<Box<str>, usize>,
}

impl Members {
    /// The members, or the first name listed twice: two members under one name could never
    /// both arrive, so such a rendezvous could never complete.
    fn new(names: Vec<Name>) -> Result<Self, Name> {
        let mut places = HashMap::with_capacity(names.len());
        for (place, name) in names.iter().enumerate() {
            if places.insert(name.as_str().into(), place).is_some() {
                return Err(name.clone());
            }
        }
        Ok(Self { names, places })
    }

    fn place(&self, task: &str) -> Option<usize> {
        self.places.get(task).copied()
    }
}

/// A rendezvous that names one task twice, refused by [`WaitFor::new`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DuplicateMember {
    /// The rendezvous.
    pub barrier: Name,
    /// The task named twice.
    pub task: Name,
}

impl fmt::Display for DuplicateMember {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "waitfor {} names task {} twice: it could never complete",
            self.barrier, self.task
        )
    }
}

impl std::error::Error for DuplicateMember {}

/// The pooled messages of one round of a `waitfor`, one per named task.
#[derive(Debug)]
pub struct Pool<M> {
    members: Arc<Members>,
    messages: Vec<M>,
}

impl<M> Pool<M> {
    /// `GETMESS(task)`: the message `task` pooled, if it is a member.
    pub fn getmess(&self, task: &str) -> Option<&M> {
        self.messages.get(self.members.place(task)?)
    }

    /// Every member with its message, in the order the rendezvous names them.
    pub fn iter(&self) -> impl Iterator<Item = (&Name, &M)> {
        self.members.names.iter().zip(&self.messages)
    }

    /// How many messages were pooled.
    pub fn len(&self) -> usize {
        self.messages.len()
    }

    /// Whether the pool is empty (a rendezvous of nobody).
    pub fn is_empty(&self) -> bool {
        self.messages.is_empty()
    }
}

/// Why a `waitfor` failed; the message comes back where it was not pooled.
#[derive(Debug, PartialEq, Eq)]
pub enum WaitForError<M> {
    /// Not every member arrived before the timeout; `missing` are those that did not.
    Timeout {
        /// The rendezvous.
        barrier: Name,
        /// The members that had not arrived.
        missing: Vec<Name>,
        /// The message, withdrawn from the pool.
        message: M,
    },
    /// The caller is not one of the named tasks.
    NotAMember {
        /// The rendezvous.
        barrier: Name,
        /// The caller.
        task: Name,
        /// The message.
        message: M,
    },
    /// The caller is already waiting in this round (two tasks under one name).
    AlreadyWaiting {
        /// The rendezvous.
        barrier: Name,
        /// The caller.
        task: Name,
        /// The message.
        message: M,
    },
}

impl<M> fmt::Display for WaitForError<M> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Timeout {
                barrier, missing, ..
            } => {
                write!(f, "waitfor {barrier} timed out waiting for")?;
                for name in missing {
                    write!(f, " {name}")?;
                }
                Ok(())
            }
            Self::NotAMember { barrier, task, .. } => {
                write!(f, "task {task} is not named in waitfor {barrier}")
            }
            Self::AlreadyWaiting { barrier, task, .. } => {
                write!(f, "task {task} is already waiting in waitfor {barrier}")
            }
        }
    }
}

impl<M: fmt::Debug> std::error::Error for WaitForError<M> {}

/// An n-way rendezvous of named tasks, pooling messages of type `M`.
pub struct WaitFor<M> {
    shared: Arc<Shared<M>>,
}

struct Shared<M> {
    name: Name,
    members: Arc<Members>,
    clock: SharedClock,
    round: Mutex<Round<M>>,
}

struct Round<M> {
    arrived: Vec<Option<M>>,
    /// How many members have arrived this round: kept, so that an arrival costs O(1).
    count: usize,
    wakers: Vec<Option<Waker>>,
    /// Where this round's pool is published when the round is released. Each member that
    /// arrives holds it, so that a member woken by the release reads its result with one
    /// load, taking no lock; the pool is freed once the round's last member has read it.
    outcome: Outcome<M>,
}

/// The pool of one round, once it is released.
type Outcome<M> = Arc<OnceLock<Pool<M>>>;

impl<M> Round<M> {
    /// Takes back the message of member `index`, which waits in this round.
    fn withdraw(&mut self, index: usize) -> M {
        self.wakers[index] = None;
        self.count -= 1;
        self.arrived[index]
            .take()
            .expect("the member's message waits")
    }
}

/// One member's arrival in a round, withdrawn if its waiter is dropped before the round is
/// released.
struct Arrival<'a, M> {
    barrier: &'a WaitFor<M>,
    index: usize,
    outcome: Outcome<M>,
    /// Cleared once the round is released or the message taken back: nothing to withdraw,
    /// and no lock to take.
    armed: bool,
}

impl<M> Drop for Arrival<'_, M> {
    fn drop(&mut self) {
        if !self.armed {
            return;
        }
        let mut round = self.barrier.lock();
        // An outcome not yet published is the current round's: released rounds publish
        // theirs under the lock.
        if self.outcome.get().is_none() && round.arrived[self.index].is_some() {
            drop(round.withdraw(self.index));
        }
    }
}

impl<M> WaitFor<M> {
    fn lock(&self) -> MutexGuard<'_, Round<M>> {
        // Every critical section leaves the round consistent before anything can panic.
        self.shared
            .round
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
    }
}

impl<M> Clone for WaitFor<M> {
    fn clone(&self) -> Self {
        Self {
            shared: Arc::clone(&self.shared),
        }
    }
}

impl<M: Send + Sync + 'static> WaitFor<M> {
    /// The rendezvous `name` of the tasks `members`, timed on `clock`. Refuses a task named
    /// twice.
    pub fn new<I, N>(
        name: impl Into<Name>,
        members: I,
        clock: SharedClock,
    ) -> Result<Self, DuplicateMember>
    where
        I: IntoIterator<Item = N>,
        N: Into<Name>,
    {
        let name = name.into();
        let members =
            Members::new(members.into_iter().map(Into::into).collect()).map_err(|task| {
                DuplicateMember {
                    barrier: name.clone(),
                    task,
                }
            })?;
        let count = members.names.len();
        Ok(Self {
            shared: Arc::new(Shared {
                name,
                members: Arc::new(members),
                clock,
                round: Mutex::new(Round {
                    arrived: (0..count).map(|_| None).collect(),
                    count: 0,
                    wakers: vec![None; count],
                    outcome: Arc::default(),
                }),
            }),
        })
    }

    /// The rendezvous' name.
    pub fn name(&self) -> &Name {
        &self.shared.name
    }

    /// The named tasks.
    pub fn members(&self) -> &[Name] {
        &self.shared.members.names
    }

    /// `waitfor`: `task` pools `message`, waits (at most `timeout`) until every member has,
    /// then runs `combine` over the pool and returns its result.
    ///
    /// The task's place among the members is found once, by name, when it arrives; woken
    /// by the round's release, it reads the pool through that round's outcome, with no
    /// lookup and no lock.
    pub async fn waitfor<R>(
        &self,
        task: &str,
        message: M,
        combine: impl FnOnce(&Pool<M>) -> R,
        timeout: Option<Duration>,
    ) -> Result<R, WaitForError<M>> {
        let shared = &self.shared;
        let Some(index) = shared.members.place(task) else {
            return Err(WaitForError::NotAMember {
                barrier: shared.name.clone(),
                task: task.into(),
                message,
            });
        };
        let mut message = Some(message);
        // Set when the task arrives, at its first poll. A waiter dropped before the round is
        // released (an outer timeout, its module killed) takes its message back, so the
        // round does not complete without it.
        let mut arrival: Option<Arrival<'_, M>> = None;
        let mut deadline = pin!(timeout.map(|timeout| shared.clock.sleep(timeout)));
        // Whether the round this task arrived in has been released: one load.
        let released = |arrival: &Option<Arrival<'_, M>>| {
            arrival
                .as_ref()
                .is_some_and(|arrival| arrival.outcome.get().is_some())
        };
        let outcome = poll_fn(|cx| {
            if released(&arrival) {
                // Woken by the release.
                return Poll::Ready(Ok(()));
            }
            let mut round = self.lock();
            match message.take() {
                Some(message) => {
                    if round.arrived[index].is_some() {
                        return Poll::Ready(Err(WaitForError::AlreadyWaiting {
                            barrier: shared.name.clone(),
                            task: task.into(),
                            message,
                        }));
                    }
                    round.arrived[index] = Some(message);
                    round.count += 1;
                    arrival = Some(Arrival {
                        barrier: self,
                        index,
                        outcome: Arc::clone(&round.outcome),
                        armed: true,
                    });
                    if round.count == round.arrived.len() {
                        // The last to arrive: the round is complete at once.
                        self.release(&mut round);
                        return Poll::Ready(Ok(()));
                    }
                }
                // Released between the load above and the lock.
                None if released(&arrival) => {
                    return Poll::Ready(Ok(()));
                }
                None => {}
            }
            match &mut round.wakers[index] {
                // Polled again by the same task: no clone (a reference count written).
                Some(waker) if waker.will_wake(cx.waker()) => {}
                slot => *slot = Some(cx.waker().clone()),
            }
            drop(round);
            let timed_out = deadline
                .as_mut()
                .as_pin_mut()
                .is_some_and(|sleep| sleep.poll(cx).is_ready());
            if !timed_out {
                return Poll::Pending;
            }
            let mut round = self.lock();
            // The last member may have come in just as the time ran out: the rendezvous wins.
            // The release is made under the lock, so this look is the last word.
            if released(&arrival) {
                return Poll::Ready(Ok(()));
            }
            let message = round.withdraw(index);
            let missing = shared
                .members
                .names
                .iter()
                .zip(&round.arrived)
                .filter(|(_, arrived)| arrived.is_none())
                .map(|(name, _)| name.clone())
                .filter(|name| name.as_str() != task)
                .collect();
            Poll::Ready(Err(WaitForError::Timeout {
                barrier: shared.name.clone(),
                missing,
                message,
            }))
        })
        .await;
        // Taken back on timeout; spent when the round was released.
        if let Some(arrival) = &mut arrival {
            arrival.armed = false;
        }
        outcome?;
        let pool = arrival
            .as_ref()
            .and_then(|arrival| arrival.outcome.get())
            .expect("a released member arrived in the round");
        Ok(combine(pool))
    }

    /// Publishes the round's pool to its members and wakes those that wait; the next round
    /// begins with a fresh outcome.
    fn release(&self, round: &mut Round<M>) {
        let messages = round
            .arrived
            .iter_mut()
            .map(|slot| slot.take().expect("every member arrived"))
            .collect();
        round.count = 0;
        let outcome = std::mem::take(&mut round.outcome);
        let published = outcome.set(Pool {
            members: Arc::clone(&self.shared.members),
            messages,
        });
        debug_assert!(published.is_ok(), "a round is released once");
        for waker in round.wakers.iter_mut().filter_map(Option::take) {
            waker.wake();
        }
    }
}

impl<M> fmt::Debug for WaitFor<M> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("WaitFor")
            .field("name", &self.shared.name)
            .field("members", &self.shared.members.names)
            .finish_non_exhaustive()
    }
}
