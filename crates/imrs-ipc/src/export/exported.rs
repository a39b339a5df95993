//! The handle of an exported port, which keeps it served while held, and the count of the
//! requests from other processes taken and not yet answered there.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::thread::JoinHandle;

use imrs_ports::Name;

/// A port exported to other processes: served while this is held, withdrawn when dropped.
pub struct Exported {
    pub(super) port: Name,
    pub(super) stop: Arc<AtomicBool>,
    pub(super) worker: Worker,
    pub(super) in_flight: Arc<InFlight>,
}

/// The requests from other processes taken and not yet answered there.
#[derive(Default)]
pub(crate) struct InFlight {
    count: AtomicUsize,
    idle: tokio::sync::Notify,
}

impl InFlight {
    pub(super) fn taken(&self) {
        self.count.fetch_add(1, Ordering::AcqRel);
    }

    pub(super) fn answered(&self) {
        if self.count.fetch_sub(1, Ordering::AcqRel) == 1 {
            self.idle.notify_waiters();
        }
    }

    /// Waits until no request is in flight.
    pub(crate) async fn settled(&self) {
        loop {
            let idle = self.idle.notified();
            if self.count.load(Ordering::Acquire) == 0 {
                return;
            }
            idle.await;
        }
    }
}

/// Who serves the port's requests: a tokio task woken by the users' notify through tokio's
/// reactor, or, where attaching a user connects a relay back to its process (a wait of its
/// own), a thread of ours.
pub(super) enum Worker {
    Task(tokio::task::JoinHandle<()>),
    Thread(Option<JoinHandle<()>>),
}

impl Exported {
    /// The port.
    pub fn port(&self) -> &Name {
        &self.port
    }

    /// Waits until every request taken from another process has been answered there. A
    /// reply usually crosses as part of the module's `reply`, but where the bridge is busy
    /// in another thread it is left to a task of the runtime: a process that ends cleanly
    /// awaits this first, so that the replies its modules gave reach their senders.
    pub async fn settled(&self) {
        self.in_flight.settled().await;
    }

    pub(crate) fn in_flight(&self) -> Arc<InFlight> {
        Arc::clone(&self.in_flight)
    }
}

impl Drop for Exported {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        match &mut self.worker {
            Worker::Task(task) => task.abort(),
            Worker::Thread(thread) => {
                if let Some(thread) = thread.take() {
                    let _ = thread.join();
                }
            }
        }
    }
}
