//! A user's host: a port of another host, imported.
//!
//! Locally it is a port of the same name and types whose owner is a bridge, attached under
//! the presence of the remote owner. The bridge takes each local send or query and asks
//! the owner's host with a zenoh `get`, and hands the reply back. It watches the owner's
//! liveliness token: when the owner's host is gone (killed, cut off past its lease, or
//! closed), it marks the owner's presence gone and lets go of its end, so that waits on the
//! port end with `PeerGone`, and the requests it had asked and not yet had answered end
//! with `NoReply`. When the token comes back, the bridge attaches again and the port is
//! served, with no new import.

use std::sync::Arc;
use std::time::Duration;

use imrs_ports::transport::Presence;
use imrs_ports::usage::Usage;
use imrs_ports::{AnyUser, End, Port, PortSpec, ResponseEnd, WireError, usage};
use tokio::task::JoinHandle;

use crate::asking::{Asking, Pending};
use crate::connected::Connected;
use crate::key::{Keys, checked};
use crate::message::{Message, decode};
use crate::take::Take;
use crate::watch::Watch;
use crate::{Host, ZenohError};

/// How long the owner's host may take to be seen, and to answer a connection.
pub(crate) const CONNECT_TIMEOUT: Duration = Duration::from_secs(5);

/// How long past a port's TIMEOUT the bridge still waits for a reply.
const AFTER_TIMEOUT: Duration = Duration::from_millis(50);

/// How long a request with no TIMEOUT may wait for its reply across hosts: zenoh's
/// queries end, and a port without a TIMEOUT waits as long as its owner takes.
pub(crate) const NO_TIMEOUT: Duration = Duration::from_secs(24 * 3600);

/// A port imported from another host, and its bridge: usable while this is held.
pub struct Imported<Req: Send + 'static, Rep: Send + 'static, U: Usage = usage::Receive> {
    port: Port<Req, Rep, U, AnyUser, 1>,
    bridge: JoinHandle<()>,
    _token: zenoh::liveliness::LivelinessToken,
    /// For a port whose owner starts each rendezvous: the queryable it reaches the module by.
    _held: Option<Box<dyn Send + Sync>>,
}

impl<Req: Send + 'static, Rep: Send + 'static, U: Usage> Imported<Req, Rep, U> {
    pub(crate) fn relayed(
        port: Port<Req, Rep, U, AnyUser, 1>,
        bridge: JoinHandle<()>,
        token: zenoh::liveliness::LivelinessToken,
        held: Box<dyn Send + Sync>,
    ) -> Self {
        Self {
            port,
            bridge,
            _token: token,
            _held: Some(held),
        }
    }

    /// The local port: attach the importing module to it as to any port.
    pub fn port(&self) -> &Port<Req, Rep, U, AnyUser, 1> {
        &self.port
    }
}

impl<Req: Send + 'static, Rep: Send + 'static, U: Usage> std::fmt::Debug for Imported<Req, Rep, U> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Imported")
            .field("port", self.port.name())
            .field("owner", self.port.owner_module())
            .finish()
    }
}

impl<Req: Send + 'static, Rep: Send + 'static, U: Usage> Drop for Imported<Req, Rep, U> {
    fn drop(&mut self) {
        self.bridge.abort();
    }
}

/// A port a user's host can import: an [`Imported`] of [`Message`] types, of any usage the
/// owner's host can export (see [`Export`](crate::Export)).
#[diagnostic::on_unimplemented(
    message = "`{Self}` cannot be imported across hosts",
    label = "not a port an IMRS port on zenoh can carry",
    note = "import an `Imported<Req, Rep, Usage>` whose request and reply are `Message`s, \
            with the bounds `Export` names for its usage"
)]
pub trait Import: sealed::Imports {}

/// Imports port `port`, owned by module `owner` on another host of `host`'s cell, for
/// module `module` of this one. Connects at once: refused with the port's own wiring error
/// (named in [`ZenohError::Refused`]) if `module` is not on its user list or the port has
/// no room for it, or if `owner` does not own it; [`ZenohError::NoOwner`] if no host
/// exports it. Call it within the tokio runtime the cell runs on.
pub async fn import<I: Import>(
    host: &Host,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<I, ZenohError> {
    I::import_from(host, port, owner, module).await
}

/// Attaching the owner's side of a local port of usage `U`.
trait Attach<Req, Rep, U: Usage>: Sized {
    fn attach_to(local: &Port<Req, Rep, U, AnyUser, 1>) -> Result<Self, WireError>;
}

impl<Req: Send + 'static, Rep: Send + 'static> Attach<Req, Rep, usage::Receive>
    for End<Req, Rep, usage::Receive>
{
    fn attach_to(local: &Port<Req, Rep, usage::Receive, AnyUser, 1>) -> Result<Self, WireError> {
        local.owner()
    }
}

impl<Req: Send + 'static, Rep: Message> Attach<Req, Rep, usage::Response>
    for ResponseEnd<Req, Rep, ()>
{
    fn attach_to(local: &Port<Req, Rep, usage::Response, AnyUser, 1>) -> Result<Self, WireError> {
        // The handler never runs: the bridge takes each query and answers it with the
        // owner's host's reply.
        local.answer(local.owner_module().clone(), |_: &(), _: Req| {
            unreachable!("a bridged RESPONSE port's queries are taken, never handled here")
        })
    }
}

/// How every import begins: `port`'s keys, its names checked, and its owner's token
/// watched, once seen (then so is the owner's host's connect queryable).
pub(crate) async fn begin(
    host: &Host,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<(Keys, Watch), ZenohError> {
    let keys = Keys::new(&host.cell, port)?;
    host.carries_for(port, module)?;
    checked("module", owner)?;
    checked("module", module)?;
    let watch = Watch::owner(&host.session, &keys.live, port, CONNECT_TIMEOUT).await?;
    Ok((keys, watch))
}

/// `module`'s connection to `port`, refused if another module than `owner` owns it.
pub(crate) async fn connect_to(
    host: &Host,
    keys: &Keys,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<Connected, ZenohError> {
    let connected = connect(host, keys, port, module).await?;
    if connected.owner == owner {
        Ok(connected)
    } else {
        Err(ZenohError::Refused {
            port: port.to_owned(),
            reason: format!("{owner} does not own it; {} does", connected.owner),
        })
    }
}

/// The port's TIMEOUT for the module, as the owner's host answered it, and how long each of
/// the module's requests waits for its reply: a little past the TIMEOUT, so that the sender
/// hears its own `ReplyTimeout` first, and the bridge, free again, takes its next send in
/// time.
pub(crate) fn waits(connected: &Connected) -> (Option<Duration>, Duration) {
    let timeout = (connected.timeout_ms > 0).then(|| Duration::from_millis(connected.timeout_ms));
    let wait = timeout.map_or(NO_TIMEOUT, |t| t.saturating_add(AFTER_TIMEOUT));
    (timeout, wait)
}

/// Connects `module` to `port` and starts the bridge of its local side, `T`.
async fn bridge<Req, Rep, U, T>(
    host: &Host,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<Imported<Req, Rep, U>, ZenohError>
where
    Req: Message,
    Rep: Message,
    U: Usage,
    T: Take<Req, Rep> + Attach<Req, Rep, U>,
{
    let (keys, watch) = begin(host, port, owner, module).await?;
    let session = &host.session;
    // The module's token before its connection: the owner's host lets go of the module's
    // end when the token goes, which it must hold for that (a failed import drops it).
    let token = session
        .liveliness()
        .declare_token(keys.user(module))
        .await
        .map_err(ZenohError::session)?;
    let connected = connect_to(host, &keys, port, owner, module).await?;
    let mut spec = PortSpec::new(port, owner);
    let (timeout, wait) = waits(&connected);
    if let Some(timeout) = timeout {
        spec = spec.user_timeout(timeout);
    }
    let local = Port::<Req, Rep, U, AnyUser, 1>::new(spec);
    let asking = Asking::new(
        session.clone(),
        keys.request(module),
        None,
        port.into(),
        wait,
    )
    .await?;
    let owner: Arc<str> = owner.into();
    let bridged = local.clone();
    let (host, port, module) = (host.clone(), port.to_owned(), module.to_owned());
    let bridge = tokio::spawn(async move {
        let mut back = false;
        loop {
            // The owner's host is back: connect again, so that it drops what it still held
            // of this module's requests asked before (they ended here with `NoReply`).
            if back && !reconnect(&host, &keys, &port, &module, &watch).await {
                return;
            }
            {
                // Marked gone on every way out of this block, the bridge aborted with its
                // import included, once the end is let go: the local module's waits end
                // with `PeerGone` rather than hang.
                let presence = GoneOnDrop(Presence::new(&*owner));
                let end = Presence::within(Some(&presence.0), || T::attach_to(&bridged));
                let Ok(end) = end else { return };
                if !serve_while_live::<Req, Rep, T>(end, &watch, &asking).await {
                    return;
                }
            }
            // Gone: wait for the owner's host to come back.
            if !watch.back().await {
                return;
            }
            back = true;
        }
    });
    Ok(Imported {
        port: local,
        bridge,
        _token: token,
        _held: None,
    })
}

/// Connects `module` again to a port whose owner's host is back, trying again, a little
/// later each time, while it refuses (a user place not free yet) and the owner stays; false
/// once nothing more can be heard of the owner.
pub(crate) async fn reconnect(
    host: &Host,
    keys: &Keys,
    port: &str,
    module: &str,
    watch: &Watch,
) -> bool {
    let mut pause = Duration::from_millis(50);
    loop {
        if connect(host, keys, port, module).await.is_ok() {
            return true;
        }
        tokio::select! {
            () = tokio::time::sleep(pause) => {}
            live = watch.gone() => if !live { return false },
        }
        pause = (pause * 2).min(host.lease);
    }
}

/// A presence marked gone when dropped.
struct GoneOnDrop(Arc<Presence>);

impl Drop for GoneOnDrop {
    fn drop(&mut self) {
        self.0.set_gone();
    }
}

/// Takes local requests through `end` and asks the owner's host, one at a time as its one
/// local user sends them, until its token is gone (true: a request asked meanwhile is
/// dropped unanswered) or the bridge must end (false).
async fn serve_while_live<Req: Message, Rep: Message, T: Take<Req, Rep>>(
    mut end: T,
    watch: &Watch,
    asking: &Asking,
) -> bool {
    loop {
        tokio::select! {
            taken = end.next() => match taken {
                Ok((request, reply)) => {
                    // The module has its answer from zenoh's callback; its next request is
                    // taken once the query has ended, or dropped (its reply with it) if the
                    // owner's host goes first.
                    let mut pending: Pending<Rep> = asking.ask(request, reply).await;
                    tokio::select! {
                        () = pending.ended() => {}
                        live = watch.gone() => return live,
                    }
                }
                // Nobody can use the local port any more.
                Err(_) => return false,
            },
            live = watch.gone() => return live,
        }
    }
}

/// `module`'s connection to `port`: the owner's host's answer, or why there is none.
pub(crate) async fn connect(
    host: &Host,
    keys: &Keys,
    port: &str,
    module: &str,
) -> Result<Connected, ZenohError> {
    let replies = host
        .session
        .get(keys.connect(module))
        .timeout(CONNECT_TIMEOUT)
        .await
        .map_err(ZenohError::session)?;
    let reply = replies
        .recv_async()
        .await
        .map_err(|_| ZenohError::NoOwner {
            port: port.to_owned(),
        })?;
    match reply.into_result() {
        Ok(sample) => decode(port, &sample.payload().to_bytes()),
        Err(error) => Err(ZenohError::Refused {
            port: port.to_owned(),
            reason: String::from_utf8_lossy(&error.payload().to_bytes()).into_owned(),
        }),
    }
}

pub(crate) mod sealed {
    use super::*;

    pub trait Imports: Sized {
        fn import_from(
            host: &Host,
            port: &str,
            owner: &str,
            module: &str,
        ) -> impl Future<Output = Result<Self, ZenohError>> + Send;
    }
}

/// Imports with [`bridge`], whose local owner side `$side` takes what the module asks.
macro_rules! asked {
    ($usage:ty, $side:ty) => {
        impl<Req: Message, Rep: Message> sealed::Imports for Imported<Req, Rep, $usage> {
            async fn import_from(
                host: &Host,
                port: &str,
                owner: &str,
                module: &str,
            ) -> Result<Self, ZenohError> {
                bridge::<Req, Rep, $usage, $side>(host, port, owner, module).await
            }
        }

        impl<Req: Message, Rep: Message> Import for Imported<Req, Rep, $usage> {}
    };
}

asked!(usage::Receive, End<Req, Rep, usage::Receive>);
asked!(usage::Response, ResponseEnd<Req, Rep, ()>);
