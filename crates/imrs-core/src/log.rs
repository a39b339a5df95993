//! A log of records: the most recent ones kept in memory, and every one streamed to
//! subscribers as it is made. The cell's event log and the simulation's log of measured facts
//! are both one.
//!
//! Memory is bounded: a log keeps at most its capacity of records (by default
//! [`Log::DEFAULT_CAPACITY`]) and forgets the oldest beyond it, counting them, so that a run
//! of any length fits in a fixed budget. Whatever needs every record — a report, a recorder —
//! subscribes and folds the stream as it comes.

use std::collections::VecDeque;
use std::fmt;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// What a [`Log`] keeps.
pub trait Record: Clone + Send + 'static {
    /// Passes the record to `tracing` as it is logged; by default, nothing.
    fn trace(&self) {}
}

type Sink<E> = Box<dyn FnMut(&E) + Send>;

/// Records of type `E`, in the order they were made.
pub struct Log<E> {
    inner: Mutex<Inner<E>>,
    /// Whether a record made now would be kept or seen: a capacity above 0, or a
    /// subscriber. Read without the lock, so that a log nobody reads costs its writers
    /// nothing ([`Log::is_wanted`]).
    wanted: AtomicBool,
}

struct Inner<E> {
    records: VecDeque<E>,
    capacity: usize,
    forgotten: u64,
    sinks: Vec<Sink<E>>,
}

impl<E: Record> Log<E> {
    /// How many records a log keeps unless told otherwise: the most recent 65,536.
    pub const DEFAULT_CAPACITY: usize = 1 << 16;

    /// An empty log that keeps the most recent [`Log::DEFAULT_CAPACITY`] records.
    pub fn new() -> Self {
        Self::with_capacity(Self::DEFAULT_CAPACITY)
    }

    /// An empty log that keeps the most recent `capacity` records (0: none; subscribers
    /// still see every one).
    pub fn with_capacity(capacity: usize) -> Self {
        Self {
            inner: Mutex::new(Inner {
                records: VecDeque::new(),
                capacity,
                forgotten: 0,
                sinks: Vec::new(),
            }),
            wanted: AtomicBool::new(capacity > 0),
        }
    }

    /// Whether anyone would see a record made now: the log keeps records, or someone
    /// subscribed. A writer whose record costs something to make (a clock read, a text)
    /// may skip it when not; [`Log::record`] keeps and streams whatever it is given.
    pub fn is_wanted(&self) -> bool {
        self.wanted.load(Ordering::Relaxed)
    }

    /// Keeps at most `capacity` records from now on, forgetting the oldest beyond it.
    pub fn set_capacity(&self, capacity: usize) {
        let mut inner = self.lock();
        inner.capacity = capacity;
        inner.trim();
        self.wanted
            .store(capacity > 0 || !inner.sinks.is_empty(), Ordering::Relaxed);
    }

    /// Stops keeping records in memory (subscribers still see them): `set_capacity(0)`.
    pub fn forget_events(&self) {
        self.set_capacity(0);
    }

    /// How many records were forgotten to stay within the capacity.
    pub fn forgotten(&self) -> u64 {
        self.lock().forgotten
    }

    /// Calls `sink` with every record made from now on, in order.
    pub fn subscribe(&self, sink: impl FnMut(&E) + Send + 'static) {
        self.lock().sinks.push(Box::new(sink));
        self.wanted.store(true, Ordering::Relaxed);
    }

    /// Logs `record`.
    pub fn record(&self, record: E) {
        record.trace();
        let mut inner = self.lock();
        for sink in &mut inner.sinks {
            sink(&record);
        }
        if inner.capacity > 0 {
            inner.records.push_back(record);
            inner.trim();
        } else {
            inner.forgotten += 1;
        }
    }

    /// The records kept: every one made, or, past the capacity, the most recent.
    pub fn snapshot(&self) -> Vec<E> {
        self.lock().records.iter().cloned().collect()
    }

    /// How many records are kept.
    pub fn len(&self) -> usize {
        self.lock().records.len()
    }

    /// Whether no record is kept.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn lock(&self) -> MutexGuard<'_, Inner<E>> {
        // A panicking sink leaves the log as it was before that record: still consistent.
        self.inner.lock().unwrap_or_else(PoisonError::into_inner)
    }
}

impl<E> Inner<E> {
    fn trim(&mut self) {
        while self.records.len() > self.capacity {
            self.records.pop_front();
            self.forgotten += 1;
        }
    }
}

impl<E: Record> Default for Log<E> {
    fn default() -> Self {
        Self::new()
    }
}

impl<E: Record> fmt::Debug for Log<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let inner = self.lock();
        f.debug_struct("Log")
            .field("records", &inner.records.len())
            .field("capacity", &inner.capacity)
            .field("forgotten", &inner.forgotten)
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Clone)]
    struct Tick;

    impl Record for Tick {}

    #[test]
    fn a_log_is_wanted_while_it_keeps_records_or_has_a_subscriber() {
        let log = Log::<Tick>::with_capacity(0);
        assert!(!log.is_wanted(), "keeps nothing, streams to no one");
        log.set_capacity(8);
        assert!(log.is_wanted());
        log.forget_events();
        assert!(!log.is_wanted());
        log.subscribe(|_| {});
        assert!(log.is_wanted(), "a subscriber sees every record");
        log.set_capacity(0);
        assert!(log.is_wanted(), "still streamed to its subscriber");
        assert!(Log::<Tick>::new().is_wanted(), "a new log keeps records");
    }
}
