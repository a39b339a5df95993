//! A station's transmit queue, as the seed's i82596 coprocessor serves it.

use std::collections::VecDeque;
use std::time::Duration;

use imrs_ports::Priority;

/// Packets waiting to go on the bus, the most urgent first (FIFO within a priority) —
/// except that the packet at the head may already be partly read into the coprocessor's
/// 64-byte FIFO, so a new packet never goes ahead of it, whatever its priority: service is
/// non-preemptive.
///
/// The bus lets a station send one packet per resolution period, so a new packet of
/// priority `p` waits at most for the packets ahead of it — the loaded head, and the
/// waiting packets at least as urgent — and then its own turn:
/// [`TransmitQueue::worst_wait`] is `(ahead + 1) · D_max`. For the most urgent message
/// that is `2 · D_max` at most, whatever else is queued.
#[derive(Debug, Clone)]
pub struct TransmitQueue<T> {
    loaded: Option<(Priority, T)>,
    waiting: VecDeque<(Priority, T)>,
}

impl<T> Default for TransmitQueue<T> {
    fn default() -> Self {
        Self {
            loaded: None,
            waiting: VecDeque::new(),
        }
    }
}

impl<T> TransmitQueue<T> {
    /// An empty queue.
    pub fn new() -> Self {
        Self::default()
    }

    /// Queues `packet`: loaded at once if nothing is, otherwise after every waiting packet
    /// at least as urgent.
    pub fn push(&mut self, priority: Priority, packet: T) {
        if self.loaded.is_none() {
            self.loaded = Some((priority, packet));
            return;
        }
        let at = self
            .waiting
            .iter()
            .position(|(queued, _)| *queued < priority)
            .unwrap_or(self.waiting.len());
        self.waiting.insert(at, (priority, packet));
    }

    /// The loaded packet goes on the wire; the most urgent waiting one is loaded next.
    pub fn transmit(&mut self) -> Option<T> {
        let (_, sent) = self.loaded.take()?;
        self.loaded = self.waiting.pop_front();
        Some(sent)
    }

    /// How many packets a new packet of `priority` would wait behind.
    pub fn ahead_of(&self, priority: Priority) -> usize {
        usize::from(self.loaded.is_some())
            + self
                .waiting
                .iter()
                .filter(|(queued, _)| *queued >= priority)
                .count()
    }

    /// The longest a new packet of `priority` waits to be on the bus, with `d_max` the
    /// bus's bound for one resolution period.
    pub fn worst_wait(&self, priority: Priority, d_max: Duration) -> Duration {
        (self.ahead_of(priority) as u32 + 1) * d_max
    }

    /// How many packets are queued, the loaded one included.
    pub fn len(&self) -> usize {
        usize::from(self.loaded.is_some()) + self.waiting.len()
    }

    /// Whether nothing is queued.
    pub fn is_empty(&self) -> bool {
        self.loaded.is_none()
    }
}
