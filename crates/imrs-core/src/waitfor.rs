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
use std::sync::{Arc, Mutex, MutexGuard, PoisonError};
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
    generation: u64,
    arrived: Vec<Option<M>>,
    /// How many members have arrived this round: kept, so that an arrival costs O(1).
    count: usize,
    wakers: Vec<Option<Waker>>,
    /// The pool of the last completed round, for members that have not picked it up yet.
    released: Option<Arc<Pool<M>>>,
}

impl<M> Round<M> {
    /// The pool of round `generation`, once that round has been released.
    fn pool_after(&self, generation: u64) -> Option<Arc<Pool<M>>> {
        (self.generation > generation).then(|| {
            self.released
                .clone()
                .expect("a released round keeps its pool")
        })
    }
}

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
    generation: u64,
    armed: bool,
}

impl<M> Drop for Arrival<'_, M> {
    fn drop(&mut self) {
        if !self.armed {
            return;
        }
        let mut round = self.barrier.lock();
        if round.generation == self.generation && round.arrived[self.index].is_some() {
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
                    generation: 0,
                    arrived: (0..count).map(|_| None).collect(),
                    count: 0,
                    wakers: vec![None; count],
                    released: None,
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
        let generation = {
            let mut round = self.lock();
            if round.arrived[index].is_some() {
                return Err(WaitForError::AlreadyWaiting {
                    barrier: shared.name.clone(),
                    task: task.into(),
                    message,
                });
            }
            round.arrived[index] = Some(message);
            round.count += 1;
            let generation = round.generation;
            if round.count == round.arrived.len() {
                self.release(&mut round);
            }
            generation
        };
        // A waiter dropped before the round is released (an outer timeout, its module
        // killed) takes its message back, so the round does not complete without it.
        let mut arrival = Arrival {
            barrier: self,
            index,
            generation,
            armed: true,
        };
        let mut deadline = pin!(timeout.map(|timeout| shared.clock.sleep(timeout)));
        let pool = poll_fn(|cx| {
            let mut round = self.lock();
            if let Some(pool) = round.pool_after(generation) {
                return Poll::Ready(Ok(pool));
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
            if let Some(pool) = round.pool_after(generation) {
                return Poll::Ready(Ok(pool));
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
        arrival.armed = false;
        let pool = pool?;
        Ok(combine(&pool))
    }

    fn release(&self, round: &mut Round<M>) {
        let messages = round
            .arrived
            .iter_mut()
            .map(|slot| slot.take().expect("every member arrived"))
            .collect();
        round.count = 0;
        round.released = Some(Arc::new(Pool {
            members: Arc::clone(&self.shared.members),
            messages,
        }));
        round.generation += 1;
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
