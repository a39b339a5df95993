//! Ports whose owner starts each rendezvous (`SENDALL`, `CALLALL`, `QUERY`), across hosts.
//!
//! On the owner's host, each remote module that connects is attached as the port's user
//! (its claim checked first, as for any port), and a relay takes what the owner broadcasts
//! or asks through that module's end, and asks the module's host with a zenoh `get` on the
//! module's `deliver` key; the answer comes back as the module's reply. On the user's
//! host, the imported port's owner is a bridge, attached under the owner's presence: a
//! queryable on the module's `deliver` key hands each broadcast or query to the local
//! module (`send_all`, `call_all` or `query` on the local port) and answers with its reply.
//! When the module's host is gone, its relay ends and its end is let go, as for a module
//! that ended; when the owner's host is gone, the local module's waits end with
//! `PeerGone`, and when it comes back the module connects again, with no new import.
//!
//! Here too such ports are made `Export` and `Import`, beside what exports and imports
//! them: the owner's side and the user's side of the other ports know nothing of relays.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, PoisonError};

use imrs_ports::transport::Presence;
use imrs_ports::usage::Usage;
use imrs_ports::{AnyUser, End, Port, PortSpec, ReceiveError, UserList, WireError, usage};
use tokio::task::JoinHandle;

use crate::asking::{Asking, Pending};
use crate::connected::Connected;
use crate::export::sealed::Exports;
use crate::export::{Admits, Claim, Export, Exported, checks_of, module_of, reply, sender_of};
use crate::import::sealed::Imports;
use crate::import::{Import, NO_TIMEOUT, begin, connect_to, reconnect};
use crate::message::{Message, decode, encode};
use crate::opening::{Opening, live, watch_users};
use crate::take::Take;
use crate::{Host, Imported, ZenohError};

/// A remote module's relay, and what tells it to stop.
type Relay = (JoinHandle<()>, Arc<tokio::sync::Notify>);

/// The relays of an exported port, one per remote module.
#[derive(Default)]
struct Relays {
    running: Mutex<HashMap<String, Relay>>,
}

impl Relays {
    fn lock(&self) -> std::sync::MutexGuard<'_, HashMap<String, Relay>> {
        self.running.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// `module`'s host is gone: its relay ends once what it asked there has ended (the
    /// answer may have come before the host went), then lets its end go.
    fn gone(&self, module: &str) {
        if let Some((_, stop)) = self.lock().remove(module) {
            stop.notify_one();
        }
    }
}

impl Drop for Relays {
    fn drop(&mut self) {
        self.lock().values().for_each(|(relay, _)| relay.abort());
    }
}

/// Exports `port_name` (owned by `owner`), relaying to each remote module through its end,
/// claimed with `claim` and attached with `attach`.
pub(crate) async fn export_relayed<Req, Rep, T>(
    host: &Host,
    port_name: &str,
    owner: String,
    (claim, admits): (Box<Claim>, Box<Admits>),
    attach: impl Fn(&str) -> Result<T, WireError> + Send + Sync + 'static,
) -> Result<Exported, ZenohError>
where
    Req: Message,
    Rep: Message,
    T: Take<Req, Rep>,
{
    let Opening {
        keys,
        connects,
        leaving,
    } = Opening::new(host, port_name).await?;
    let session = &host.session;
    let token = live(host, &keys).await?;
    let relays = Arc::new(Relays::default());
    let lease = host.lease;
    let connecting = {
        let (relays, session, port) = (Arc::clone(&relays), session.clone(), port_name.to_owned());
        tokio::spawn(async move {
            while let Ok(query) = connects.recv_async().await {
                let answer = module_of(&query).and_then(|module| {
                    let mut running = relays.lock();
                    // A relay that has ended (its module gone, or its end closed) is made
                    // anew for a module that connects again.
                    let module = module.to_owned();
                    if running
                        .get(&module)
                        .is_some_and(|(relay, _)| relay.is_finished())
                    {
                        running.remove(&module);
                    }
                    if let std::collections::hash_map::Entry::Vacant(vacant) = running.entry(module)
                    {
                        let module = vacant.key();
                        claim(module)?;
                        let presence = Presence::new(module.as_str());
                        let end = Presence::within(Some(&presence), || attach(module))
                            .map_err(|e| e.to_string())?;
                        let asking = Asking::new(
                            session.clone(),
                            keys.deliver(module),
                            Some(owner.as_str().into()),
                            port.as_str().into(),
                            NO_TIMEOUT,
                        );
                        let stop = Arc::new(tokio::sync::Notify::new());
                        let relay =
                            relay::<Req, Rep, T>(end, asking, presence, Arc::clone(&stop), lease);
                        vacant.insert((tokio::spawn(relay), stop));
                    }
                    let connected = Connected {
                        owner: owner.clone(),
                        timeout_ms: 0,
                    };
                    encode(&port, &connected).map_err(|e| e.to_string())
                });
                reply(&query, answer).await;
            }
        })
    };
    let watching = {
        let relays = Arc::clone(&relays);
        watch_users(host, leaving, move |module| relays.gone(module))
    };
    Ok(Exported::new(
        port_name,
        host,
        admits,
        vec![connecting, watching],
        Box::new(relays),
        token,
    ))
}

/// Takes each broadcast or query the owner makes through a remote module's `end`, and asks
/// the module's host; its answer is the module's reply. Told to `stop` (the module's host
/// is gone), it lets the end go and marks the module's presence gone, so that the owner's
/// waits on it end as for a module that ended.
async fn relay<Req: Message, Rep: Message, T: Take<Req, Rep>>(
    mut end: T,
    asking: impl Future<Output = Result<Asking, ZenohError>>,
    presence: Arc<Presence>,
    stop: Arc<tokio::sync::Notify>,
    grace: std::time::Duration,
) {
    // The broadcast or query asked last: the owner asks one at a time, and the next is taken
    // once its query has ended.
    let mut pending: Option<Pending<Rep>> = None;
    match asking.await {
        Ok(asking) => loop {
            tokio::select! {
                biased;
                () = stop.notified() => break,
                taken = end.next() => match taken {
                    Ok((request, reply)) => {
                        let asked = pending.insert(asking.ask(request, reply).await);
                        tokio::select! {
                            biased;
                            () = stop.notified() => break,
                            () = asked.ended() => {}
                        }
                    }
                    // A quiet spell past the port's TIMEOUT: the module is still there.
                    Err(ReceiveError::Timeout { .. }) => {}
                    Err(_) => break,
                },
            }
        },
        // The module is told its owner is gone when this ends: its waits on the port end.
        Err(error) => tracing::warn!(%error, "a relay to a module could not start"),
    }
    // A host that is gone ends the query, with its answer if it gave one first; one cut off
    // is given a lease to answer, then the reply is dropped (`NoReply`).
    if let Some(pending) = pending {
        let deadline = tokio::time::Instant::now() + grace;
        while pending.waits() && tokio::time::Instant::now() < deadline {
            tokio::time::sleep(RECHECK.min(grace)).await;
        }
        pending.give_up();
    }
    drop(end);
    presence.set_gone();
}

/// How often a relay told its module is gone looks whether the last query was answered.
const RECHECK: std::time::Duration = std::time::Duration::from_millis(10);

/// Exports with [`export_relayed`], for a port whose owner starts each rendezvous.
macro_rules! exported {
    ($usage:ty, $($bound:tt)*) => {
        impl<Req: Message + $($bound)*, Rep: Message + Default, L: UserList, const N: usize>
            Exports for Port<Req, Rep, $usage, L, N>
        {
            async fn export_to(&self, host: &Host) -> Result<Exported, ZenohError> {
                let owner = self.owner_module().to_string();
                let port = self.clone();
                export_relayed::<Req, Rep, _>(
                    host,
                    self.name().as_str(),
                    owner,
                    checks_of(self),
                    move |module| port.attach_relayed(module),
                )
                .await
            }
        }

        impl<Req: Message + $($bound)*, Rep: Message + Default, L: UserList, const N: usize> Export
            for Port<Req, Rep, $usage, L, N>
        {
        }
    };
}

exported!(usage::SendAll, Clone);
exported!(usage::CallAll, Clone);
exported!(usage::Query, Send);

/// A remote module's end of a port whose owner starts each rendezvous: the end it
/// receives broadcasts on, or its response end (whose handler never runs: the relay takes
/// each query and answers it with the module's host's answer).
trait AttachRelayed<Req, Rep> {
    type End;
    fn attach_relayed(&self, module: &str) -> Result<Self::End, WireError>;
}

impl<Req: Send + 'static, Rep: Send + 'static, L: UserList, const N: usize> AttachRelayed<Req, Rep>
    for Port<Req, Rep, usage::SendAll, L, N>
{
    type End = imrs_ports::End<Req, Rep, usage::Receive>;
    fn attach_relayed(&self, module: &str) -> Result<Self::End, WireError> {
        self.user_named(module)
    }
}

impl<Req: Send + 'static, Rep: Send + 'static, L: UserList, const N: usize> AttachRelayed<Req, Rep>
    for Port<Req, Rep, usage::CallAll, L, N>
{
    type End = imrs_ports::ResponseEnd<Req, Rep, ()>;
    fn attach_relayed(&self, module: &str) -> Result<Self::End, WireError> {
        self.answer(module, never_handled::<Req, Rep>)
    }
}

impl<Req: Send + 'static, Rep: Send + 'static, L: UserList, const N: usize> AttachRelayed<Req, Rep>
    for Port<Req, Rep, usage::Query, L, N>
{
    type End = imrs_ports::ResponseEnd<Req, Rep, ()>;
    fn attach_relayed(&self, module: &str) -> Result<Self::End, WireError> {
        self.answer(module, never_handled::<Req, Rep>)
    }
}

/// The handler of a relayed response end: never run, as the relay takes each query and
/// answers it with the module's host's answer.
fn never_handled<Req, Rep>(_: &(), _: Req) -> Rep {
    unreachable!("a relayed port's queries are taken, never handled here")
}

/// The local port's owner end on a user's host: hands a broadcast or query from the
/// owner's host to the one local module, and gives back its reply.
pub(crate) trait Deliver<Req, Rep>: Send + 'static {
    fn deliver(&mut self, request: Req) -> impl Future<Output = Option<Rep>> + Send + '_;
}

impl<Req: Clone + Send + 'static, Rep: Default + Send + 'static> Deliver<Req, Rep>
    for End<Req, Rep, usage::SendAll>
{
    async fn deliver(&mut self, request: Req) -> Option<Rep> {
        self.peer_attached().await;
        let mut broadcast = self.send_all(request).await.ok()?;
        // Taken, not moved: the broadcast lets go of its request when dropped.
        Some(std::mem::take(&mut broadcast.first))
    }
}

impl<Req: Clone + Send + 'static, Rep: Default + Send + 'static> Deliver<Req, Rep>
    for End<Req, Rep, usage::CallAll>
{
    async fn deliver(&mut self, request: Req) -> Option<Rep> {
        self.peer_attached().await;
        let mut broadcast = self.call_all(request).await.ok()?;
        Some(std::mem::take(&mut broadcast.first))
    }
}

impl<Req: Send + 'static, Rep: Send + 'static> Deliver<Req, Rep> for End<Req, Rep, usage::Query> {
    async fn deliver(&mut self, request: Req) -> Option<Rep> {
        self.peer_attached().await;
        self.query(request).await.ok()
    }
}

/// The local owner end, while the owner's host is there.
type Slot<Req, Rep, U> = Arc<tokio::sync::Mutex<Option<End<Req, Rep, U>>>>;

/// Imports `port` (owned by `owner`) for `module`: the owner's broadcasts or queries reach
/// `module` on the local port.
pub(crate) async fn import_relayed<Req, Rep, U>(
    host: &Host,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<Imported<Req, Rep, U>, ZenohError>
where
    Req: Message,
    Rep: Message,
    U: Usage + imrs_ports::usage::Plain,
    End<Req, Rep, U>: Deliver<Req, Rep>,
{
    let (keys, watch) = begin(host, port, owner, module).await?;
    let session = &host.session;
    let local =
        Port::<Req, Rep, U, AnyUser, 1>::new(PortSpec::new(port, owner).user_list([module]));
    let slot: Slot<Req, Rep, U> = Arc::default();
    let mut presence = attach_owner(&local, owner, &slot).await?;
    // Told when the owner's host goes: a delivery that waits for the module's answer ends,
    // and lets go of the slot.
    let (owner_gone, gone) = tokio::sync::watch::channel(false);
    let runtime = tokio::runtime::Handle::current();
    let delivering = {
        let (slot, owner, port) = (Arc::clone(&slot), owner.to_owned(), port.to_owned());
        session
            .declare_queryable(keys.deliver(module))
            .callback(move |query| {
                let (slot, owner, port) = (Arc::clone(&slot), owner.clone(), port.clone());
                let gone = gone.clone();
                runtime.spawn(async move {
                    let answer = deliver::<Req, Rep, U>(&query, &slot, &owner, &port, gone).await;
                    reply(&query, answer).await;
                });
            })
            .await
            .map_err(ZenohError::session)?
    };
    let token = session
        .liveliness()
        .declare_token(keys.user(module))
        .await
        .map_err(ZenohError::session)?;
    connect_to(host, &keys, port, owner, module).await?;
    let bridge = {
        let (host, local, owner, port, module) = (
            host.clone(),
            local.clone(),
            owner.to_owned(),
            port.to_owned(),
            module.to_owned(),
        );
        tokio::spawn(async move {
            loop {
                // The owner's host gone, or this host's session closed: either way the
                // local module's waits end with `PeerGone` rather than hang.
                let live = watch.gone().await;
                // The module's waits end first; a delivery it holds the reply of ends too.
                presence.set_gone();
                owner_gone.send_replace(true);
                drop(slot.lock().await.take());
                if !live {
                    return;
                }
                // Gone: wait for the owner's host to come back, then connect again, so
                // that it attaches the module again.
                if !watch.back().await {
                    return;
                }
                owner_gone.send_replace(false);
                let Ok(back) = attach_owner(&local, &owner, &slot).await else {
                    return;
                };
                presence = back;
                if !reconnect(&host, &keys, &port, &module, &watch).await {
                    return;
                }
            }
        })
    };
    Ok(Imported::relayed(
        local,
        bridge,
        token,
        Box::new(delivering),
    ))
}

/// Attaches the local port's owner end under a presence of `owner`, into `slot`.
async fn attach_owner<Req, Rep, U>(
    local: &Port<Req, Rep, U, AnyUser, 1>,
    owner: &str,
    slot: &Slot<Req, Rep, U>,
) -> Result<Arc<Presence>, ZenohError>
where
    Req: Send + 'static,
    Rep: Send + 'static,
    U: Usage + imrs_ports::usage::Plain,
{
    let presence = Presence::new(owner);
    let end = Presence::within(Some(&presence), || local.owner());
    let end = end.map_err(|error| ZenohError::Refused {
        port: local.name().to_string(),
        reason: error.to_string(),
    })?;
    *slot.lock().await = Some(end);
    Ok(presence)
}

/// One broadcast or query from the owner's host, handed to the local module: its reply in
/// CDR, or why there is none.
async fn deliver<Req, Rep, U>(
    query: &zenoh::query::Query,
    slot: &Slot<Req, Rep, U>,
    owner: &str,
    port: &str,
    mut gone: tokio::sync::watch::Receiver<bool>,
) -> Result<Vec<u8>, String>
where
    Req: Message,
    Rep: Message,
    U: Usage,
    End<Req, Rep, U>: Deliver<Req, Rep>,
{
    if sender_of(query)? != owner {
        return Err(format!("only {owner} broadcasts on port {port}"));
    }
    let bytes = query.payload().map(|p| p.to_bytes()).unwrap_or_default();
    let request: Req = decode(port, &bytes).map_err(|e| e.to_string())?;
    let mut slot = slot.lock().await;
    let end = slot
        .as_mut()
        .ok_or_else(|| format!("port {port}: its owner is gone"))?;
    let answer = tokio::select! {
        answer = end.deliver(request) => {
            answer.ok_or_else(|| format!("port {port}: the module did not answer"))?
        }
        // Nobody is there to read the answer; the slot must go to the bridge.
        _ = gone.wait_for(|gone| *gone) => {
            return Err(format!("port {port}: its owner's host is gone"));
        }
    };
    encode(port, &answer).map_err(|e| e.to_string())
}

/// Imports with [`import_relayed`], for a port whose owner starts each rendezvous.
macro_rules! imported {
    ($usage:ty, $($bound:tt)*) => {
        impl<Req: Message + $($bound)*, Rep: Message + Default> Imports
            for Imported<Req, Rep, $usage>
        {
            async fn import_from(
                host: &Host,
                port: &str,
                owner: &str,
                module: &str,
            ) -> Result<Self, ZenohError> {
                import_relayed::<Req, Rep, $usage>(host, port, owner, module).await
            }
        }

        impl<Req: Message + $($bound)*, Rep: Message + Default> Import
            for Imported<Req, Rep, $usage>
        {
        }
    };
}

imported!(usage::SendAll, Clone);
imported!(usage::CallAll, Clone);
imported!(usage::Query, Send);
