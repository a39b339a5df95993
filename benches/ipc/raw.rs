//! The raw iceoryx2 baseline: a request-response service and its two events, as the IMRS
//! bridges would use them, served and asked by hand; its ends waiting on the events, in a
//! thread or through tokio's reactor in a task, or spinning.

use std::time::{Duration, Instant};

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use imrs_ipc::Wire;
use tokio::io::Interest;
use tokio::io::unix::AsyncFd;

use crate::Small;

pub(super) type Svc = ipc_threadsafe::Service;

/// The suffix of a raw part whose events have one id, as the IMRS bridges' do.
pub(super) const ONE_ID: &str = "-one-id";

/// The raw part served by a task of the peer's runtime.
pub(super) const TASK_PART: &str = "task-one-id";

/// How a raw round trip's two ends wait.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Wait {
    /// On iceoryx2 events, each side notifying the other.
    Events,
    /// Looking again at once, yielding the processor between looks: nobody notifies.
    Spin,
}

type RawService<T> =
    iceoryx2::service::port_factory::request_response::PortFactory<Svc, T, (), T, ()>;
type RawEvents = iceoryx2::service::port_factory::event::PortFactory<Svc>;

/// The raw services of `part`: the request-response service and its two events, on a node
/// that must live as long as they are used.
pub(super) fn raw_services<T: Wire>(
    cell: &str,
    part: &str,
) -> (Node<Svc>, RawService<T>, RawEvents, RawEvents) {
    let node = NodeBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<Svc>()
        .expect("a node");
    let name = |what: &str| {
        ServiceName::new(&format!("raw/{cell}/{part}/{what}")).expect("a service name")
    };
    let service = node
        .service_builder(&name("messages"))
        .request_response::<T, T>()
        .open_or_create()
        .expect("the service");
    let event = |what: &str| {
        let events = node.service_builder(&name(what)).event();
        // As the IMRS bridges size theirs: one event id, which a wake-up clears, rather
        // than the default 256.
        let events = if part.ends_with(ONE_ID) {
            events.event_id_max_value(0)
        } else {
            events
        };
        events.open_or_create().expect("events")
    };
    let (requested, replied) = (event("requested"), event("replied"));
    (node, service, requested, replied)
}

/// A raw iceoryx2 server: waits on its request event (or spins), answers a copy, notifies
/// (unless the client spins too).
pub(super) fn raw_server<T: Wire>(cell: &str, part: &str, wait: Wait) {
    let (_node, service, requested, replied) = raw_services::<T>(cell, part);
    let server = service.server_builder().create().expect("a server");
    let listener = requested.listener_builder().create().expect("a listener");
    let notifier = replied.notifier_builder().create().expect("a notifier");
    loop {
        match wait {
            Wait::Events => {
                if listener.blocking_wait(|_| {}).is_err() {
                    return;
                }
            }
            Wait::Spin => std::thread::yield_now(),
        }
        while let Ok(Some(request)) = server.receive() {
            let payload = *request.payload();
            let _ = request.send_copy(payload);
            if wait == Wait::Events {
                let _ = notifier.notify();
            }
        }
    }
}

pub(super) fn raw_round_trips<T: Wire>(
    cell: &str,
    part: &str,
    rounds: usize,
    wait: Wait,
) -> Vec<Duration> {
    let (_node, service, requested, replied) = raw_services::<T>(cell, part);
    let client = service.client_builder().create().expect("a client");
    let listener = replied.listener_builder().create().expect("a listener");
    let notifier = requested.notifier_builder().create().expect("a notifier");
    let round_trip = || {
        let pending = client.send_copy(T::default()).expect("sent");
        if wait == Wait::Events {
            let _ = notifier.notify();
        }
        loop {
            if let Ok(Some(response)) = pending.receive() {
                return std::hint::black_box(*response.payload());
            }
            match wait {
                Wait::Events => {
                    let _ = listener.timed_wait(|_| {}, Duration::from_millis(50));
                }
                Wait::Spin => std::thread::yield_now(),
            }
        }
    };
    for _ in 0..rounds / 10 {
        round_trip();
    }
    (0..rounds)
        .map(|_| {
            let start = Instant::now();
            round_trip();
            start.elapsed()
        })
        .collect()
}

/// A listener's socket, as tokio's reactor names it.
pub(super) struct Socket(std::os::fd::RawFd);

impl std::os::fd::AsRawFd for Socket {
    fn as_raw_fd(&self) -> std::os::fd::RawFd {
        self.0
    }
}

/// `listener`'s wake-ups, through tokio's reactor: a task waits for them with no thread of
/// its own, as the IMRS bridges do.
pub(super) fn readiness(listener: &Listener<Svc>) -> AsyncFd<Socket> {
    // SAFETY: `native_handle` only reads the number of the listener's own socket.
    let raw = unsafe { listener.file_descriptor().native_handle() };
    // SAFETY: the socket is open for as long as `listener` lives, and each caller drops the
    // registration before the listener.
    unsafe { AsyncFd::register_with_interest(Socket(raw), Interest::READABLE) }
        .expect("registered with the reactor")
}

/// Waits in a task until `listener` is notified, and takes its notifications.
pub(super) async fn notified(socket: &AsyncFd<Socket>, listener: &Listener<Svc>) {
    let mut ready = socket.readable().await.expect("the reactor runs");
    ready.clear_ready();
    let _ = listener.try_wait(|_| {});
}

/// A raw iceoryx2 server in a tokio task, waiting on its request event through the reactor.
pub(super) async fn raw_task_server(cell: String) {
    let (_node, service, requested, replied) = raw_services::<Small>(&cell, TASK_PART);
    let server = service.server_builder().create().expect("a server");
    let listener = requested.listener_builder().create().expect("a listener");
    let notifier = replied.notifier_builder().create().expect("a notifier");
    let socket = readiness(&listener);
    loop {
        notified(&socket, &listener).await;
        while let Ok(Some(request)) = server.receive() {
            let payload = *request.payload();
            let _ = request.send_copy(payload);
            let _ = notifier.notify();
        }
    }
}
