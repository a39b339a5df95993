//! A log of records: kept in memory, and streamed to subscribers as it grows. The cell's
//! event log and the simulation's log of measured facts are both one.

use std::fmt;
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
}

struct Inner<E> {
    records: Vec<E>,
    forget: bool,
    sinks: Vec<Sink<E>>,
}

impl<E: Record> Log<E> {
    /// An empty log that keeps every record.
    pub fn new() -> Self {
        Self {
            inner: Mutex::new(Inner {
                records: Vec::new(),
                forget: false,
                sinks: Vec::new(),
            }),
        }
    }

    /// Stops keeping records in memory (subscribers still see them): for long runs.
    pub fn forget_events(&self) {
        let mut inner = self.lock();
        inner.forget = true;
        inner.records = Vec::new();
    }

    /// Calls `sink` with every record made from now on, in order.
    pub fn subscribe(&self, sink: impl FnMut(&E) + Send + 'static) {
        self.lock().sinks.push(Box::new(sink));
    }

    /// Logs `record`.
    pub fn record(&self, record: E) {
        record.trace();
        let mut inner = self.lock();
        for sink in &mut inner.sinks {
            sink(&record);
        }
        if !inner.forget {
            inner.records.push(record);
        }
    }

    /// Every record kept so far.
    pub fn snapshot(&self) -> Vec<E> {
        self.lock().records.clone()
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

impl<E: Record> Default for Log<E> {
    fn default() -> Self {
        Self::new()
    }
}

impl<E: Record> fmt::Debug for Log<E> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Log").field("records", &self.len()).finish()
    }
}
