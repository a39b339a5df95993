//! The actor frameworks a Rust user would pick instead, doing the same round trip: kameo's
//! `ask` and ractor's `call!`, an 8-byte or 1 KiB message (`[u8; N]`, handed over by value as
//! to an IMRS port) answered with a `u64`, on whatever tokio runtime the caller runs them in.
//! What each framework does with a message inside (both box it into their mailboxes) is
//! theirs and counts in their figures.

use std::convert::Infallible;
use std::hint::black_box;
use std::time::{Duration, Instant};

use kameo::actor::{ActorRef, Spawn};
use kameo::message::{Context, Message};

/// A kameo actor that answers each message with its first byte.
pub struct KameoServer;

impl kameo::Actor for KameoServer {
    type Args = Self;
    type Error = Infallible;

    async fn on_start(server: Self, _: ActorRef<Self>) -> Result<Self, Infallible> {
        Ok(server)
    }
}

impl<const N: usize> Message<[u8; N]> for KameoServer {
    type Reply = u64;

    async fn handle(&mut self, message: [u8; N], _: &mut Context<Self, u64>) -> u64 {
        u64::from(message[0])
    }
}

/// A kameo server, spawned on the runtime this is called in.
pub fn kameo_server() -> ActorRef<KameoServer> {
    KameoServer::spawn(KameoServer)
}

/// `iters` kameo `ask`s of `server`, timed, from whatever runtime runs this.
pub async fn kameo_asks<const N: usize>(server: &ActorRef<KameoServer>, iters: u64) -> Duration {
    let start = Instant::now();
    for _ in 0..iters {
        black_box(
            server
                .ask(black_box([1u8; N]))
                .await
                .expect("the kameo server answers"),
        );
    }
    start.elapsed()
}

/// A ractor actor that answers each message with its first byte.
pub struct RactorServer<const N: usize>;

/// What the ractor server is sent: the payload and the port for the answer.
pub struct RactorAsk<const N: usize>([u8; N], ractor::RpcReplyPort<u64>);

impl<const N: usize> ractor::Actor for RactorServer<N> {
    type Msg = RactorAsk<N>;
    type State = ();
    type Arguments = ();

    async fn pre_start(
        &self,
        _: ractor::ActorRef<Self::Msg>,
        _: (),
    ) -> Result<(), ractor::ActorProcessingErr> {
        Ok(())
    }

    async fn handle(
        &self,
        _: ractor::ActorRef<Self::Msg>,
        RactorAsk(message, reply): Self::Msg,
        _: &mut (),
    ) -> Result<(), ractor::ActorProcessingErr> {
        // The asker may be gone; then nobody wants the answer.
        let _ = reply.send(u64::from(message[0]));
        Ok(())
    }
}

/// A ractor server, spawned on the runtime this is awaited in.
pub async fn ractor_server<const N: usize>() -> ractor::ActorRef<RactorAsk<N>> {
    let (server, _running) = ractor::Actor::spawn(None, RactorServer::<N>, ())
        .await
        .expect("the ractor server starts");
    server
}

/// `iters` ractor `call!`s of `server`, timed, from whatever runtime runs this.
pub async fn ractor_calls<const N: usize>(
    server: &ractor::ActorRef<RactorAsk<N>>,
    iters: u64,
) -> Duration {
    let start = Instant::now();
    for _ in 0..iters {
        let payload = black_box([1u8; N]);
        black_box(
            ractor::call!(server, |reply| RactorAsk(payload, reply))
                .expect("the ractor server answers"),
        );
    }
    start.elapsed()
}
