//! A user's side: a port of another process, imported. Locally it is a port of the same
//! name and types whose owner is a bridge: it takes each local send into shared memory and,
//! woken by iceoryx2's reply events, hands each reply back. It does so where it is woken
//! ([`crate::dispatch`]): in the module's thread as it sends, in the reactor's as the reply
//! comes. On a TIGHT port the user's spinning send does the same in its turns.

use imrs_ports::transport::{EndTransport as _, PortTransport as _};
use std::marker::PhantomData;
use std::sync::{Arc, Mutex, Weak};
use std::task::{Context, Poll, Waker};
use std::time::Duration;

use iceoryx2::port::notifier::Notifier;
use imrs_ports::usage::Usage;
use imrs_ports::{
    AnyUser, End, Name, Port, PortSpec, ProcessType, ReplyHandle, ResponseEnd, Shared, WireError,
    usage,
};

use crate::Exported;
use crate::bridge::{Readiness, Svc};
use crate::carry::{Asker, Carry, Pending, lend, lock};
use crate::connect::{Connection, ask_connect, connect};
use crate::dispatch::{Dispatch, Work};
use crate::export::exported::InFlight;
use crate::sweep::sweep_dead;
use crate::turn::{Quiet, Turn, Turns};
use crate::wire::{OK, RequestMeta, SEND};
use crate::{IpcError, Remote, Wire};

/// A port's client, shared by its forwarder and its lender.
pub(crate) type SharedAsker<Req, Rep> = Arc<Mutex<Asker<Req, Rep>>>;

/// A request sent, and the local sender's right to its reply (taken when answered), which
/// the port carries as `R`.
type Waiting<Req, Rep, R> = (Pending<Req, Rep>, Option<ReplyHandle<R>>);

/// How often a waiter with requests waiting looks for dead peers.
const SWEEP_PERIOD: Duration = Duration::from_millis(500);

/// A port imported from another process, and its bridge: usable while this is held.
pub struct Imported<Req: Send + 'static, Rep: Send + 'static, U: Usage = usage::Receive> {
    port: Port<Req, Rep, U, AnyUser, 1>,
    /// Whatever keeps the bridge working: dropped, it stops.
    _bridge: Mutex<Box<dyn Send>>,
    /// For a port whose owner starts each rendezvous: the owner's requests this process
    /// has taken and not yet answered.
    in_flight: Option<Arc<InFlight>>,
}

/// The task that carries one port's requests into another process: working while this is
/// held.
pub(crate) struct Relay {
    task: tokio::task::JoinHandle<()>,
}

impl<Req: Send + 'static, Rep: Send + 'static, U: Usage> Imported<Req, Rep, U> {
    pub(crate) fn new(port: Port<Req, Rep, U, AnyUser, 1>, bridge: impl Send + 'static) -> Self {
        Self {
            port,
            _bridge: Mutex::new(Box::new(bridge)),
            in_flight: None,
        }
    }

    /// The same, answering the owner's requests through `server`.
    pub(crate) fn serving(
        port: Port<Req, Rep, U, AnyUser, 1>,
        server: Exported,
        bridge: impl Send + 'static,
    ) -> Self {
        let in_flight = Some(server.in_flight());
        Self {
            in_flight,
            ..Self::new(port, (server, bridge))
        }
    }

    /// The local port: attach the importing module to it as to any port.
    pub fn port(&self) -> &Port<Req, Rep, U, AnyUser, 1> {
        &self.port
    }

    /// For a port whose owner starts each rendezvous (`SENDALL`, `CALLALL`, `QUERY`): waits
    /// until every broadcast or query this process took from the owner has been answered
    /// back to it. An answer may be left to a task of the runtime, after the module gave it:
    /// a process that ends cleanly awaits this first, so that its modules' last answers
    /// arrive. For other ports there is nothing to wait for.
    pub async fn settled(&self) {
        if let Some(in_flight) = &self.in_flight {
            in_flight.settled().await;
        }
    }
}

impl Drop for Relay {
    fn drop(&mut self) {
        self.task.abort();
    }
}

/// Imports port `port`, owned by module `owner` in another process of `remote`'s cell, for
/// module `module` of this one: a port its owner receives on, to which `module` sends.
/// Connects at once: refused with the port's own [`WireError`] if `module` is not on its
/// user list or the port has no room for it, and with [`IpcError::TypeMismatch`] if the
/// processes disagree on its types. Call it within the tokio runtime the cell runs on.
pub(crate) fn import<Req: Wire, Rep: Wire>(
    remote: &Remote,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<Imported<Req, Rep>, IpcError> {
    bridge::<Req, Rep, Req, Rep, _, _>(
        remote,
        port,
        module,
        |local: &Port<Req, Rep, usage::Receive, AnyUser, 1>| local.owner(),
        owner,
    )
}

/// Imports a port of messages built in place ([`Shared`]), exported with
/// [`export_shared`](crate::export_shared), as [`import`] does a port of values. The
/// importing module's [`End::loan`] lends it a sample of shared memory: it builds its
/// message there, and its send hands the sample to the owner's process with nothing copied.
/// Each reply is read where the owner's process wrote it. A loan is refused, naming the
/// port, while the module holds as many loans and requests as the port allows at once.
pub(crate) fn import_shared<Req: Wire, Rep: Wire>(
    remote: &Remote,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<Imported<Shared<Req>, Shared<Rep>>, IpcError> {
    let imported = bridge::<Req, Rep, Shared<Req>, Shared<Rep>, _, _>(
        remote,
        port,
        module,
        |local: &Port<Shared<Req>, Shared<Rep>, usage::Receive, AnyUser, 1>| local.owner(),
        owner,
    )?;
    Ok(imported)
}

/// Imports a `RESPONSE` port of another process, as [`import`] does a port its owner
/// receives on: `module` queries it, and the owner's response handler answers when the
/// owner's order says.
pub(crate) fn import_response<Req: Wire, Rep: Wire>(
    remote: &Remote,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<Imported<Req, Rep, usage::Response>, IpcError> {
    bridge(
        remote,
        port,
        module,
        // The handler never runs: the bridge takes each query and answers it with the
        // other process's reply.
        |local: &Port<Req, Rep, usage::Response, AnyUser, 1>| {
            local.answer(local.owner_module().clone(), |_: &(), _: Req| {
                Rep::default()
            })
        },
        owner,
    )
}

/// Imports a `RESPONSE` port of messages built in place ([`Shared`]), exported with
/// [`export_response_shared`](crate::export_response_shared), as [`import_shared`] does a
/// port its owner receives on: `module` loans each query in shared memory
/// ([`End::loan`]), and reads each answer where the owner's response handler built it.
pub(crate) fn import_response_shared<Req: Wire, Rep: Wire>(
    remote: &Remote,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<Imported<Shared<Req>, Shared<Rep>, usage::Response>, IpcError> {
    bridge::<Req, Rep, Shared<Req>, Shared<Rep>, _, _>(
        remote,
        port,
        module,
        // The handler never runs, as for `import_response`.
        |local: &Port<Shared<Req>, Shared<Rep>, usage::Response, AnyUser, 1>| {
            local.answer(local.owner_module().clone(), |_: &(), _: Shared<Req>| {
                Shared::<Rep>::default()
            })
        },
        owner,
    )
}

/// The local owner's side of an imported port: where the bridge takes each request, and
/// the right to answer it.
pub(crate) trait Take<Req, Rep>: Send + 'static {
    /// The next request, or `None` once the port is done; the task is woken when one comes.
    fn poll_next(&mut self, cx: &mut Context<'_>) -> Poll<Option<(Req, ReplyHandle<Rep>)>>;
    /// The next request, if one is waiting now.
    fn try_next(&mut self) -> Option<(Req, ReplyHandle<Rep>)>;
    /// Makes the bridge's waits park at once: the task waits here, and a spinning module's
    /// turns take from here, which a spin of the task's own would hold up.
    fn park(&mut self);
}

impl<Req: Send + 'static, Rep: Send + 'static> Take<Req, Rep> for End<Req, Rep, usage::Receive> {
    fn poll_next(&mut self, cx: &mut Context<'_>) -> Poll<Option<(Req, ReplyHandle<Rep>)>> {
        // A receive dropped before it completes takes nothing: one made at each poll is as
        // good as one kept.
        std::pin::pin!(self.receive()).poll(cx).map(Result::ok)
    }

    fn try_next(&mut self) -> Option<(Req, ReplyHandle<Rep>)> {
        self.try_receive()
    }

    fn park(&mut self) {
        self.park_waits();
    }
}

impl<Req: Send + 'static, Rep: Send + 'static> Take<Req, Rep> for ResponseEnd<Req, Rep, ()> {
    fn poll_next(&mut self, cx: &mut Context<'_>) -> Poll<Option<(Req, ReplyHandle<Rep>)>> {
        loop {
            match self.poll_pending(cx) {
                Poll::Ready(Ok(())) => {
                    if let Some(taken) = self.take() {
                        return Poll::Ready(Some(taken));
                    }
                }
                Poll::Ready(Err(_)) => return Poll::Ready(None),
                Poll::Pending => return Poll::Pending,
            }
        }
    }

    fn try_next(&mut self) -> Option<(Req, ReplyHandle<Rep>)> {
        self.take()
    }

    // A response end's wait for its queries never spins.
    fn park(&mut self) {}
}

/// Imports port `port` for `module`: a local port of message types `M` and `R`, whose
/// owner's end, `own`, is the bridge; what crosses is of wire types `Req` and `Rep`.
fn bridge<Req, Rep, M, R, U, T>(
    remote: &Remote,
    port: &str,
    module: &str,
    own: impl FnOnce(&Port<M, R, U, AnyUser, 1>) -> Result<T, WireError>,
    owner: &str,
) -> Result<Imported<M, R, U>, IpcError>
where
    Req: Wire,
    Rep: Wire,
    M: Carry<Req> + Lent<Req, Rep>,
    R: Carry<Rep>,
    U: Usage,
    T: Take<M, R>,
{
    let name = Name::from(port);
    let connection = connect::<Req, Rep>(remote, &name, module)?;
    // The port waits as its owner declared it: a TIGHT port's sends spin here too.
    let process_type = if connection.tight {
        ProcessType::Tight
    } else {
        ProcessType::default()
    };
    let local: Port<M, R, U, AnyUser, 1> = Port::new(
        PortSpec::new(name.clone(), owner)
            .user_list([module])
            .process_type(process_type),
    );
    let taken = own(&local).map_err(IpcError::Local)?;
    let tight = connection.tight;
    let (relay, side) = relay_connected::<Req, Rep, M, R, T>(connection, &name, module, taken)?;
    if tight {
        local.pump_with(Turn(Arc::downgrade(&side)));
    }
    let client = Arc::clone(&lock(&side).client);
    Ok(Imported::new(M::lend_from(local, client, name), relay))
}

/// Where the importing module's loans come from: nowhere, for a port of values; the
/// client's shared memory, for a port of [`Shared`] messages.
pub(crate) trait Lent<Req: Wire, Rep: Wire>: Sized {
    /// `port`, lending from `client` if its messages are built in place.
    fn lend_from<R: Send + 'static, U: Usage>(
        port: Port<Self, R, U, AnyUser, 1>,
        client: SharedAsker<Req, Rep>,
        name: Name,
    ) -> Port<Self, R, U, AnyUser, 1>;
}

impl<Req: Wire, Rep: Wire> Lent<Req, Rep> for Req {
    fn lend_from<R: Send + 'static, U: Usage>(
        port: Port<Self, R, U, AnyUser, 1>,
        _: SharedAsker<Req, Rep>,
        _: Name,
    ) -> Port<Self, R, U, AnyUser, 1> {
        port
    }
}

impl<Req: Wire, Rep: Wire> Lent<Req, Rep> for Shared<Req> {
    fn lend_from<R: Send + 'static, U: Usage>(
        port: Port<Self, R, U, AnyUser, 1>,
        client: SharedAsker<Req, Rep>,
        name: Name,
    ) -> Port<Self, R, U, AnyUser, 1> {
        port.lend_with(move || lend(&client, &name))
    }
}

/// Relays what `taken` takes to port `name`'s owner in another process, as module
/// `module`, and hands each reply back; connects first. Call it within a tokio runtime.
/// Also gives the relay's client, whose samples a message may be built in.
pub(crate) fn relay<Req, Rep, M, R, T>(
    remote: &Remote,
    name: &Name,
    module: &str,
    taken: T,
) -> Result<(Relay, SharedAsker<Req, Rep>), IpcError>
where
    Req: Wire,
    Rep: Wire,
    M: Carry<Req>,
    R: Carry<Rep>,
    T: Take<M, R>,
{
    let connection = connect::<Req, Rep>(remote, name, module)?;
    let (relay, side) = relay_connected::<Req, Rep, M, R, T>(connection, name, module, taken)?;
    let client = Arc::clone(&lock(&side).client);
    Ok((relay, client))
}

/// One port's bridge in a user's process: the local owner's end through which the
/// importing module's requests are taken, the client that sends them into shared memory,
/// and the requests sent and waiting for their replies.
pub(crate) struct Relaying<Req: Wire, Rep: Wire, M, R, T> {
    taken: T,
    client: SharedAsker<Req, Rep>,
    waiting: Vec<Waiting<Req, Rep, R>>,
    module: String,
    wake_owner: Notifier<Svc>,
    /// The owner's notifications that replies came.
    readiness: Readiness,
    /// The waker of the bridge: the module's sends and the owner's notifications wake it.
    dispatch: Waker,
    /// Whether the bridge is done: the local port closed, or the reactor is gone.
    closed: bool,
    /// Requests sent by a spinning module's turn, whose owner was not woken.
    quiet: Quiet,
    _carried: PhantomData<fn(M)>,
}

impl<Req: Wire, Rep: Wire, M: Carry<Req>, R: Carry<Rep>, T: Take<M, R>>
    Relaying<Req, Rep, M, R, T>
{
    /// Sends `request` to the owner, and keeps `reply` for its answer; wakes the owner, or,
    /// from a spinning module's turn, holds the wake-up back.
    fn forward(&mut self, request: M, reply: ReplyHandle<R>, wake: bool) {
        let sent = {
            let client = lock(&self.client);
            request.into_request(&client).and_then(|mut loan| {
                *loan.user_header_mut() = RequestMeta::new(SEND, &self.module);
                loan.send().ok()
            })
        };
        // Not sent (no room, no owner): the reply handle is dropped, and the local sender
        // gets `SendError::NoReply` at once.
        let Some(pending) = sent else { return };
        self.waiting.push((pending, Some(reply)));
        if wake {
            self.announce_now();
        } else {
            self.quiet.hold();
        }
    }

    fn announce_now(&mut self) {
        self.quiet.take();
        let _ = self.wake_owner.notify();
    }
}

impl<Req: Wire, Rep: Wire, M: Carry<Req>, R: Carry<Rep>, T: Take<M, R>> Work
    for Relaying<Req, Rep, M, R, T>
{
    /// Forwards each request the importing module sent, and hands each reply that came
    /// back to its sender.
    fn work(&mut self, everything: bool) -> bool {
        let dispatch = self.dispatch.clone();
        let mut cx = Context::from_waker(&dispatch);
        let notified = self.readiness.drain(&mut cx).unwrap_or_else(|_| {
            self.closed = true;
            false
        });
        // Forwarded where it is taken: a large message is not moved on.
        loop {
            match self.taken.poll_next(&mut cx) {
                Poll::Ready(Some((request, reply))) => self.forward(request, reply, true),
                Poll::Ready(None) => {
                    self.closed = true;
                    break;
                }
                Poll::Pending => break,
            }
        }
        // Wake-ups a spinning module's turns held back go now: the bridge works here when
        // the module no longer spins.
        self.announce();
        // A reply comes with the owner's notification: a wake-up of a send alone has none.
        if everything || notified {
            look(&mut self.waiting);
        }
        !self.closed
    }
}

impl<Req: Wire, Rep: Wire, M: Carry<Req>, R: Carry<Rep>, T: Take<M, R>> Turns
    for Relaying<Req, Rep, M, R, T>
{
    fn turn(&mut self) {
        while let Some((request, reply)) = self.taken.try_next() {
            self.forward(request, reply, false);
        }
        look(&mut self.waiting);
        if self.quiet.turn(!self.waiting.is_empty()) {
            self.announce_now();
        }
    }

    fn announce(&mut self) {
        if self.quiet.take() {
            let _ = self.wake_owner.notify();
        }
    }
}

type Relayed<Req, Rep, M, R, T> = Arc<Mutex<Relaying<Req, Rep, M, R, T>>>;

/// A bridge's task, and its side, which a spinning module's turns share.
type Bridged<Req, Rep, M, R, T> = (Relay, Relayed<Req, Rep, M, R, T>);

/// [`relay`], over a connection made.
fn relay_connected<Req, Rep, M, R, T>(
    connection: Connection<Req, Rep>,
    name: &Name,
    module: &str,
    mut taken: T,
) -> Result<Bridged<Req, Rep, M, R, T>, IpcError>
where
    Req: Wire,
    Rep: Wire,
    M: Carry<Req>,
    R: Carry<Rep>,
    T: Take<M, R>,
{
    let runtime = tokio::runtime::Handle::try_current().map_err(|_| IpcError::Transport {
        port: name.clone(),
        detail: "import it from within the tokio runtime its cell runs on".into(),
    })?;
    let Connection {
        channel,
        client,
        listener,
        wake_owner,
        tight,
    } = connection;
    taken.park();
    // Woken by the owner's notify through tokio's reactor, and by the module's sends. On a
    // port that parks the work is done where the wake-up comes, so that a request reaches
    // shared memory, and a reply its sender, with no task switch between; otherwise, and
    // at each sweep, by a task in the runtime the importing module runs on.
    let dispatch = Dispatch::new(!tight);
    let side = Arc::new(Mutex::new(Relaying {
        taken,
        client: Arc::new(Mutex::new(client)),
        waiting: Vec::new(),
        module: module.to_owned(),
        wake_owner,
        readiness: Readiness::new(listener, name)?,
        dispatch: Waker::from(Arc::clone(&dispatch)),
        closed: false,
        quiet: Quiet::default(),
        _carried: PhantomData,
    }));
    dispatch.serve(Arc::downgrade(&side) as Weak<Mutex<dyn Work>>);
    let task = runtime.spawn({
        let side = Arc::clone(&side);
        async move {
            // The channel lives as long as the task: its node keeps the services open.
            let _channel = channel;
            relay_requests(&side, &dispatch).await;
        }
    });
    Ok((Relay { task }, side))
}

/// Keeps `module` attached to the port's owner, whoever that is: the owner of a port that
/// starts each rendezvous itself hears nothing from its users once they connect, so an
/// owner started again (or exporting the port again) would not know them. Every half
/// second the module connects again: an owner that knows it answers at once, and a new
/// one attaches it, relaying to it from then on. A connection unanswered for a whole tick
/// may have gone to an owner that died, so what dead processes left is swept first, and a
/// new owner is reached. Call it within a tokio runtime; the task ends when this is
/// dropped.
pub(crate) fn keep_attached<Req: Wire, Rep: Wire>(
    connection: Connection<Req, Rep>,
    module: &str,
) -> Relay {
    let module = module.to_owned();
    let task = tokio::spawn(async move {
        let Connection {
            channel,
            client,
            listener,
            wake_owner,
            ..
        } = connection;
        // The channel lives as long as the task: its node keeps the services open.
        let _channel = channel;
        let mut tick = tokio::time::interval(SWEEP_PERIOD);
        tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
        // The first tick is at once: the module has just connected.
        tick.tick().await;
        let mut asked: Option<Pending<Req, Rep>> = None;
        loop {
            tick.tick().await;
            // The owner's wake-ups for these answers are not waited on: let them go.
            let _ = listener.try_wait(|_| {});
            if let Some(asked) = asked.take()
                && !matches!(asked.receive(), Ok(Some(_)))
            {
                sweep_dead().await;
            }
            asked = ask_connect(&client, &module);
            let _ = wake_owner.notify();
        }
    });
    Relay { task }
}

/// The bridge's task: does the bridge's work where a wake-up could not be served where it
/// came, and every half second, to see whether the owner died while requests wait (their
/// senders then fail at once). A spinning module's turns do the same between its wake-ups.
async fn relay_requests<Req: Wire, Rep: Wire, M: Carry<Req>, R: Carry<Rep>, T: Take<M, R>>(
    side: &Mutex<Relaying<Req, Rep, M, R, T>>,
    dispatch: &Dispatch,
) {
    let mut sweep = tokio::time::interval(SWEEP_PERIOD);
    sweep.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    loop {
        if !lock(side).work(true) {
            return;
        }
        tokio::select! {
            () = dispatch.woken() => {}
            // Ticking even with nothing waiting: a spinning module's turn may forward a
            // request while this task waits, and the task would never learn that a
            // request waits on an owner who then dies.
            _ = sweep.tick() => {
                let waiting = !lock(side).waiting.is_empty();
                if waiting {
                    sweep_dead().await;
                }
            }
        }
    }
}

/// Hands each reply that came to its sender, and lets go of the requests that are done:
/// answered, or whose owner is gone (their reply handles drop, and their senders fail).
fn look<Req: Wire, Rep: Wire, R: Carry<Rep>>(waiting: &mut Vec<Waiting<Req, Rep, R>>) {
    waiting.retain_mut(|(pending, reply)| {
        // Whether the owner still holds the request, read before looking for its reply: an
        // owner replies, then lets the request go, so a reply sent before it let go is
        // there to be received now.
        let connected = pending.is_connected();
        match pending.receive() {
            Ok(Some(response)) => {
                if let Some(reply) = reply.take()
                    && response.user_header().status == OK
                {
                    reply.reply(R::from_answer(response));
                }
                false
            }
            // The owner is gone (or let the request go unanswered): the reply handle drops,
            // and the sender fails at once.
            Ok(None) => connected,
            Err(_) => false,
        }
    });
}
