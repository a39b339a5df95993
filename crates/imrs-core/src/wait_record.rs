//! A thread's record of the peers it waits on, written by the thread and read, rarely, by the
//! deadlock diagnosis.
//!
//! A send or a query that has to wait notes the port and the module it waits on here, and
//! clears it when it ends. Most threads wait on one port at a time: that wait takes three
//! plain stores into words no other thread writes, and its end one more, so a rendezvous
//! pays nothing it would notice; a thread that waits on several ports at once (a `join` of
//! two sends) keeps the others in a list behind a lock of its own. Nothing here is shared
//! by two modules, and nothing is cell-wide: the diagnosis reads every thread's record only
//! once a wait has lasted.

use std::cell::Cell;
use std::sync::atomic::{AtomicU32, AtomicUsize, Ordering, fence};
use std::sync::{Mutex, MutexGuard, OnceLock, PoisonError};

use imrs_ports::Name;

/// One wait, as the diagnosis reads it: names as [`Name::token`]s.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Wait {
    /// The port waited on.
    pub(crate) port: usize,
    /// The module waited on, or 0 for the port's users (an owner's post, which any user may
    /// serve).
    pub(crate) peer: usize,
    /// When the wait began, in the order of this OS thread's waits (wrapping after 2^32):
    /// which wait of a cycle closed it, on a current-thread runtime, where every wait is on
    /// one OS thread.
    pub(crate) seq: u32,
}

/// Which of a record's places a wait took, to clear it when the wait ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum WaitId {
    First,
    More(u32),
}

#[derive(Debug, Default)]
pub(crate) struct WaitRecord {
    /// The port's token while the first place holds a wait, 0 while it is free; written
    /// last on beginning (Release), so a reader that sees it sees the fields beside it.
    port: AtomicUsize,
    peer: AtomicUsize,
    seq: AtomicU32,
    /// The waits beyond the first one of a thread that waits on several ports at once:
    /// made the first time it does, so that the usual thread carries a pointer, not a list.
    more: OnceLock<Box<Mutex<Vec<Wait>>>>,
}

impl WaitRecord {
    /// Notes a wait on `port`, served by `peer` (or, `None`, by any of the port's users).
    ///
    /// Inlined into the port operation that waits: the usual wait takes the first place,
    /// three stores, and a call would cost as much again.
    #[inline]
    pub(crate) fn begin(&self, port: &Name, peer: Option<&Name>) -> WaitId {
        let wait = Wait {
            port: port.token(),
            peer: peer.map_or(0, Name::token),
            seq: next_seq(),
        };
        // Only this thread writes the first place, so a load tells whether it is free.
        if self.port.load(Ordering::Relaxed) == 0 {
            // As a seqlock's writer: the free mark (the last end's store of 0) is ordered
            // before these fields change, for a reader that fences after reading them.
            fence(Ordering::Release);
            self.peer.store(wait.peer, Ordering::Relaxed);
            self.seq.store(wait.seq, Ordering::Relaxed);
            self.port.store(wait.port, Ordering::Release);
            return WaitId::First;
        }
        self.begin_more(wait)
    }

    /// A wait beside one in progress (a `join` of two sends): into the list.
    #[cold]
    #[inline(never)]
    fn begin_more(&self, wait: Wait) -> WaitId {
        lock(self.more.get_or_init(Box::default)).push(wait);
        WaitId::More(wait.seq)
    }

    /// The wait `id` has ended.
    #[inline]
    pub(crate) fn end(&self, id: WaitId) {
        match id {
            WaitId::First => self.port.store(0, Ordering::Release),
            WaitId::More(seq) => self.end_more(seq),
        }
    }

    #[cold]
    #[inline(never)]
    fn end_more(&self, seq: u32) {
        if let Some(more) = self.more.get() {
            let mut more = lock(more);
            if let Some(at) = more.iter().position(|wait| wait.seq == seq) {
                more.remove(at);
            }
        }
    }

    /// Whether a wait is in progress.
    pub(crate) fn is_waiting(&self) -> bool {
        self.port.load(Ordering::Acquire) != 0
            || self.more.get().is_some_and(|more| !lock(more).is_empty())
    }

    /// The waits in progress, pushed onto `into`. Read from another thread: a wait that
    /// ends or begins meanwhile may be missed or seen, never seen half-written.
    pub(crate) fn live(&self, into: &mut Vec<Wait>) {
        let port = self.port.load(Ordering::Acquire);
        if port != 0 {
            let wait = Wait {
                port,
                peer: self.peer.load(Ordering::Relaxed),
                seq: self.seq.load(Ordering::Relaxed),
            };
            // Still the same wait (or one on the same port): its fields belong together.
            fence(Ordering::Acquire);
            if self.port.load(Ordering::Acquire) == port {
                into.push(wait);
            }
        }
        if let Some(more) = self.more.get() {
            into.extend(lock(more).iter().copied());
        }
    }
}

fn lock(more: &Mutex<Vec<Wait>>) -> MutexGuard<'_, Vec<Wait>> {
    // One push, one retain or one copy: never left half-done.
    more.lock().unwrap_or_else(PoisonError::into_inner)
}

thread_local! {
    /// This OS thread's next wait number: on a current-thread runtime, they order every
    /// wait of the cell.
    static NEXT_SEQ: Cell<u32> = const { Cell::new(0) };
}

/// The next wait number of this OS thread.
#[inline]
fn next_seq() -> u32 {
    NEXT_SEQ.with(|next| {
        let seq = next.get().wrapping_add(1);
        next.set(seq);
        seq
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_first_wait_takes_the_first_place_and_the_others_the_list() {
        let record = WaitRecord::default();
        let (p, q, owner) = (Name::from("P"), Name::from("Q"), Name::from("OWNER"));
        let first = record.begin(&p, Some(&owner));
        let second = record.begin(&q, None);
        assert_eq!(first, WaitId::First);
        assert!(matches!(second, WaitId::More(_)));
        let mut live = Vec::new();
        record.live(&mut live);
        assert_eq!(live.len(), 2);
        assert_eq!((live[0].port, live[0].peer), (p.token(), owner.token()));
        assert_eq!((live[1].port, live[1].peer), (q.token(), 0));
        assert!(
            live[0].seq < live[1].seq,
            "numbered in the order they began"
        );
        record.end(first);
        live.clear();
        record.live(&mut live);
        assert_eq!(
            live.iter().map(|wait| wait.port).collect::<Vec<_>>(),
            [q.token()]
        );
        record.end(second);
        live.clear();
        record.live(&mut live);
        assert!(live.is_empty());
    }

    #[test]
    fn a_reader_on_another_thread_never_sees_a_wait_half_written() {
        let record = WaitRecord::default();
        let ports: Vec<(Name, Name)> = (0..4)
            .map(|n| {
                (
                    Name::from(format!("RACED_PORT_{n}")),
                    Name::from(format!("RACED_PEER_{n}")),
                )
            })
            .collect();
        let pairs: Vec<(usize, usize)> =
            ports.iter().map(|(p, o)| (p.token(), o.token())).collect();
        std::thread::scope(|scope| {
            scope.spawn(|| {
                for round in 0..20_000 {
                    let (port, peer) = &ports[round % ports.len()];
                    let id = record.begin(port, Some(peer));
                    record.end(id);
                }
            });
            let mut live = Vec::new();
            for _ in 0..20_000 {
                live.clear();
                record.live(&mut live);
                for wait in &live {
                    assert!(pairs.contains(&(wait.port, wait.peer)), "{wait:?}");
                }
            }
        });
    }
}
