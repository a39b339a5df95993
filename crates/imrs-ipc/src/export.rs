//! The owner's side: a port exported to other processes. A bridge thread waits on
//! iceoryx2's request events; each request goes into the real port from the remote module's
//! own end — a send, or a query its owner's order answers — on tokio, and its reply goes
//! back through shared memory.

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;

use iceoryx2::port::notifier::Notifier;
use imrs_core::imrs_ports::{End, Name, Port, Shared, UserList, WireError, usage};

use crate::bridge::{Channel, Readiness, Side, Svc, TICK};
use crate::carry::{Active, Carry, Held};
use crate::wire::{
    CONNECT, MALFORMED, NO_REPLY, NOT_ON_USER_LIST, OK, REFUSED, ReplyMeta, SEND, TOO_MANY_USERS,
};
use crate::{IpcError, Remote, Wire};

/// A remote module's end of the real port, through which its requests go in.
pub(crate) trait Forward<Req, Rep>: Send + 'static {
    /// The request, as the module's primitive on this port; its reply, or `None`.
    fn forward(&mut self, request: Req) -> impl Future<Output = Option<Rep>> + Send + '_;
}

impl<Req: Send + 'static, Rep: Send + 'static> Forward<Req, Rep> for End<Req, Rep, usage::Send> {
    async fn forward(&mut self, request: Req) -> Option<Rep> {
        self.send(request).await.ok()
    }
}

/// A query: a remote user's to the owner of a `RESPONSE` port, or a remote owner's to the
/// one local user of a `QUERY` port, once that user has attached (the owner counts a remote
/// module attached from its connection; here the module attaches a moment later).
impl<Req: Send + 'static, Rep: Send + 'static> Forward<Req, Rep> for End<Req, Rep, usage::Query> {
    async fn forward(&mut self, request: Req) -> Option<Rep> {
        self.peer_attached().await;
        self.query(request).await.ok()
    }
}

/// Why a remote module could not be attached.
pub(crate) enum Refusal {
    /// The port's own wiring error.
    Wire(WireError),
    /// Something else failed (a relay back to the module's process).
    Failed,
}

impl From<WireError> for Refusal {
    fn from(error: WireError) -> Self {
        Self::Wire(error)
    }
}

/// A port exported to other processes: served while this is held, withdrawn when dropped.
pub struct Exported {
    port: Name,
    stop: Arc<AtomicBool>,
    serving: Serving,
    in_flight: Arc<InFlight>,
}

/// The requests from other processes taken and not yet answered there.
#[derive(Default)]
pub(crate) struct InFlight {
    count: AtomicUsize,
    idle: tokio::sync::Notify,
}

impl InFlight {
    fn taken(&self) {
        self.count.fetch_add(1, Ordering::AcqRel);
    }

    fn answered(&self) {
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
enum Serving {
    Task(tokio::task::JoinHandle<()>),
    Thread(Option<JoinHandle<()>>),
}

impl Exported {
    /// The port.
    pub fn port(&self) -> &Name {
        &self.port
    }

    /// Waits until every request taken from another process has been answered there. A
    /// reply crosses in a task of the runtime, after the module gave it: a process that ends
    /// cleanly awaits this first, so that the replies its modules gave reach their senders.
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
        match &mut self.serving {
            Serving::Task(task) => task.abort(),
            Serving::Thread(thread) => {
                if let Some(thread) = thread.take() {
                    let _ = thread.join();
                }
            }
        }
    }
}

/// Exports `port` (a port its owner receives on) to the other processes of `remote`'s
/// cell: their modules' sends arrive at its owner's `receive`. Call it within the tokio
/// runtime the cell runs on: the remote users' sends run there. Refused if another process
/// already exports the port, or if the processes disagree on its types.
pub fn export<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Req, Rep, usage::Receive, L, N>,
) -> Result<Exported, IpcError> {
    let port = port.clone();
    // The remote modules' side of each rendezvous is a task on this runtime: a TIGHT
    // port's spin would keep it off the worker the owner spins on.
    port.park_waits();
    bridge::<Req, Rep, Req, Rep, _, _>(remote, Name::from(&port), N, false, move |module: &str| {
        Ok(port.user_named(module)?)
    })
}

/// Exports `port`, a port of messages built in place ([`Shared`]), as [`export`] does a
/// port of values: a remote module's request is read where its sender built it, in shared
/// memory, with nothing copied on the way. The owner's reply, built in a loan made for the
/// request ([`Shared::loan_reply`]), crosses back the same way; one built on the heap is
/// copied once into its sample.
pub fn export_shared<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Shared<Req>, Shared<Rep>, usage::Receive, L, N>,
) -> Result<Exported, IpcError> {
    let port = port.clone();
    // The remote modules' side of each rendezvous is a task on this runtime: a TIGHT
    // port's spin would keep it off the worker the owner spins on.
    port.park_waits();
    bridge::<Req, Rep, Shared<Req>, Shared<Rep>, _, _>(
        remote,
        Name::from(&port),
        N,
        false,
        move |module: &str| Ok(port.user_named(module)?),
    )
}

/// Exports `port` (a `RESPONSE` port) to the other processes of `remote`'s cell: their
/// modules' queries wait for its owner's response handler, which runs when the owner's
/// order says, as for a query from its own process.
pub fn export_response<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Req, Rep, usage::Response, L, N>,
) -> Result<Exported, IpcError> {
    let port = port.clone();
    // The remote modules' side of each rendezvous is a task on this runtime: a TIGHT
    // port's spin would keep it off the worker the owner spins on.
    port.park_waits();
    bridge::<Req, Rep, Req, Rep, _, _>(remote, Name::from(&port), N, false, move |module: &str| {
        Ok(port.user_named(module)?)
    })
}

/// Serves port `name`'s requests from other processes: each remote module is attached by
/// `attach`, and its requests (wire type `Req`, carried in the port as `M`) go in through
/// its end.
/// Exports `port`, a `RESPONSE` port of messages built in place ([`Shared`]), as
/// [`export_response`] does a port of values: a remote module's query is read in place by
/// the owner's response handler, which runs when the owner's order says and can build its
/// answer in place too ([`Shared::loan_reply`]).
pub fn export_response_shared<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Shared<Req>, Shared<Rep>, usage::Response, L, N>,
) -> Result<Exported, IpcError> {
    let port = port.clone();
    // The remote modules' side of each rendezvous is a task on this runtime: a TIGHT
    // port's spin would keep it off the worker the owner spins on.
    port.park_waits();
    bridge::<Req, Rep, Shared<Req>, Shared<Rep>, _, _>(
        remote,
        Name::from(&port),
        N,
        false,
        move |module: &str| Ok(port.user_named(module)?),
    )
}

pub(crate) fn bridge<Req, Rep, M, R, E, A>(
    remote: &Remote,
    name: Name,
    users: usize,
    attach_blocks: bool,
    mut attach: A,
) -> Result<Exported, IpcError>
where
    Req: Wire,
    Rep: Wire,
    M: Carry<Req>,
    R: Carry<Rep>,
    E: Forward<M, R>,
    A: FnMut(&str) -> Result<E, Refusal> + Send + 'static,
{
    let runtime = tokio::runtime::Handle::try_current().map_err(|_| IpcError::Transport {
        port: name.clone(),
        detail: "export it from within the tokio runtime its cell runs on".into(),
    })?;
    let channel = Channel::<Req, Rep>::open(remote, &name, Side::Owner { users })?;
    let server =
        channel
            .service
            .server_builder()
            .create()
            .map_err(|error| IpcError::Transport {
                port: name.clone(),
                detail: format!("another process already owns it ({error:?})"),
            })?;
    let listener = channel.listener(&channel.requested)?;
    let notifier = Arc::new(Mutex::new(channel.notifier(&channel.replied)?));
    let stop = Arc::new(AtomicBool::new(false));
    let in_flight = Arc::new(InFlight::default());
    let flying = Arc::clone(&in_flight);
    if !attach_blocks {
        // A task in the runtime the owner's module runs on, woken by the users' notify, so
        // that a request reaches the module with no hand-over between threads.
        let readiness = Readiness::new(listener, &name)?;
        let task = runtime.clone().spawn(async move {
            // The channel lives as long as the task: its node keeps the services open.
            let _channel = channel;
            let mut users: Users<E> = HashMap::new();
            // Woken by a user's notify; and at each tick all the same, so that a request
            // whose notify was lost (or a peer that never sent one) waits a tick at most.
            let mut tick = tokio::time::interval(TICK);
            loop {
                // An error is a connection iceoryx2 could not make yet: the next wake-up
                // retries.
                while let Ok(Some(active)) = server.receive() {
                    take::<Req, Rep, M, R, E>(
                        active,
                        &mut attach,
                        &mut users,
                        &runtime,
                        &notifier,
                        &flying,
                    );
                }
                tokio::select! {
                    notified = readiness.notified() => {
                        if notified.is_err() {
                            return;
                        }
                    }
                    _ = tick.tick() => {}
                }
            }
        });
        return Ok(Exported {
            port: name,
            stop,
            serving: Serving::Task(task),
            in_flight,
        });
    }
    let halt = Arc::clone(&stop);
    let thread = std::thread::Builder::new()
        .name(format!("imrs-ipc {name}"))
        .spawn(move || {
            // The channel lives as long as the thread: its node keeps the services open.
            let _channel = channel;
            let mut users: Users<E> = HashMap::new();
            while !halt.load(Ordering::Acquire) {
                // Blocks until a request event or the tick: no polling of the data.
                if listener.timed_wait(|_| {}, TICK).is_err() {
                    break;
                }
                // An error is a connection iceoryx2 could not make yet: the next wake-up
                // retries.
                while let Ok(Some(active)) = server.receive() {
                    take::<Req, Rep, M, R, E>(
                        active,
                        &mut attach,
                        &mut users,
                        &runtime,
                        &notifier,
                        &flying,
                    );
                }
            }
        })
        .map_err(|error| IpcError::Transport {
            port: name.clone(),
            detail: format!("starting its bridge thread: {error}"),
        })?;
    Ok(Exported {
        port: name,
        stop,
        serving: Serving::Thread(Some(thread)),
        in_flight,
    })
}

/// The remote modules' ends, by module.
type Users<E> = HashMap<String, Arc<tokio::sync::Mutex<E>>>;

/// One request from another process.
fn take<Req: Wire, Rep: Wire, M: Carry<Req>, R: Carry<Rep>, E: Forward<M, R>>(
    active: Active<Req, Rep>,
    attach: &mut impl FnMut(&str) -> Result<E, Refusal>,
    users: &mut Users<E>,
    runtime: &tokio::runtime::Handle,
    notifier: &Arc<Mutex<Notifier<Svc>>>,
    in_flight: &Arc<InFlight>,
) {
    let meta = *active.user_header();
    let active: Held<Req, Rep> = Arc::new(Mutex::new(active));
    // A header a peer wrote garbage into is refused; the bridge goes on serving. Borrowed
    // from the header's copy: a request allocates no name.
    let Some(module) = meta.module() else {
        respond(&active, MALFORMED, 0, Rep::default(), notifier);
        return;
    };
    // A module this copy of the owner has not seen yet — the owner was restarted since the
    // module connected — is attached now, as at its connection.
    let end = match user(attach, users, module) {
        Ok(end) => end,
        Err((status, detail)) => {
            respond(&active, status, detail, Rep::default(), notifier);
            return;
        }
    };
    match meta.kind {
        CONNECT => respond(&active, OK, 0, Rep::default(), notifier),
        SEND => {
            let request = M::from_request(&active);
            let (notifier, in_flight) = (Arc::clone(notifier), Arc::clone(in_flight));
            in_flight.taken();
            // Each request waits on tokio, so that several remote modules' requests are
            // pending at once and the owner's order decides which it takes.
            runtime.spawn(async move {
                let reply = end.lock().await.forward(request).await;
                match reply {
                    Some(reply) => respond(&active, OK, 0, reply, &notifier),
                    None => respond(&active, NO_REPLY, 0, Rep::default(), &notifier),
                }
                in_flight.answered();
            });
        }
        _ => respond(&active, MALFORMED, 0, Rep::default(), notifier),
    }
}

/// The end of remote module `module`, attached at its first request; or the status of the
/// port's refusal.
fn user<E>(
    attach: &mut impl FnMut(&str) -> Result<E, Refusal>,
    users: &mut Users<E>,
    module: &str,
) -> Result<Arc<tokio::sync::Mutex<E>>, (u32, u32)> {
    if let Some(end) = users.get(module) {
        return Ok(Arc::clone(end));
    }
    match attach(module) {
        Ok(end) => {
            let end = Arc::new(tokio::sync::Mutex::new(end));
            users.insert(module.to_owned(), Arc::clone(&end));
            Ok(end)
        }
        Err(Refusal::Wire(WireError::NotOnUserList { .. })) => Err((NOT_ON_USER_LIST, 0)),
        Err(Refusal::Wire(WireError::TooManyUsers { capacity, .. })) => {
            Err((TOO_MANY_USERS, u32::try_from(capacity).unwrap_or(u32::MAX)))
        }
        Err(_) => Err((REFUSED, 0)),
    }
}

/// Replies through shared memory, then wakes the users' bridges. The request is let go
/// when the last holder drops it: here, or, for a request read in place, the module.
fn respond<Req: Wire, Rep: Wire, R: Carry<Rep>>(
    active: &Held<Req, Rep>,
    status: u32,
    detail: u32,
    reply: R,
    notifier: &Mutex<Notifier<Svc>>,
) {
    if let Some(mut response) = reply.into_reply(active) {
        *response.user_header_mut() = ReplyMeta { status, detail };
        // A user that died meanwhile cannot be answered; nothing else is lost.
        let _ = response.send();
    }
    let _ = notifier
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .notify();
}
