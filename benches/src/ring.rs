//! A ring of modules passing a token, for the ring bench and its profile; and the same ring
//! of tokio tasks, of kameo actors and of ractor actors. In every ring a hop is an ask (the
//! token, a `u64`, by value) that the next member answers at once, before it asks the member
//! after it: the answer travels back while the token goes on.

use std::convert::Infallible;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use imrs_core::prelude::*;
use imrs_ports::RealClock;
use kameo::actor::{ActorRef, Spawn};
use kameo::message::{Context, Message};
use kameo::reply::DelegatedReply;
use tokio::sync::{mpsc, oneshot};

/// When the token was first sent, and how long its last hop took to land.
#[derive(Default)]
struct Lap {
    start: Option<Instant>,
    timed: Option<Duration>,
}

type Shared = Arc<Mutex<Lap>>;

/// A runtime of `threads` threads: current-thread for one.
pub fn runtime(threads: usize) -> tokio::runtime::Runtime {
    if threads == 1 {
        return crate::current_thread();
    }
    tokio::runtime::Builder::new_multi_thread()
        .worker_threads(threads)
        .enable_all()
        .build()
        .expect("a runtime starts")
}

/// Module `i` of a ring of `size`: receives the token on its own port, answers, and passes it
/// on to module `i + 1`, until `hops` hops are made. Module 0 sends the token first.
fn ring_module(
    i: usize,
    ports: &[Port<u64, (), usage::Receive>],
    hops: u64,
    lap: &Shared,
) -> ModuleSpec<()> {
    let (own, next) = (ports[i].clone(), ports[(i + 1) % ports.len()].clone());
    let lap = Arc::clone(lap);
    ModuleSpec::new(format!("M{i}"), ())
        .uses(&next)
        .task(format!("M{i}"), move |ctx| {
            let (owner, user, lap) = (ctx.owner(&own), ctx.user(&next), Arc::clone(&lap));
            async move {
                let (mut own, mut next) = (owner?, user?);
                if i == 0 {
                    lap.lock().unwrap().start = Some(Instant::now());
                    ctx.send(&mut next, 1).await?;
                }
                loop {
                    let (token, reply) = ctx.receive(&mut own).await?;
                    reply.reply(());
                    if token == hops {
                        let mut lap = lap.lock().unwrap();
                        lap.timed = lap.start.map(|start| start.elapsed());
                        return Ok(());
                    }
                    ctx.send(&mut next, token + 1).await?;
                }
            }
        })
}

/// `hops` hops around a ring of `size` modules on a runtime of `threads` threads.
pub fn imrs_ring(size: usize, hops: u64, threads: usize) -> Duration {
    let lap = Shared::default();
    let runtime = runtime(threads);
    runtime.block_on(async {
        let cell = Cell::new(Arc::new(RealClock::new()));
        // The ring's events stream to no one; keep few, as a long-running cell would.
        cell.events().set_capacity(1_024);
        let ports: Vec<Port<u64, (), usage::Receive>> = (0..size)
            .map(|i| {
                cell.port(PortSpec::new(format!("P{i}"), format!("M{i}")))
                    .unwrap()
            })
            .collect();
        let mut handles = Vec::with_capacity(size);
        // Module 0 last, so that every other is listening when the token starts.
        for i in (0..size).rev() {
            handles.push(cell.start(ring_module(i, &ports, hops, &lap)).unwrap());
        }
        let last = last_member(size, hops);
        let mut finisher = handles.swap_remove(size - 1 - last);
        finisher.finished().await;
    });
    // Dropping the runtime drops the modules still waiting for a token.
    drop(runtime);
    let lap = lap.lock().unwrap();
    lap.timed.expect("the last hop landed")
}

/// A hop of the tokio ring: the token and a oneshot for the answer.
type Hop = (u64, oneshot::Sender<()>);

/// The ring as `size` tokio tasks, each waiting on an mpsc receiver: each hop an mpsc send,
/// answered through a oneshot. `hops` hops on a runtime of `threads` threads.
pub fn tokio_ring(size: usize, hops: u64, threads: usize) -> Duration {
    let runtime = runtime(threads);
    let timed = runtime.block_on(async {
        let (senders, receivers): (Vec<_>, Vec<_>) =
            (0..size).map(|_| mpsc::channel::<Hop>(1)).unzip();
        let (done, finished) = oneshot::channel();
        let mut done = Some(done);
        let mut first = None;
        for (i, mut inbox) in receivers.into_iter().enumerate() {
            let next = senders[(i + 1) % size].clone();
            // Task `t % size` receives token `t`: the last hop lands at `hops % size`.
            let done = if i == last_member(size, hops) {
                done.take()
            } else {
                None
            };
            if i == 0 {
                first = Some(next.clone());
            }
            tokio::spawn(async move {
                while let Some((token, ack)) = inbox.recv().await {
                    let _ = ack.send(());
                    if token == hops {
                        if let Some(done) = done {
                            let _ = done.send(());
                        }
                        return;
                    }
                    let (ack, acked) = oneshot::channel();
                    if next.send((token + 1, ack)).await.is_err() {
                        return;
                    }
                    let _ = acked.await;
                }
            });
        }
        let first = first.expect("a ring has a first task");
        let start = Instant::now();
        let (ack, acked) = oneshot::channel();
        first.send((1, ack)).await.expect("the ring listens");
        let _ = acked.await;
        finished.await.expect("the last hop landed");
        start.elapsed()
    });
    drop(runtime);
    timed
}

/// The member of a ring of `size` that receives token `hops`: member `t % size` receives
/// token `t`, token 1 going to member 1.
fn last_member(size: usize, hops: u64) -> usize {
    (hops % size as u64) as usize
}

/// A member of the kameo ring.
pub struct KameoMember {
    next: Option<ActorRef<KameoMember>>,
    hops: u64,
    done: Option<oneshot::Sender<()>>,
}

impl kameo::Actor for KameoMember {
    type Args = Self;
    type Error = Infallible;

    async fn on_start(member: Self, _: ActorRef<Self>) -> Result<Self, Infallible> {
        Ok(member)
    }
}

/// Tells a kameo member which member comes after it, once all are spawned.
pub struct Link(ActorRef<KameoMember>);

impl Message<Link> for KameoMember {
    type Reply = ();

    async fn handle(&mut self, Link(next): Link, _: &mut Context<Self, ()>) {
        self.next = Some(next);
    }
}

/// The kameo ring's token.
#[derive(Debug)]
pub struct Token(u64);

impl Message<Token> for KameoMember {
    type Reply = DelegatedReply<()>;

    async fn handle(
        &mut self,
        Token(token): Token,
        ctx: &mut Context<Self, Self::Reply>,
    ) -> Self::Reply {
        // Answered at once, as a module's `reply` is, before the token goes on.
        let answered = ctx.reply(());
        if token == self.hops {
            if let Some(done) = self.done.take() {
                let _ = done.send(());
            }
            return answered;
        }
        let next = self.next.as_ref().expect("every member is linked first");
        next.ask(Token(token + 1))
            .await
            .expect("the next member answers");
        answered
    }
}

/// `hops` hops around a ring of `size` kameo actors on one current-thread runtime, each hop
/// an `ask` answered at once.
pub fn kameo_ring(size: usize, hops: u64) -> Duration {
    crate::current_thread().block_on(async {
        let (done, finished) = oneshot::channel();
        let mut done = Some(done);
        let members: Vec<ActorRef<KameoMember>> = (0..size)
            .map(|i| {
                let done = if i == last_member(size, hops) {
                    done.take()
                } else {
                    None
                };
                KameoMember::spawn(KameoMember {
                    next: None,
                    hops,
                    done,
                })
            })
            .collect();
        for (i, member) in members.iter().enumerate() {
            let next = members[(i + 1) % size].clone();
            member.ask(Link(next)).await.expect("a member is linked");
        }
        let start = Instant::now();
        members[1 % size]
            .ask(Token(1))
            .await
            .expect("the ring listens");
        finished.await.expect("the last hop landed");
        let timed = start.elapsed();
        for member in &members {
            member.kill();
        }
        timed
    })
}

/// What a member of the ractor ring is sent.
pub enum RactorHop {
    /// The member that comes after this one, once all are spawned, and the port to say it
    /// was taken.
    Link(ractor::ActorRef<RactorHop>, ractor::RpcReplyPort<()>),
    /// The token, and the port for the answer.
    Token(u64, ractor::RpcReplyPort<()>),
}

/// A member of the ractor ring.
pub struct RactorMember;

/// A ractor member's state: the member after it, the hops to make, and (for the member that
/// receives the last token) where to say it landed.
pub struct RactorMemberState {
    next: Option<ractor::ActorRef<RactorHop>>,
    hops: u64,
    done: Option<oneshot::Sender<()>>,
}

impl ractor::Actor for RactorMember {
    type Msg = RactorHop;
    type State = RactorMemberState;
    type Arguments = (u64, Option<oneshot::Sender<()>>);

    async fn pre_start(
        &self,
        _: ractor::ActorRef<RactorHop>,
        (hops, done): Self::Arguments,
    ) -> Result<RactorMemberState, ractor::ActorProcessingErr> {
        Ok(RactorMemberState {
            next: None,
            hops,
            done,
        })
    }

    async fn handle(
        &self,
        _: ractor::ActorRef<RactorHop>,
        hop: RactorHop,
        state: &mut RactorMemberState,
    ) -> Result<(), ractor::ActorProcessingErr> {
        match hop {
            RactorHop::Link(next, linked) => {
                state.next = Some(next);
                let _ = linked.send(());
            }
            RactorHop::Token(token, reply) => {
                // Answered at once, as a module's `reply` is, before the token goes on.
                let _ = reply.send(());
                if token == state.hops {
                    if let Some(done) = state.done.take() {
                        let _ = done.send(());
                    }
                    return Ok(());
                }
                let next = state.next.as_ref().ok_or("a member is linked first")?;
                ractor::call!(next, RactorHop::Token, token + 1)
                    .map_err(|_| "the next member answers")?;
            }
        }
        Ok(())
    }
}

/// `hops` hops around a ring of `size` ractor actors on one current-thread runtime, each hop
/// a `call!` answered at once.
pub fn ractor_ring(size: usize, hops: u64) -> Duration {
    crate::current_thread().block_on(async {
        let (done, finished) = oneshot::channel();
        let mut done = Some(done);
        let mut members = Vec::with_capacity(size);
        for i in 0..size {
            let done = if i == last_member(size, hops) {
                done.take()
            } else {
                None
            };
            let (member, _running) = ractor::Actor::spawn(None, RactorMember, (hops, done))
                .await
                .expect("a ractor member starts");
            members.push(member);
        }
        for (i, member) in members.iter().enumerate() {
            let next = members[(i + 1) % size].clone();
            ractor::call!(member, RactorHop::Link, next).expect("a member is linked");
        }
        let start = Instant::now();
        ractor::call!(members[1 % size], RactorHop::Token, 1).expect("the ring listens");
        finished.await.expect("the last hop landed");
        let timed = start.elapsed();
        for member in &members {
            member.stop(None);
        }
        timed
    })
}
