//! The bridge in the owner's process: it takes each request from shared memory into the real
//! port through its module's end, and, woken when the reply comes, sends it back; in a task
//! of the runtime or a thread of its own, and in a spinning owner's turns.

use std::collections::HashMap;
use std::marker::PhantomData;
use std::pin::Pin;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, Weak};
use std::task::{Context, Poll, Wake, Waker};

use iceoryx2::port::notifier::Notifier;
use imrs_ports::Name;

use super::attach::{Forward, Refusal, Users, user};
use super::exported::{Exported, InFlight, Worker};
use crate::bridge::{Channel, Readiness, Side, Svc, TICK};
use crate::carry::{Active, Carry, Held, Server, lock};
use crate::dispatch::{Dispatch, Work};
use crate::turn::{Quiet, Turns};
use crate::wire::{CONNECT, MALFORMED, NO_REPLY, OK, ReplyMeta, SEND, TIGHT};
use crate::{IpcError, Remote, Wire};

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
