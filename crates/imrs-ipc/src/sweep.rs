//! Looking for dead processes: what they left behind is removed, so that the living see
//! them gone.
//!
//! Looking at every node of the host takes milliseconds (8–17 ms a sweep in a debug build
//! of the chip cell across processes), and each imported port with requests waiting looks
//! twice a second. Run on a worker of the runtime, a sweep held the modules' tasks up for
//! as long, and a cell on a sped-up wall clock lives that as a stall: its processes' timers
//! woke 13–19 ms late at worst, against 4–11 ms with the sweeps off the workers. So a sweep
//! runs on tokio's blocking threads, one at a time in a process, and every bridge that asks
//! while one runs is served by the next.

use std::time::Instant;

use iceoryx2::prelude::*;

use crate::bridge::Svc;

/// This process's sweeps.
static SWEEPS: Sweeps = Sweeps::new();

/// Removes what dead processes left behind: their nodes, and their ports' places in the
/// services; returns once a sweep that began after the call has ended.
pub(crate) async fn sweep_dead() {
    SWEEPS.sweep(sweep_now).await;
}

fn sweep_now() {
    let _ = Node::<Svc>::list(Config::global_config(), |state| {
        if let NodeState::Dead(view) = state {
            let _ = view.try_remove_stale_resources();
        }
        CallbackProgression::Continue
    });
}

/// Sweeps one at a time: when the last began, held while one runs.
struct Sweeps {
    last: tokio::sync::Mutex<Option<Instant>>,
}

impl Sweeps {
    const fn new() -> Self {
        Self {
            last: tokio::sync::Mutex::const_new(None),
        }
    }

    /// Runs `sweep` on tokio's blocking threads, unless a sweep that began after this call
    /// has ended meanwhile (it saw what this one would see); returns once one has.
    async fn sweep(&self, sweep: impl FnOnce() + Send + 'static) {
        let asked = Instant::now();
        let mut last = self.last.lock().await;
        if last.is_some_and(|began| began >= asked) {
            return;
        }
        *last = Some(Instant::now());
        // A sweep that could not run (the runtime is ending) removed nothing; the next one
        // tries again.
        let _ = tokio::task::spawn_blocking(sweep).await;
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;
    use std::sync::atomic::{AtomicU32, Ordering};
    use std::sync::mpsc::{Receiver, channel};
    use std::time::Duration;

    use tokio::sync::oneshot;

    use super::*;

    /// A sweep that counts itself, says it `started`, and waits (up to 5 s) for `go`:
    /// whether it got it.
    fn held_sweep(
        runs: &Arc<AtomicU32>,
        started: oneshot::Sender<()>,
        go: Receiver<()>,
    ) -> impl FnOnce() -> bool + Send + 'static {
        let runs = Arc::clone(runs);
        move || {
            runs.fetch_add(1, Ordering::SeqCst);
            let _ = started.send(());
            go.recv_timeout(Duration::from_secs(5)).is_ok()
        }
    }

    #[tokio::test(flavor = "current_thread")]
    async fn a_sweep_frees_the_runtimes_thread_and_serves_all_who_asked_meanwhile() {
        let sweeps = Arc::new(Sweeps::new());
        let runs = Arc::new(AtomicU32::new(0));
        let (go, held) = channel();
        let (got_go, said) = channel();
        let (started, has_started) = oneshot::channel();
        let first = held_sweep(&runs, started, held);
        let running = tokio::spawn({
            let sweeps = Arc::clone(&sweeps);
            async move { sweeps.sweep(move || got_go.send(first()).unwrap()).await }
        });
        // The first sweep runs, and waits for `go`, which only a task of this runtime's one
        // thread sends: a sweep on this thread would wait the 5 s out, and fail below.
        has_started.await.unwrap();
        // Two more bridges ask while it runs.
        let later: Vec<_> = (0..2)
            .map(|_| {
                let (sweeps, runs) = (Arc::clone(&sweeps), Arc::clone(&runs));
                tokio::spawn(async move {
                    sweeps
                        .sweep(move || {
                            runs.fetch_add(1, Ordering::SeqCst);
                        })
                        .await
                })
            })
            .collect();
        tokio::task::yield_now().await;
        // (Gone if the sweep gave up on it.)
        let _ = go.send(());
        running.await.unwrap();
        assert!(said.recv().unwrap(), "the sweep held the runtime's thread");
        for asked in later {
            asked.await.unwrap();
        }
        // The first began before they asked, so it cannot serve them; one more sweep,
        // begun after both asked, serves both.
        assert_eq!(runs.load(Ordering::SeqCst), 2);
        // And a bridge that asks now gets a sweep of its own.
        let runs_now = Arc::clone(&runs);
        sweeps
            .sweep(move || {
                runs_now.fetch_add(1, Ordering::SeqCst);
            })
            .await;
        assert_eq!(runs.load(Ordering::SeqCst), 3);
    }
}
