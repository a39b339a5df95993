//! The 8 B round trips taking turns, one round trip at a time in one task: raw iceoryx2
//! blocking its thread, raw iceoryx2 waited on in a task, and the IMRS port, by value and
//! loaned.

use std::time::{Duration, Instant};

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use imrs_ipc::{Imported, Remote, import};
use imrs_ports::{Shared, usage};

use crate::raw::{ONE_ID, Svc, TASK_PART, notified, raw_services, readiness};
use crate::{Large, Small};

/// The 8 B round trips, one of each in turn, `rounds` times in one task, so that whatever
/// else the machine does weighs on all three alike: a raw round trip whose client blocks
/// its thread on the reply event (events of one id, as the IMRS bridges size theirs); a raw
/// round trip whose client and server wait in tasks, through tokio's reactor; and an IMRS
/// port's.
pub(super) async fn alternating(cell: String, rounds: usize) -> [Vec<Duration>; 5] {
    struct Raw {
        _node: Node<Svc>,
        client: iceoryx2::port::client::Client<Svc, Small, (), Small, ()>,
        listener: Listener<Svc>,
        notifier: iceoryx2::port::notifier::Notifier<Svc>,
    }
    let raw = |part: &str| {
        let (node, service, requested, replied) = raw_services::<Small>(&cell, part);
        Raw {
            _node: node,
            client: service.client_builder().create().expect("a client"),
            listener: replied.listener_builder().create().expect("a listener"),
            notifier: requested.notifier_builder().create().expect("a notifier"),
        }
    };
    let (blocking, in_task) = (raw(&format!("small{ONE_ID}")), raw(TASK_PART));
    let socket = readiness(&in_task.listener);
    let remote = Remote::new(&cell).expect("a cell name");
    let imported =
        import::<Imported<Small, Small, usage::Receive>, _>(&remote, "SMALL", "ECHO", "ASKER")
            .expect("imported");
    let mut asker = imported.port().user_named("ASKER").expect("the user's end");
    let loaned_small = import::<Imported<Shared<Small>, Shared<Small>, usage::Receive>, _>(
        &remote,
        "SMALL_LOANED",
        "ECHO",
        "ASKER",
    )
    .expect("imported");
    let mut small_asker = loaned_small
        .port()
        .user_named("ASKER")
        .expect("the user's end");
    let loaned_large = import::<Imported<Shared<Large>, Shared<Large>, usage::Receive>, _>(
        &remote,
        "LARGE_LOANED",
        "ECHO",
        "ASKER",
    )
    .expect("imported");
    let mut large_asker = loaned_large
        .port()
        .user_named("ASKER")
        .expect("the user's end");
    let mut times: [Vec<Duration>; 5] = Default::default();
    for round in 0..rounds + rounds / 10 {
        let start = Instant::now();
        let pending = blocking.client.send_copy(Small::default()).expect("sent");
        let _ = blocking.notifier.notify();
        while !matches!(pending.receive(), Ok(Some(_))) {
            let _ = blocking
                .listener
                .timed_wait(|_| {}, Duration::from_millis(50));
        }
        let raw_blocking = start.elapsed();

        let start = Instant::now();
        let pending = in_task.client.send_copy(Small::default()).expect("sent");
        let _ = in_task.notifier.notify();
        while !matches!(pending.receive(), Ok(Some(_))) {
            notified(&socket, &in_task.listener).await;
        }
        let raw_in_task = start.elapsed();

        let start = Instant::now();
        std::hint::black_box(asker.send(Small::default()).await.expect("a round trip"));
        let imrs = start.elapsed();

        let start = Instant::now();
        let message = small_asker.loan().expect("a loan");
        std::hint::black_box(&*small_asker.send(message).await.expect("a round trip"));
        let loaned_small = start.elapsed();

        let start = Instant::now();
        let message = large_asker.loan().expect("a loan");
        std::hint::black_box(&*large_asker.send(message).await.expect("a round trip"));
        let loaned_large = start.elapsed();
        // The first tenth warms up.
        if round >= rounds / 10 {
            let round = [raw_blocking, raw_in_task, imrs, loaned_small, loaned_large];
            for (times, time) in times.iter_mut().zip(round) {
                times.push(time);
            }
        }
    }
    drop(socket);
    times
}
