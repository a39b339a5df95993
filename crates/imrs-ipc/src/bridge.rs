//! What both sides of a crossing port share: the iceoryx2 node, the request-response
//! service, and the two event services that wake whoever waits (requests for the owner,
//! replies for the users) — so that nobody polls.

use std::os::fd::{AsRawFd, RawFd};
use std::task::{Context, Poll};
use std::time::Duration;

use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::{event, request_response};
use imrs_ports::Name;
use tokio::io::Interest;
use tokio::io::unix::AsyncFd;

use crate::wire::{ReplyMeta, RequestMeta};
use crate::{IpcError, Remote, Wire};

/// Ports usable from any thread: the bridges hand requests to tokio tasks.
pub(crate) type Svc = ipc_threadsafe::Service;

/// How many requests one user process may have pending at once.
pub(crate) const MAX_PENDING: usize = 16;
/// How often a waiting bridge thread looks up from its wait: to see whether it should stop
/// and whether a peer died. A wake-up, not a poll of the data: data wakes it at once.
pub(crate) const TICK: Duration = Duration::from_millis(50);

pub(crate) type Service<Req, Rep> =
    request_response::PortFactory<Svc, Req, RequestMeta, Rep, ReplyMeta>;

/// A listener whose wake-ups reach a waker through tokio's reactor: its socket is
/// registered there, so that the other process's notify wakes the bridge directly, with no
/// thread of ours between.
pub(crate) struct Readiness {
    // Declared first, so dropped first: deregistered before the listener closes its socket.
    socket: AsyncFd<Socket>,
    listener: Listener<Svc>,
}

/// A listener's socket, as tokio's reactor names it.
struct Socket(RawFd);

impl AsRawFd for Socket {
    fn as_raw_fd(&self) -> RawFd {
        self.0
    }
}

impl Readiness {
    /// Watches `listener`'s notifications. Call it within a tokio runtime whose I/O driver
    /// is enabled (`enable_io` or `enable_all`); refused, naming the port, otherwise.
    pub(crate) fn new(listener: Listener<Svc>, port: &Name) -> Result<Self, IpcError> {
        // SAFETY: `native_handle` only reads the number of the listener's own socket.
        let raw = unsafe { listener.file_descriptor().native_handle() };
        // tokio panics where the runtime has no I/O driver: a mistake of the caller's set-up,
        // told as an error rather than a crash.
        let registered = std::panic::catch_unwind(|| {
            // SAFETY: the descriptor is the listener's socket, open for as long as the
            // listener lives, and `Socket` always returns that same number. `Readiness` owns
            // the listener and drops the registration first (field order), so the
            // registration never outlives the socket.
            unsafe { AsyncFd::register_with_interest(Socket(raw), Interest::READABLE) }
        });
        let socket = match registered {
            Ok(Ok(socket)) => socket,
            Ok(Err(error)) => return Err(transport(port, "watching its events", error)),
            Err(_) => {
                return Err(transport(
                    port,
                    "watching its events",
                    "the tokio runtime has no I/O driver: build it with enable_io or enable_all",
                ));
            }
        };
        Ok(Self { socket, listener })
    }

    /// Takes the other side's notifications, and registers `cx`'s waker to be woken when
    /// it next notifies: whether it had notified since the last call. `Err` if the reactor
    /// is gone.
    ///
    /// The notifications are taken at every call, not only when the socket was readable:
    /// iceoryx2's notifier sends no datagram while its listener is marked notified, and it
    /// marks it so only after sending. A take that falls between the two reads the datagram
    /// (the reactor, which looks at the socket later, then sees nothing to report) and
    /// leaves the mark set: from then on every notify is silent, until the listener takes
    /// again. Taken only on readiness, that never came, and each reply waited for the
    /// bridge's sweep.
    pub(crate) fn drain(&self, cx: &mut Context<'_>) -> std::io::Result<bool> {
        // Cleared before the notifications are taken: one that comes after is a new edge,
        // which wakes the waker again.
        while let Poll::Ready(ready) = self.socket.poll_read_ready(cx) {
            ready?.clear_ready();
        }
        Ok(self
            .listener
            .try_wait(|_| {})
            .is_ok_and(|notifications| notifications > 0))
    }
}

/// Which side of a port opens its services.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Side {
    /// The owner's process, which creates the services (or opens them again after a
    /// restart), sized for the port's number of users.
    Owner {
        /// How many users the port admits.
        users: usize,
    },
    /// A user's process, which opens the services the owner created.
    User,
}

/// The iceoryx2 side of one port, created by its owner's process and opened by its users'.
pub(crate) struct Channel<Req: Wire, Rep: Wire> {
    pub(crate) port: Name,
    /// Keeps the services open while the port crosses.
    _node: Node<Svc>,
    pub(crate) service: Service<Req, Rep>,
    pub(crate) requested: event::PortFactory<Svc>,
    pub(crate) replied: event::PortFactory<Svc>,
}

pub(crate) fn transport(port: &Name, what: &str, error: impl std::fmt::Debug) -> IpcError {
    IpcError::Transport {
        port: port.clone(),
        detail: format!("{what}: {error:?}"),
    }
}

/// A node of this process for port `port`'s services.
/// Whether some process serves the service of `port`, a name given as text (from a peer):
/// checked before the name is made, so that a claim whose relay cannot be connected leaves
/// no name behind.
pub(crate) fn is_served(remote: &Remote, port: &str) -> bool {
    remote.service(port, "messages").is_ok_and(|name| {
        <Svc as iceoryx2::service::Service>::does_exist(
            &name,
            iceoryx2::config::Config::global_config(),
            MessagingPattern::RequestResponse,
        )
        .unwrap_or(false)
    })
}

pub(crate) fn node(port: &Name) -> Result<Node<Svc>, IpcError> {
    // Defaults need no configuration file; iceoryx2 says so at every start unless told to
    // keep its warnings for what matters (`IOX2_LOG_LEVEL` still overrides).
    static QUIET: std::sync::Once = std::sync::Once::new();
    QUIET.call_once(|| set_log_level_from_env_or(LogLevel::Error));
    // The framework's own processes decide when to stop: no signal handlers.
    NodeBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<Svc>()
        .map_err(|error| transport(port, "creating the node", error))
}

/// Why a user's process could not open port `port`'s service: no owner created it, the
/// two processes disagree on its types, or iceoryx2 failed.
pub(crate) fn refusal(port: &Name, error: &dyn std::fmt::Debug) -> IpcError {
    let detail = format!("{error:?}");
    if detail.contains("DoesNotExist") {
        IpcError::NoOwner { port: port.clone() }
    } else if detail.contains("Incompatible") || detail.contains("TypeDefinition") {
        IpcError::TypeMismatch {
            port: port.clone(),
            detail,
        }
    } else {
        transport(port, "opening its service", detail)
    }
}

impl<Req: Wire, Rep: Wire> Channel<Req, Rep> {
    /// Opens port `port` of `remote` from `side`: the owner creates its services, sized
    /// from the port's restrictions rather than iceoryx2's defaults; a user opens them, and
    /// is told there is no owner if they are not there.
    pub(crate) fn open(remote: &Remote, port: &Name, side: Side) -> Result<Self, IpcError> {
        let node = node(port)?;
        let refused = |error: &dyn std::fmt::Debug| refusal(port, error);
        let messages = node
            .service_builder(&remote.service(port.as_str(), "messages")?)
            .request_response::<Req, Rep>()
            .request_user_header::<RequestMeta>()
            .response_user_header::<ReplyMeta>();
        let service = match side {
            // One client more than the port has users: a process beyond them connects,
            // and is refused by name with the port's own error rather than by iceoryx2.
            Side::Owner { users } => messages
                .max_servers(1)
                .max_clients(users + 1)
                .max_nodes(users + 2)
                .max_active_requests_per_client(MAX_PENDING)
                .max_loaned_requests(MAX_PENDING)
                .max_response_buffer_size(2)
                .open_or_create()
                .map_err(|error| refused(&error))?,
            Side::User => messages.open().map_err(|error| refused(&error))?,
        };
        let event = |part: &str| {
            let events = node
                .service_builder(&remote.service(port.as_str(), part)?)
                .event();
            match side {
                // The events only wake: one event id. A listener clears, at every wake-up,
                // each id the service allows, an atomic swap apiece: with iceoryx2's
                // default of 256 ids that took about 0.65 µs of a wake-up's 2.6 µs.
                Side::Owner { users } => events
                    .event_id_max_value(0)
                    .max_notifiers(users + 3)
                    .max_listeners(users + 3)
                    .max_nodes(users + 2)
                    .open_or_create()
                    .map_err(|error| transport(port, "opening its events", error)),
                Side::User => events.open().map_err(|error| refused(&error)),
            }
        };
        let (requested, replied) = (event("requested")?, event("replied")?);
        Ok(Self {
            port: port.clone(),
            _node: node,
            service,
            requested,
            replied,
        })
    }

    pub(crate) fn listener(
        &self,
        events: &event::PortFactory<Svc>,
    ) -> Result<Listener<Svc>, IpcError> {
        events
            .listener_builder()
            .create()
            .map_err(|error| transport(&self.port, "listening", error))
    }

    pub(crate) fn notifier(
        &self,
        events: &event::PortFactory<Svc>,
    ) -> Result<Notifier<Svc>, IpcError> {
        events
            .notifier_builder()
            .create()
            .map_err(|error| transport(&self.port, "notifying", error))
    }
}

#[cfg(test)]
mod tests {
    use std::mem::ManuallyDrop;
    use std::os::fd::FromRawFd;
    use std::os::unix::net::UnixDatagram;

    use super::*;

    /// Takes one datagram from the listener's socket behind iceoryx2's back: whether there
    /// was one.
    fn take_datagram(socket: RawFd) -> bool {
        // SAFETY: the descriptor is the listener's socket, open while the test holds the
        // listener; `ManuallyDrop` keeps this borrowed view from closing it.
        let socket = ManuallyDrop::new(unsafe { UnixDatagram::from_raw_fd(socket) });
        socket.set_nonblocking(true).expect("a socket");
        socket.recv(&mut [0; 64]).is_ok()
    }

    /// The race's outcome made by hand: a notify's datagram read before the notifier marked
    /// the listener notified. The mark stays, the socket is empty, and every notify after
    /// sends nothing; a drain that took notifications only on readiness never heard again.
    #[tokio::test(flavor = "current_thread")]
    async fn a_listener_left_marked_with_an_empty_socket_is_heard_again_after_a_drain() {
        let node = NodeBuilder::new().create::<Svc>().unwrap();
        let name = ServiceName::new(&imrs_testkit::unique_name("drain")).unwrap();
        let events = node
            .service_builder(&name)
            .event()
            .event_id_max_value(0)
            .open_or_create()
            .unwrap();
        let notifier = events.notifier_builder().create().unwrap();
        let listener = events.listener_builder().create().unwrap();
        let readiness = Readiness::new(listener, &Name::from("DRAIN")).unwrap();
        let socket = readiness.socket.get_ref().0;

        notifier.notify().unwrap();
        assert!(take_datagram(socket), "a notify sends a datagram");
        notifier.notify().unwrap();
        assert!(
            !take_datagram(socket),
            "a listener marked notified gets no datagram"
        );

        let mut cx = Context::from_waker(std::task::Waker::noop());
        assert!(
            readiness.drain(&mut cx).unwrap(),
            "the drain did not take the notifications waiting"
        );
        notifier.notify().unwrap();
        assert!(
            take_datagram(socket),
            "after the drain a notify wakes the listener again"
        );
    }
}
