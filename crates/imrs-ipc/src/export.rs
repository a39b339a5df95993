//! The owner's side: a port exported to other processes. The bridge, woken by iceoryx2's
//! request events, takes each request into the real port from the remote module's own end
//! — a send, or a query its owner's order answers — and, woken again when the reply comes,
//! sends it back through shared memory. It does so where it is woken ([`crate::dispatch`]):
//! in the reactor's thread as the request comes, in the module's as it answers. On a TIGHT
//! port the owner's spinning receive does the same in its turns.

use imrs_ports::transport::{EndTransport as _, PortTransport as _};
use std::collections::HashMap;
use std::marker::PhantomData;
use std::pin::Pin;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, Weak};
use std::task::{Context, Poll, Wake, Waker};
use std::thread::JoinHandle;

use iceoryx2::port::notifier::Notifier;
use imrs_ports::usage::{Plain, Usage};
use imrs_ports::{ClaimRefused, End, Name, Port, ProcessType, Shared, UserList, WireError, usage};

use crate::bridge::{Channel, Readiness, Side, Svc, TICK};
use crate::carry::{Active, Carry, Held, Server, lock};
use crate::dispatch::{Dispatch, Work};
use crate::turn::{Quiet, Turn, Turns};
use crate::wire::{
    CONNECT, MALFORMED, NO_REPLY, NOT_ON_USER_LIST, OK, REFUSED, ReplyMeta, SEND, TIGHT,
    TOO_MANY_NAMES, TOO_MANY_USERS,
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
    /// The module is not on the port's user list (its name, not kept).
    NotOnUserList,
    /// Every user place of the port is taken.
    Full {
        /// The port's number of users.
        capacity: usize,
    },
    /// The module's name would be one more than the process keeps from peers
    /// ([`Name::MOST_FROM_PEERS`]).
    TooManyNames,
    /// Something else failed (a relay back to the module's process).
    Failed,
}

impl From<ClaimRefused> for Refusal {
    fn from(refused: ClaimRefused) -> Self {
        match refused {
            ClaimRefused::NotOnUserList { .. } => Self::NotOnUserList,
            ClaimRefused::Full { capacity, .. } => Self::Full { capacity },
            ClaimRefused::TooManyNames { .. } => Self::TooManyNames,
        }
    }
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
    worker: Worker,
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
enum Worker {
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

/// Exports `port` (a port its owner receives on) to the other processes of `remote`'s
/// cell: their modules' sends arrive at its owner's `receive`. Call it within the tokio
/// runtime the cell runs on: the remote users' sends run there. Refused if another process
/// already exports the port, or if the processes disagree on its types.
pub(crate) fn export<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Req, Rep, usage::Receive, L, N>,
) -> Result<Exported, IpcError> {
    export_port::<Req, Rep, _, _, _, _, N>(remote, port)
}

/// Exports `port`, a port of messages built in place ([`Shared`]), as [`export`] does a
/// port of values: a remote module's request is read where its sender built it, in shared
/// memory, with nothing copied on the way. The owner's reply, built in a loan made for the
/// request ([`Shared::loan_reply`]), crosses back the same way; one built on the heap is
/// copied once into its sample.
pub(crate) fn export_shared<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Shared<Req>, Shared<Rep>, usage::Receive, L, N>,
) -> Result<Exported, IpcError> {
    export_port::<Req, Rep, _, _, _, _, N>(remote, port)
}

/// Exports `port` (a `RESPONSE` port) to the other processes of `remote`'s cell: their
/// modules' queries wait for its owner's response handler, which runs when the owner's
/// order says, as for a query from its own process.
pub(crate) fn export_response<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Req, Rep, usage::Response, L, N>,
) -> Result<Exported, IpcError> {
    export_port::<Req, Rep, _, _, _, _, N>(remote, port)
}

/// Exports `port`, a `RESPONSE` port of messages built in place ([`Shared`]), as
/// [`export_response`] does a port of values: a remote module's query is read in place by
/// the owner's response handler, which runs when the owner's order says and can build its
/// answer in place too ([`Shared::loan_reply`]).
pub(crate) fn export_response_shared<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Shared<Req>, Shared<Rep>, usage::Response, L, N>,
) -> Result<Exported, IpcError> {
    export_port::<Req, Rep, _, _, _, _, N>(remote, port)
}

/// Exports `port`, whose remote users' requests (wire type `Req`, carried in the port as
/// `M`) go in through each remote module's own end. On a TIGHT port the owner's spinning
/// waits also do the bridge's work, in the owner's thread.
fn export_port<Req, Rep, M, R, U, L, const N: usize>(
    remote: &Remote,
    port: &Port<M, R, U, L, N>,
) -> Result<Exported, IpcError>
where
    Req: Wire,
    Rep: Wire,
    M: Carry<Req>,
    R: Carry<Rep>,
    U: Usage,
    U::Complement: Plain,
    L: UserList,
    End<M, R, U::Complement>: Forward<M, R>,
{
    let tight = port.process_type() == ProcessType::Tight;
    let attached = port.clone();
    let (exported, side) = bridge::<Req, Rep, M, R, _, _>(
        remote,
        Name::from(port),
        N,
        false,
        tight,
        move |module: &str| {
            // Refused by its name's text before the name is made: see `Port::claim`.
            let module = attached.claim(module)?;
            // The remote module's end waits in the bridge's task, which a spinning wait
            // would keep off its worker: it parks, whatever the port's process type.
            let mut end = attached.user_named(module)?;
            end.park_waits();
            Ok(end)
        },
    )?;
    if tight {
        port.pump_with(Turn(side));
    }
    Ok(exported)
}

/// Serves port `name`'s requests from other processes: each remote module is attached by
/// `attach`, and its requests (wire type `Req`, carried in the port as `M`) go in through
/// its end. `tight`: the port is TIGHT, which its users' processes are told when they
/// connect. Also gives the bridge's side, for a spinning owner's turns.
pub(crate) fn bridge<Req, Rep, M, R, E, A>(
    remote: &Remote,
    name: Name,
    users: usize,
    attach_blocks: bool,
    tight: bool,
    attach: A,
) -> Result<(Exported, Weak<Mutex<dyn Turns>>), IpcError>
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
    // A bridge thread waits on the listener itself. A task is woken through the reactor,
    // and on a port that parks its work is done where the wake-up comes: in the reactor's
    // thread when a user notifies, in the module's when it answers.
    let (waits, readiness) = if attach_blocks {
        (Some(listener), None)
    } else {
        (None, Some(Readiness::new(listener, &name)?))
    };
    let dispatch = Dispatch::new(!tight && !attach_blocks);
    let notifier = Arc::new(Mutex::new(channel.notifier(&channel.replied)?));
    let stop = Arc::new(AtomicBool::new(false));
    let in_flight = Arc::new(InFlight::default());
    let woken = Arc::new(Woken {
        flag: AtomicBool::new(false),
        dispatch: Arc::clone(&dispatch),
    });
    let side = Arc::new(Mutex::new(Serving {
        server,
        attach,
        users: HashMap::new(),
        flights: Vec::new(),
        // A bridge thread cannot poll the requests in flight: each is a task of its own.
        spawn_on: attach_blocks.then(|| runtime.clone()),
        notifier,
        in_flight: Arc::clone(&in_flight),
        waker: Waker::from(Arc::clone(&woken)),
        woken,
        readiness,
        dispatch: Waker::from(Arc::clone(&dispatch)),
        closed: false,
        answered: Vec::new(),
        quiet: Quiet::default(),
        tight,
        _carried: PhantomData,
    }));
    dispatch.serve(Arc::downgrade(&side) as Weak<Mutex<dyn Work>>);
    let weak = Arc::downgrade(&side) as Weak<Mutex<dyn Turns>>;
    let Some(listener) = waits else {
        let task = runtime.spawn(async move {
            // The channel lives as long as the task: its node keeps the services open.
            let _channel = channel;
            // Woken where a wake-up could not be served where it came; and at each tick all
            // the same, so that a request whose notify was lost (or a peer that never sent
            // one) waits a tick at most.
            let mut tick = tokio::time::interval(TICK);
            loop {
                if !lock(&side).work(true) {
                    return;
                }
                tokio::select! {
                    () = dispatch.woken() => {}
                    _ = tick.tick() => {}
                }
            }
        });
        return Ok((
            Exported {
                port: name,
                stop,
                worker: Worker::Task(task),
                in_flight,
            },
            weak,
        ));
    };
    let halt = Arc::clone(&stop);
    let thread = std::thread::Builder::new()
        .name(format!("imrs-ipc {name}"))
        .spawn(move || {
            // The channel lives as long as the thread: its node keeps the services open.
            let _channel = channel;
            while !halt.load(Ordering::Acquire) {
                // Blocks until a request event or the tick: no polling of the data.
                if listener.timed_wait(|_| {}, TICK).is_err() {
                    break;
                }
                let _open = lock(&side).work(true);
            }
        })
        .map_err(|error| IpcError::Transport {
            port: name.clone(),
            detail: format!("starting its bridge thread: {error}"),
        })?;
    Ok((
        Exported {
            port: name,
            stop,
            worker: Worker::Thread(Some(thread)),
            in_flight,
        },
        weak,
    ))
}

/// The remote modules' ends, by module.
type Users<E> = HashMap<String, Arc<tokio::sync::Mutex<E>>>;

/// A request gone into the real port through its module's end: it ends with the request
/// answered in shared memory, the other process not yet woken. It answers where the reply
/// comes out, so that a large reply is not moved on.
type Flight<Req, Rep> = Pin<Box<dyn Future<Output = Held<Req, Rep>> + Send>>;

/// Wakes the bridge when a reply comes for a request in flight.
struct Woken {
    flag: AtomicBool,
    dispatch: Arc<Dispatch>,
}

impl Wake for Woken {
    fn wake(self: Arc<Self>) {
        self.wake_by_ref();
    }

    fn wake_by_ref(self: &Arc<Self>) {
        self.flag.store(true, Ordering::Release);
        self.dispatch.wake_by_ref();
    }
}

/// A port's bridge in its owner's process: the server that takes the remote modules'
/// requests from shared memory, their ends of the real port, and the requests gone in
/// through them and waiting for their replies.
struct Serving<Req: Wire, Rep: Wire, M, R, E, A> {
    server: Server<Req, Rep>,
    attach: A,
    users: Users<E>,
    flights: Vec<Flight<Req, Rep>>,
    /// Where each flight is spawned as a task of its own, for a bridge that is a thread.
    spawn_on: Option<tokio::runtime::Handle>,
    notifier: Arc<Mutex<Notifier<Svc>>>,
    in_flight: Arc<InFlight>,
    /// The flights' waker, which wakes the bridge.
    waker: Waker,
    woken: Arc<Woken>,
    /// The users' notifications, for a bridge that is a task.
    readiness: Option<Readiness>,
    /// The waker their notifications wake.
    dispatch: Waker,
    /// Whether the reactor is gone, and with it the users' notifications.
    closed: bool,
    /// Requests answered by a spinning owner's turn, whose users' processes were not woken.
    answered: Vec<Held<Req, Rep>>,
    quiet: Quiet,
    tight: bool,
    _carried: PhantomData<fn(M, R)>,
}

impl<Req, Rep, M, R, E, A> Serving<Req, Rep, M, R, E, A>
where
    Req: Wire,
    Rep: Wire,
    M: Carry<Req>,
    R: Carry<Rep>,
    E: Forward<M, R>,
    A: FnMut(&str) -> Result<E, Refusal> + Send + 'static,
{
    /// Takes the requests that came (if `take`), and answers those whose replies came;
    /// wakes the users' processes, or, from a spinning owner's turn (`wake` false), holds
    /// the wake-ups back.
    fn serve(&mut self, wake: bool, take: bool) {
        let mut came = false;
        // An error is a connection iceoryx2 could not make yet: the next wake-up retries.
        while take && let Ok(Some(active)) = self.server.receive() {
            let Some(flight) = self.take(active) else {
                continue;
            };
            match &self.spawn_on {
                Some(runtime) => {
                    let (notifier, in_flight) =
                        (Arc::clone(&self.notifier), Arc::clone(&self.in_flight));
                    runtime.spawn(async move {
                        let _answered = flight.await;
                        notify(&notifier);
                        in_flight.answered();
                    });
                }
                None => {
                    self.flights.push(flight);
                    came = true;
                }
            }
        }
        // A new flight goes in at its first poll; the others move when their replies come.
        if !(came || self.woken.flag.swap(false, Ordering::AcqRel)) {
            return;
        }
        let mut cx = Context::from_waker(&self.waker);
        let mut at = 0;
        while at < self.flights.len() {
            let Poll::Ready(active) = self.flights[at].as_mut().poll(&mut cx) else {
                at += 1;
                continue;
            };
            drop(self.flights.swap_remove(at));
            if wake {
                notify(&self.notifier);
                self.in_flight.answered();
            } else {
                self.answered.push(active);
                self.quiet.hold();
            }
        }
    }

    /// One request from another process: answered at once, or gone into the real port as
    /// the flight returned.
    fn take(&mut self, active: Active<Req, Rep>) -> Option<Flight<Req, Rep>> {
        let meta = *active.user_header();
        let active: Held<Req, Rep> = Arc::new(Mutex::new(active));
        let answer = |status: u32, detail: u32| {
            reply(&active, status, detail, Rep::default());
            notify(&self.notifier);
            None
        };
        // A header a peer wrote garbage into is refused; the bridge goes on serving.
        // Borrowed from the header's copy: a request allocates no name.
        let Some(module) = meta.module() else {
            return answer(MALFORMED, 0);
        };
        // A module this copy of the owner has not seen yet — the owner was restarted since
        // the module connected — is attached now, as at its connection.
        let end = match user(&mut self.attach, &mut self.users, module) {
            Ok(end) => end,
            Err((status, detail)) => return answer(status, detail),
        };
        match meta.kind {
            CONNECT => answer(OK, if self.tight { TIGHT } else { 0 }),
            SEND => {
                let request = M::from_request(&active);
                self.in_flight.taken();
                // Each request waits on its own, so that several remote modules' requests
                // are pending at once and the owner's order decides which it takes.
                // Unconstrained: a spinning owner's turn polls the flight in the module's
                // own task, whose tokio budget (128 operations a poll) a module that never
                // waits long spends in about a hundred requests. The end's lock would then
                // say pending at every 128th request, which would wait for the bridge's
                // task while the module spun its spin out and parked: 0.3 ms, not 3 µs.
                Some(Box::pin(tokio::task::unconstrained(async move {
                    let reply = end.lock().await.forward(request).await;
                    respond(&active, reply);
                    active
                })))
            }
            _ => answer(MALFORMED, 0),
        }
    }
}

impl<Req, Rep, M, R, E, A> Work for Serving<Req, Rep, M, R, E, A>
where
    Req: Wire,
    Rep: Wire,
    M: Carry<Req>,
    R: Carry<Rep>,
    E: Forward<M, R>,
    A: FnMut(&str) -> Result<E, Refusal> + Send + 'static,
{
    fn work(&mut self, everything: bool) -> bool {
        let notified = match &self.readiness {
            Some(readiness) => readiness
                .drain(&mut Context::from_waker(&self.dispatch))
                .unwrap_or_else(|_| {
                    self.closed = true;
                    false
                }),
            None => false,
        };
        // A wake-up of the flights alone (a module answered) has no request to take.
        self.serve(true, everything || notified);
        self.announce();
        !self.closed
    }
}

impl<Req, Rep, M, R, E, A> Turns for Serving<Req, Rep, M, R, E, A>
where
    Req: Wire,
    Rep: Wire,
    M: Carry<Req>,
    R: Carry<Rep>,
    E: Forward<M, R>,
    A: FnMut(&str) -> Result<E, Refusal> + Send + 'static,
{
    fn turn(&mut self) {
        self.serve(false, true);
        // A user's process that took its reply has let its request go: it was not parked,
        // and needs no wake-up.
        let in_flight = &self.in_flight;
        self.answered.retain(|active| {
            let waiting = lock(active).is_connected();
            if !waiting {
                in_flight.answered();
            }
            waiting
        });
        if self.quiet.turn(!self.answered.is_empty()) {
            self.announce();
        }
    }

    fn announce(&mut self) {
        self.quiet.take();
        if self.answered.is_empty() {
            return;
        }
        notify(&self.notifier);
        for _ in self.answered.drain(..) {
            self.in_flight.answered();
        }
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
        Err(Refusal::Wire(WireError::NotOnUserList { .. }) | Refusal::NotOnUserList) => {
            Err((NOT_ON_USER_LIST, 0))
        }
        Err(
            Refusal::Wire(WireError::TooManyUsers { capacity, .. }) | Refusal::Full { capacity },
        ) => Err((TOO_MANY_USERS, u32::try_from(capacity).unwrap_or(u32::MAX))),
        Err(Refusal::TooManyNames) => Err((
            TOO_MANY_NAMES,
            u32::try_from(Name::MOST_FROM_PEERS).unwrap_or(u32::MAX),
        )),
        Err(_) => Err((REFUSED, 0)),
    }
}

/// Replies through shared memory, with `status` and `detail`. The request is let go when
/// the last holder drops it: here, or, for a request read in place, the module.
fn reply<Req: Wire, Rep: Wire, R: Carry<Rep>>(
    active: &Held<Req, Rep>,
    status: u32,
    detail: u32,
    reply: R,
) {
    if let Some(mut response) = reply.into_reply(active) {
        *response.user_header_mut() = ReplyMeta { status, detail };
        // A user that died meanwhile cannot be answered; nothing else is lost.
        let _ = response.send();
    }
}

/// Replies with the port's reply, or says there was none.
fn respond<Req: Wire, Rep: Wire, R: Carry<Rep>>(active: &Held<Req, Rep>, answer: Option<R>) {
    match answer {
        Some(answer) => reply(active, OK, 0, answer),
        None => reply(active, NO_REPLY, 0, Rep::default()),
    }
}

/// Wakes the users' bridges: a reply is there.
fn notify(notifier: &Mutex<Notifier<Svc>>) {
    let _ = lock(notifier).notify();
}

#[cfg(test)]
mod tests {
    use std::pin::pin;

    use imrs_ports::{AnyUser, PortSpec};

    use super::*;
    use crate::connect::connect;
    use crate::wire::RequestMeta;
    use crate::{FromBytes, ZeroCopySend};

    #[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend, FromBytes)]
    #[repr(C)]
    #[type_name("imrs_ipc_unit::Number")]
    struct Number {
        value: u64,
    }

    /// Polls `future` once, without yielding: a spinning wait's one poll.
    async fn poll_once<F: Future + Unpin>(future: &mut F) -> Poll<F::Output> {
        std::future::poll_fn(|cx| Poll::Ready(Pin::new(&mut *future).poll(cx))).await
    }

    #[test]
    fn a_spinning_owner_takes_a_waiting_request_at_its_first_poll_however_many_came_before() {
        // One thread: the bridge's task cannot run while the owner's task spins, so every
        // request must go in through the owner's own turns.
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .unwrap();
        runtime.block_on(async {
            let remote = Remote::new(&format!("unit-turns-{}", std::process::id())).unwrap();
            let port: Port<Number, Number, usage::Receive, AnyUser, 1> =
                Port::new(PortSpec::new("DOUBLE", "DOUBLER").process_type(ProcessType::Tight));
            let _exported = export(&remote, &port).unwrap();
            let mut owner = port.owner().unwrap();
            // The handshake waits for the bridge's task, which runs on this thread meanwhile.
            let connection = tokio::task::spawn_blocking({
                let remote = remote.clone();
                move || connect::<Number, Number>(&remote, &Name::from("DOUBLE"), "ASKER")
            })
            .await
            .unwrap()
            .unwrap();
            let ask = |value: u64| {
                let mut loan = connection.client.loan_uninit().unwrap();
                *loan.user_header_mut() = RequestMeta::new(SEND, "ASKER");
                loan.write_payload(Number { value }).send().unwrap()
            };
            // All in one poll of this task, as a module that never waits long: more requests
            // than tokio's budget for one poll (128), each sent with no wake-up, so that only
            // the owner's spinning receive can take it.
            let mut answered = None;
            for value in 1..=400 {
                let pending = ask(value);
                let mut receive = pin!(owner.receive());
                let Poll::Ready(Ok((request, reply))) = poll_once(&mut receive).await else {
                    panic!("request {value} waited in shared memory past the owner's spin");
                };
                assert_eq!(request.value, value);
                reply.reply(Number { value: 2 * value });
                // The turn that took this request sent the reply to the one before.
                if let Some((value, pending)) = answered.replace((value, pending)) {
                    let response = pending.receive().unwrap().expect("the reply was sent");
                    assert_eq!(response.payload().value, 2 * value);
                }
            }
            // The last reply goes at the next wait's first turn.
            let mut receive = pin!(owner.receive());
            assert!(poll_once(&mut receive).await.is_pending());
            let (value, pending) = answered.unwrap();
            let response = pending.receive().unwrap().expect("the reply was sent");
            assert_eq!(response.payload().value, 2 * value);
        });
    }
}
