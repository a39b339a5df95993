//! The IMRS cases, each timed in a task where a module runs: round trips on an imported
//! port, by value and built in place, and broadcasts on `SENDALL` ports to the peers that
//! listen to them.

use std::time::{Duration, Instant};

use imrs_ipc::{Imported, Remote, Wire, export, import};
use imrs_ports::{AnyUser, End, Port, PortSpec, Shared, usage};

use crate::peers::{Peer, start_peer};
use crate::{Large, Small};

/// `rounds` round trips, each timed, after a tenth as many to warm up. A macro, not an
/// async closure: the round trips run in a task, and the future of an async closure that
/// borrows the port's end is not `Send` for every lifetime, as a task needs.
macro_rules! timed {
    ($rounds:expr, $round_trip:block) => {{
        for _ in 0..$rounds / 10 {
            $round_trip
        }
        let mut times = Vec::with_capacity($rounds);
        for _ in 0..$rounds {
            let start = Instant::now();
            $round_trip
            times.push(start.elapsed());
        }
        times
    }};
}

/// Runs `round_trips` where a module runs: in a task on the runtime's workers.
pub(super) fn in_task(
    runtime: &tokio::runtime::Runtime,
    round_trips: impl Future<Output = Vec<Duration>> + Send + 'static,
) -> Vec<Duration> {
    runtime
        .block_on(runtime.spawn(round_trips))
        .expect("the round trips ran")
}

/// Broadcasts on four `SENDALL` ports of this process to their one user, a peer started for
/// them: 8 B and 64 KiB, by value and built in place; each timed to its first reply. Then
/// on two more, built in place, to two users, each in a peer of its own; each timed to its
/// last reply.
pub(super) fn broadcasts(
    runtime: &tokio::runtime::Runtime,
    cell: &str,
    rounds: usize,
) -> [Vec<Duration>; 7] {
    let cell = format!("{cell}-news");
    let remote = Remote::new(&cell).expect("a cell name");
    let _entered = runtime.enter();
    let small = Port::<Small, Small, usage::SendAll, AnyUser, 1>::new(PortSpec::new(
        "NEWS_SMALL",
        "CAMERA",
    ));
    let large = Port::<Large, Large, usage::SendAll, AnyUser, 1>::new(PortSpec::new(
        "NEWS_LARGE",
        "CAMERA",
    ));
    let loaned_small = Port::<Shared<Small>, Shared<Small>, usage::SendAll, AnyUser, 1>::new(
        PortSpec::new("NEWS_SMALL_LOANED", "CAMERA"),
    );
    let loaned_large = Port::<Shared<Large>, Shared<Large>, usage::SendAll, AnyUser, 1>::new(
        PortSpec::new("NEWS_LARGE_LOANED", "CAMERA"),
    );
    let pair = |name: &str| PortSpec::new(name, "CAMERA").user_list(["LISTENER", "LISTENER_2"]);
    let pair_small =
        Port::<Shared<Small>, Shared<Small>, usage::SendAll, AnyUser, 2>::new(pair("PAIR_SMALL"));
    let pair_large =
        Port::<Shared<Large>, Shared<Large>, usage::SendAll, AnyUser, 2>::new(pair("PAIR_LARGE"));
    let _exported = [
        export(&remote, &small),
        export(&remote, &large),
        export(&remote, &loaned_small),
        export(&remote, &loaned_large),
        export(&remote, &pair_small),
        export(&remote, &pair_large),
    ]
    .map(|exported| exported.expect("exported"));
    let mut child = start_peer(&cell, Peer::Listener("LISTENER"));
    let mut second = start_peer(&cell, Peer::Listener("LISTENER_2"));
    let times = [
        in_task(runtime, broadcast_times(small.owner().unwrap(), rounds)),
        in_task(runtime, broadcast_times(large.owner().unwrap(), rounds)),
        in_task(
            runtime,
            shared_broadcast_times(loaned_small.owner().unwrap(), 1, rounds, loaned),
        ),
        in_task(
            runtime,
            shared_broadcast_times(loaned_large.owner().unwrap(), 1, rounds, loaned),
        ),
        in_task(
            runtime,
            shared_broadcast_times(pair_small.owner().unwrap(), 2, rounds, loaned),
        ),
        in_task(
            runtime,
            shared_broadcast_times(pair_large.owner().unwrap(), 2, rounds, loaned),
        ),
        in_task(
            runtime,
            shared_broadcast_times(pair_large.owner().unwrap(), 2, rounds, on_heap),
        ),
    ];
    for child in [&mut child, &mut second] {
        let _ = child.kill();
        let _ = child.wait();
    }
    times
}

/// `rounds` broadcasts of `T::default()` to the port's users, each timed to its first reply.
async fn broadcast_times<T: Wire>(
    mut owner: End<T, T, usage::SendAll>,
    rounds: usize,
) -> Vec<Duration> {
    timed!(rounds, {
        let mut news = owner.send_all(T::default()).await.expect("an answer");
        std::hint::black_box(std::mem::take(&mut news.first));
    })
}

/// The owner's end of a `SENDALL` port of messages built in place.
type Camera<T> = End<Shared<T>, Shared<T>, usage::SendAll>;

/// A broadcast built in a loan of the port: a sample of shared memory, sent as it is.
fn loaned<T: Wire>(owner: &mut Camera<T>) -> Shared<T> {
    owner.loan().expect("a loan")
}

/// A broadcast built on the heap: the port copies it into one sample for all its users.
fn on_heap<T: Wire>(_: &mut Camera<T>) -> Shared<T> {
    Shared::new(T::default())
}

/// `rounds` broadcasts, each made by `build`, and timed to the last of the replies of its
/// `users` users.
async fn shared_broadcast_times<T: Wire>(
    mut owner: Camera<T>,
    users: usize,
    rounds: usize,
    build: fn(&mut Camera<T>) -> Shared<T>,
) -> Vec<Duration> {
    timed!(rounds, {
        let message = build(&mut owner);
        let mut news = owner.send_all(message).await.expect("an answer");
        std::hint::black_box(&*std::mem::take(&mut news.first));
        for _ in 1..users {
            let (_, reply) = news.next_reply().await.expect("every user answers");
            std::hint::black_box(&*reply);
        }
    })
}

/// Round trips of messages built in place: each loaned from the port (zeroed, in shared
/// memory), sent, and its reply read where the owner's process wrote it.
pub(super) fn loaned_round_trips<T: Wire>(
    cell: &str,
    port: &str,
    rounds: usize,
) -> impl Future<Output = Vec<Duration>> + Send + 'static {
    let (cell, port) = (cell.to_owned(), port.to_owned());
    async move { loaned_round_trips_of::<T>(&cell, &port, rounds).await }
}

async fn loaned_round_trips_of<T: Wire>(cell: &str, port: &str, rounds: usize) -> Vec<Duration> {
    let remote = Remote::new(cell).expect("a cell name");
    let imported =
        import::<Imported<Shared<T>, Shared<T>, usage::Receive>, _>(&remote, port, "ECHO", "ASKER")
            .expect("imported");
    let mut asker = imported.port().user_named("ASKER").expect("the user's end");
    timed!(rounds, {
        let message = asker.loan().expect("a loan");
        let reply = asker.send(message).await.expect("a round trip");
        std::hint::black_box(&*reply);
    })
}

pub(super) fn imrs_round_trips<T: Wire>(
    cell: &str,
    port: &str,
    rounds: usize,
) -> impl Future<Output = Vec<Duration>> + Send + 'static {
    let (cell, port) = (cell.to_owned(), port.to_owned());
    async move { imrs_round_trips_of::<T>(&cell, &port, rounds).await }
}

async fn imrs_round_trips_of<T: Wire>(cell: &str, port: &str, rounds: usize) -> Vec<Duration> {
    let remote = Remote::new(cell).expect("a cell name");
    let imported = import::<Imported<T, T, usage::Receive>, _>(&remote, port, "ECHO", "ASKER")
        .expect("imported");
    let mut asker = imported.port().user_named("ASKER").expect("the user's end");
    timed!(rounds, {
        std::hint::black_box(asker.send(T::default()).await.expect("a round trip"));
    })
}
