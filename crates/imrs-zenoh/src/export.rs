//! The owner's host: a port exported to other hosts.
//!
//! Three things serve it while it is exported: a liveliness token that tells other hosts
//! the owner is there; a queryable on the port's `connect` key, which attaches each remote
//! module as the port's user (its restrictions checked then, as in one process); and a
//! queryable on its request key, whose every query goes into the real port through the
//! asking module's own end, and is answered with the reply. Each importing host holds a
//! token per module; when it is gone (the host killed, cut off, or closed), that module's
//! end is dropped and its presence marked gone, so the owner's waits on it end as they
//! would for a module that ended.

use std::borrow::Cow;
use std::collections::HashMap;
use std::sync::{Arc, Mutex, PoisonError};
use std::time::Duration;

use imrs_ports::transport::Presence;
use imrs_ports::{Port, UserList, WireError, usage};
use tokio::sync::Semaphore;
use tokio::task::JoinHandle;
use zenoh::query::Query;

use crate::connected::Connected;
use crate::forward::Forward;
use crate::key::checked;
use crate::message::{Message, decode, encode};
use crate::opening::{Opening, live, watch_users};
use crate::{Host, UserWatch, ZenohError};

/// A port exported to other hosts: served while this is held, withdrawn when dropped.
pub struct Exported {
    port: String,
    host: Host,
    admits: Box<Admits>,
    tasks: Vec<JoinHandle<()>>,
    /// What serves the port besides the tasks: a queryable, or the relays to its users.
    _held: Box<dyn Send + Sync>,
    _token: zenoh::liveliness::LivelinessToken,
}

/// Whether the port's user list has a module, by its name's text (any, without a list).
pub(crate) type Admits = dyn Fn(&str) -> bool + Send + Sync;

impl Exported {
    pub(crate) fn new(
        port: &str,
        host: &Host,
        admits: Box<Admits>,
        tasks: Vec<JoinHandle<()>>,
        held: Box<dyn Send + Sync>,
        token: zenoh::liveliness::LivelinessToken,
    ) -> Self {
        Self {
            port: port.to_owned(),
            host: host.clone(),
            admits,
            tasks,
            _held: held,
            _token: token,
        }
    }

    /// The port.
    pub fn port(&self) -> &str {
        &self.port
    }

    /// Watches module `module`, a user of this port on another host, for a supervisor that
    /// must act when the module's host is gone, whether killed or cut off. Refused, by
    /// name, for a module that is not on the port's user list or that this host does not
    /// admit to the port (it could never import it); on a port without a user list, any
    /// name is watched.
    pub async fn watch_user(&self, module: &str) -> Result<UserWatch, ZenohError> {
        if !(self.admits)(module) {
            return Err(ZenohError::NotAUser {
                port: self.port.clone(),
                module: module.to_owned(),
            });
        }
        self.host.carries_for(&self.port, module)?;
        UserWatch::new(&self.host, &self.port, module).await
    }
}

impl Drop for Exported {
    fn drop(&mut self) {
        self.tasks.iter().for_each(JoinHandle::abort);
    }
}

impl std::fmt::Debug for Exported {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Exported")
            .field("port", &self.port)
            .finish()
    }
}

/// A port whose owner's host can export it, of [`Message`] types: a port its owner receives
/// on, a `RESPONSE` port, or a port whose owner starts each rendezvous (`SENDALL` and
/// `CALLALL`, whose requests are `Clone`; and `QUERY`; the replies of all three `Default`).
#[diagnostic::on_unimplemented(
    message = "`{Self}` cannot cross hosts",
    label = "not a port an IMRS port on zenoh can carry",
    note = "a port crosses hosts when its request and reply are `Message`s: serde types, \
            encoded in CDR (for `SENDALL` and `CALLALL` the request is also `Clone`, and for \
            those and `QUERY` the reply is also `Default`)"
)]
pub trait Export: sealed::Exports {}

/// Exports `port` to the other hosts of `host`'s cell, for their modules to use as its
/// users: their sends reach its owner's `receive`, their queries its response handler,
/// which runs when the owner's order says. Call it within the tokio runtime the cell runs
/// on. Refused if another host already exports the port (as far as this host has heard:
/// two hosts that export one port at the same moment may both be served).
pub async fn export<P: Export>(host: &Host, port: &P) -> Result<Exported, ZenohError> {
    port.export_to(host).await
}

/// The remote modules attached to the port, each with its end and its presence.
struct Users<E> {
    ends: Mutex<HashMap<String, Attached<E>>>,
}

struct Attached<E> {
    end: Arc<tokio::sync::Mutex<E>>,
    /// The port's TIMEOUT for the module, as declared, which its host waits for.
    timeout: Option<Duration>,
    presence: Arc<Presence>,
    /// Set when the module's host is gone: its requests still waiting are dropped, so that
    /// the last hold on its end goes and its user place is free again.
    gone: tokio::sync::watch::Sender<bool>,
    /// Room for the module's requests waiting here at once.
    room: Arc<Semaphore>,
}

/// The most requests of one module that wait here at once. A module's host asks one at a
/// time; past this a peer that floods the port under a module's name is refused at once,
/// so what it costs this host is bounded by the port's users times this.
pub(crate) const MAX_WAITING: usize = 16;

/// Attaches a remote module: its end, and the port's TIMEOUT for it as declared.
type Attach<E> = dyn Fn(&str) -> Result<(E, Option<Duration>), WireError> + Send + Sync;

/// A remote module's end, the port's TIMEOUT for it, the word that its host is gone, and
/// the room for its requests.
type Held<E> = (
    Arc<tokio::sync::Mutex<E>>,
    Option<Duration>,
    tokio::sync::watch::Receiver<bool>,
    Arc<Semaphore>,
);

impl<E> Users<E> {
    /// `module`'s end, attached now with `attach` if it is not yet and `claim` lets it.
    fn end(
        &self,
        module: &str,
        claim: &Claim,
        attach: impl FnOnce(&str) -> Result<(E, Option<Duration>), WireError>,
    ) -> Result<Held<E>, String> {
        let mut ends = self.ends.lock().unwrap_or_else(PoisonError::into_inner);
        if let Some(attached) = ends.get(module) {
            let end = Arc::clone(&attached.end);
            let room = Arc::clone(&attached.room);
            return Ok((end, attached.timeout, attached.gone.subscribe(), room));
        }
        // Refused by its text alone, before its name is made (names are kept for the life
        // of the process): a refused claim grows nothing here. An accepted name is kept,
        // at most `Name::MOST_FROM_PEERS` of them made from peers' text.
        claim(module)?;
        let presence = Presence::new(module);
        // The end is held by the remote module's presence, so that its peers see it gone
        // when the module's host is.
        let (end, timeout) = Presence::within(Some(&presence), || attach(module))
            .map_err(|error| error.to_string())?;
        let end = Arc::new(tokio::sync::Mutex::new(end));
        let (gone, told) = tokio::sync::watch::channel(false);
        let room = Arc::new(Semaphore::new(MAX_WAITING));
        let attached = Attached {
            end: Arc::clone(&end),
            timeout,
            presence,
            gone,
            room: Arc::clone(&room),
        };
        ends.insert(module.to_owned(), attached);
        Ok((end, timeout, told, room))
    }

    /// `module` connects (again): its host has just imported the port, or has seen this host
    /// come back, and what it asked before has ended on its side (`NoReply`). Its requests
    /// still waiting here are dropped with its end, which is let go before it is attached
    /// afresh, so that they hold neither its user place nor its turn.
    async fn renew(&self, module: &str) {
        let old = self
            .ends
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .remove(module);
        let Some(old) = old else { return };
        old.gone.send_replace(true);
        let mut end = old.end;
        // Each request told drops its hold on the end at its next poll.
        while let Err(held) = Arc::try_unwrap(end) {
            end = held;
            tokio::task::yield_now().await;
        }
    }

    /// `module`'s host is gone: its end is let go, and whoever waits on it is told.
    fn gone(&self, module: &str) {
        let attached = self
            .ends
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .remove(module);
        if let Some(attached) = attached {
            attached.gone.send_replace(true);
            attached.presence.set_gone();
        }
    }
}

/// Whether a remote module may attach, by its name's text: why not, naming the port.
pub(crate) type Claim = dyn Fn(&str) -> Result<(), String> + Send + Sync;

/// Serves `port_name` for the remote modules, each claimed with `claim` and attached with
/// `attach`.
async fn serve<Req, Rep, E>(
    host: &Host,
    port_name: &str,
    owner: String,
    (claim, admits): (Box<Claim>, Box<Admits>),
    attach: impl Fn(&str) -> Result<E, WireError> + Send + Sync + 'static,
) -> Result<Exported, ZenohError>
where
    Req: Message,
    Rep: Message,
    E: Forward<Req, Rep>,
{
    let Opening {
        keys,
        connects,
        leaving,
    } = Opening::new(host, port_name).await?;
    let session = &host.session;
    let users = Arc::new(Users::<E> {
        ends: Mutex::default(),
    });
    let lease = host.lease;
    let attach = Arc::new(move |module: &str| {
        attach(module).map(|end| {
            let declared = end.timeout();
            (end.waiting_longer(lease), declared)
        })
    });
    let claim: Arc<Claim> = claim.into();
    let port: Arc<str> = port_name.into();

    // Each request is taken in zenoh's own thread as it comes, and waits for its own
    // rendezvous in a task of the cell's runtime; the next is taken meanwhile.
    let runtime = tokio::runtime::Handle::current();
    let serving = {
        let (users, attach, port) = (Arc::clone(&users), Arc::clone(&attach), Arc::clone(&port));
        let claim = Arc::clone(&claim);
        session
            .declare_queryable(keys.requests())
            .callback(move |query| {
                let (users, attach, port) =
                    (Arc::clone(&users), Arc::clone(&attach), Arc::clone(&port));
                let claim = Arc::clone(&claim);
                runtime.spawn(async move {
                    let answer =
                        forward::<Req, Rep, E>(&query, &users, &*claim, &*attach, &port).await;
                    reply(&query, answer).await;
                });
            })
            .await
            .map_err(ZenohError::session)?
    };
    let token = live(host, &keys).await?;
    let connecting = {
        let (users, attach, port) = (Arc::clone(&users), Arc::clone(&attach), Arc::clone(&port));
        let claim = Arc::clone(&claim);
        tokio::spawn(async move {
            let owner = owner;
            while let Ok(query) = connects.recv_async().await {
                let module = module_of(&query);
                if let Ok(module) = &module {
                    users.renew(module).await;
                }
                let answer = module.and_then(|module| {
                    let (_, timeout, _, _) = users.end(module, &*claim, |m| attach(m))?;
                    let connected = Connected {
                        owner: owner.clone(),
                        timeout_ms: timeout.map_or(0, |t| t.as_millis().max(1) as u64),
                    };
                    encode(&port, &connected).map_err(|e| e.to_string())
                });
                reply(&query, answer).await;
            }
        })
    };
    let watching = {
        let users = Arc::clone(&users);
        watch_users(host, leaving, move |module| users.gone(module))
    };
    Ok(Exported::new(
        port_name,
        host,
        admits,
        vec![connecting, watching],
        Box::new(serving),
        token,
    ))
}

/// One remote request, through its module's end: the reply in CDR, or why there is none.
async fn forward<Req, Rep, E>(
    query: &Query,
    users: &Users<E>,
    claim: &Claim,
    attach: &Attach<E>,
    port: &str,
) -> Result<Vec<u8>, String>
where
    Req: Message,
    Rep: Message,
    E: Forward<Req, Rep>,
{
    let module = module_of(query)?;
    let (end, _, mut gone, room) = users.end(module, claim, attach)?;
    let Ok(_room) = room.try_acquire() else {
        return Err(format!(
            "port {port}: module {module} has {MAX_WAITING} requests waiting already"
        ));
    };
    let bytes = query.payload().map(|p| p.to_bytes()).unwrap_or_default();
    let request: Req = decode(port, &bytes).map_err(|e| e.to_string())?;
    // One request of a module at a time, as in one process: its next waits here.
    let forwarding = async { end.lock().await.forward(request).await };
    let reply = tokio::select! {
        reply = forwarding => reply?,
        // Its host is gone: nobody is there to read the reply, and the request's hold on
        // the module's end must go with it.
        _ = gone.wait_for(|gone| *gone) => {
            return Err(format!("port {port}: module {module}'s host is gone"));
        }
    };
    encode(port, &reply).map_err(|e| e.to_string())
}

/// The module a request or a connection comes from: the last chunk of its key, which
/// access control lets only the module's own host ask.
pub(crate) fn module_of(query: &Query) -> Result<&str, String> {
    module_in(query.key_expr().as_str())
}

/// The module a key of a request or a connection names, checked as part of a key
/// expression (a query for a wildcard names none).
pub(crate) fn module_in(key: &str) -> Result<&str, String> {
    let module = key.rsplit('/').next().unwrap_or_default();
    checked("module", module).map_err(|e| e.to_string())
}

/// The module that asks a `deliver` key: the attachment, its name in UTF-8.
pub(crate) fn sender_of(query: &Query) -> Result<Cow<'_, str>, String> {
    let attachment = query
        .attachment()
        .ok_or("a delivery names no sender: its attachment must be the owner's name")?;
    module_from(attachment.to_bytes())
}

/// The module's name an attachment holds, checked as part of a key expression. Read where
/// it lies when the attachment is one slice, as it is for a name.
pub(crate) fn module_from(attachment: Cow<'_, [u8]>) -> Result<Cow<'_, str>, String> {
    let not_utf8 = |_| "a request's module name is not UTF-8".to_owned();
    let module = match attachment {
        Cow::Borrowed(bytes) => Cow::Borrowed(std::str::from_utf8(bytes).map_err(not_utf8)?),
        Cow::Owned(bytes) => {
            Cow::Owned(String::from_utf8(bytes).map_err(|e| not_utf8(e.utf8_error()))?)
        }
    };
    checked("module", &module).map_err(|e| e.to_string())?;
    Ok(module)
}

/// Answers `query`: a reply on its own key, or an error reply with the reason in UTF-8.
pub(crate) async fn reply(query: &Query, answer: Result<Vec<u8>, String>) {
    let sent = match answer {
        Ok(bytes) => query.reply(query.key_expr().clone(), bytes).await,
        Err(reason) => query.reply_err(reason).await,
    };
    if let Err(error) = sent {
        tracing::debug!(%error, "a reply could not be sent: its asker is gone");
    }
}

pub(crate) mod sealed {
    use super::*;

    pub trait Exports {
        fn export_to(
            &self,
            host: &Host,
        ) -> impl Future<Output = Result<Exported, ZenohError>> + Send;
    }
}

/// Exports with [`serve`], for a port whose users start each rendezvous.
macro_rules! asked {
    ($usage:ty) => {
        impl<Req: Message, Rep: Message, L: UserList, const N: usize> sealed::Exports
            for Port<Req, Rep, $usage, L, N>
        {
            async fn export_to(&self, host: &Host) -> Result<Exported, ZenohError> {
                let port = self.clone();
                let owner = self.owner_module().to_string();
                serve::<Req, Rep, _>(
                    host,
                    self.name().as_str(),
                    owner,
                    checks_of(self),
                    move |module| port.user_named(module),
                )
                .await
            }
        }

        impl<Req: Message, Rep: Message, L: UserList, const N: usize> Export
            for Port<Req, Rep, $usage, L, N>
        {
        }
    };
}

asked!(usage::Receive);
asked!(usage::Response);

/// `port`'s checks of a remote module: its claim, refused in words that name the port; and
/// its user list, as [`Exported::watch_user`] checks it.
pub(crate) fn checks_of<Req, Rep, U, L, const N: usize>(
    port: &Port<Req, Rep, U, L, N>,
) -> (Box<Claim>, Box<Admits>)
where
    Req: Send + 'static,
    Rep: Send + 'static,
    U: imrs_ports::usage::Usage,
    L: UserList,
{
    let claimed = port.clone();
    let listed = port.clone();
    (
        Box::new(move |module: &str| {
            claimed
                .claim(module)
                .map(drop)
                .map_err(|refused| refused.to_string())
        }),
        Box::new(move |module: &str| listed.admits(module)),
    )
}
