//! A TCP relay of our own between two hosts, which delays, stalls and partitions the link:
//! `tc netem` is not in these kernels. Loss on a TCP link shows to the hosts as stalls
//! (the kernel sends the segment again), so the relay models it as a chunk held back.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;

use tokio::io::{AsyncReadExt, AsyncWriteExt};
use tokio::net::{TcpListener, TcpStream};

/// How the relay treats what crosses it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Impairment {
    /// Added to every chunk, each way.
    pub(crate) delay: Duration,
    /// One chunk in this many is held back a further `stall` (0: none).
    pub(crate) stall_one_in: u64,
    /// How long a stalled chunk is held back.
    pub(crate) stall: Duration,
}

/// A relay listening on loopback, forwarding to a target endpoint.
pub(crate) struct Relay {
    /// Where hosts connect to reach the target: `tcp/127.0.0.1:<port>`.
    pub(crate) endpoint: String,
    cut: Arc<AtomicBool>,
    task: tokio::task::JoinHandle<()>,
}

impl Relay {
    /// A relay to `target` (`127.0.0.1:<port>`), impaired as `impairment` says.
    pub(crate) async fn start(target: String, impairment: Impairment) -> Self {
        let listener = TcpListener::bind("127.0.0.1:0").await.unwrap();
        let endpoint = format!("tcp/{}", listener.local_addr().unwrap());
        let cut = Arc::new(AtomicBool::new(false));
        let counter = Arc::new(AtomicU64::new(0));
        let task = {
            let cut = Arc::clone(&cut);
            tokio::spawn(async move {
                while let Ok((inbound, _)) = listener.accept().await {
                    let (cut, counter, target) =
                        (Arc::clone(&cut), Arc::clone(&counter), target.clone());
                    tokio::spawn(async move {
                        // While cut, a new connection is held open and carries nothing.
                        while cut.load(Ordering::SeqCst) {
                            tokio::time::sleep(Duration::from_millis(20)).await;
                        }
                        let Ok(outbound) = TcpStream::connect(&target).await else {
                            return;
                        };
                        let (in_read, in_write) = inbound.into_split();
                        let (out_read, out_write) = outbound.into_split();
                        let there = pump(in_read, out_write, &cut, &counter, impairment);
                        let back = pump(out_read, in_write, &cut, &counter, impairment);
                        tokio::join!(there, back);
                    });
                }
            })
        };
        Self {
            endpoint,
            cut,
            task,
        }
    }

    /// Partitions the link: nothing crosses, nothing is closed, until [`Relay::heal`].
    pub(crate) fn partition(&self) {
        self.cut.store(true, Ordering::SeqCst);
    }

    /// Heals a partition: new connections carry again (those open meanwhile stay stuck,
    /// as a peer whose lease ran out has closed them).
    pub(crate) fn heal(&self) {
        self.cut.store(false, Ordering::SeqCst);
    }
}

impl Drop for Relay {
    fn drop(&mut self) {
        self.task.abort();
    }
}

/// Copies `from` to `to`, chunk by chunk, impaired; stops for good at a partition.
async fn pump(
    mut from: tokio::net::tcp::OwnedReadHalf,
    mut to: tokio::net::tcp::OwnedWriteHalf,
    cut: &AtomicBool,
    counter: &AtomicU64,
    impairment: Impairment,
) {
    let mut buffer = vec![0; 64 * 1024];
    loop {
        let Ok(read) = from.read(&mut buffer).await else {
            return;
        };
        if read == 0 || cut.load(Ordering::SeqCst) {
            // Partitioned: hold the connection, carry nothing more.
            while read != 0 && cut.load(Ordering::SeqCst) {
                tokio::time::sleep(Duration::from_millis(20)).await;
            }
            return;
        }
        tokio::time::sleep(impairment.delay).await;
        let n = counter.fetch_add(1, Ordering::Relaxed);
        if impairment.stall_one_in > 0 && n % impairment.stall_one_in == impairment.stall_one_in - 1
        {
            tokio::time::sleep(impairment.stall).await;
        }
        if to.write_all(&buffer[..read]).await.is_err() {
            return;
        }
    }
}
