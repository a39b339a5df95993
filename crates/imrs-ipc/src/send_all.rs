//! `SENDALL`, `CALLALL` and `QUERY` ports across processes: the owner's broadcast or query
//! reaches user modules in other processes. Here the owner starts each rendezvous, so the bridges swap
//! roles: a user module's process serves a service of its own, `PORT/to/MODULE`, and the
//! owner's process relays to it whatever that module's end of the real port receives — a
//! message to reply to, or a query its response handler would answer.

use imrs_ports::transport::PortTransport as _;
use imrs_ports::{
    AnyUser, End, Name, Port, PortSpec, ResponseEnd, Shared, UserList, WireError, usage,
};

use imrs_ports::usage::{Plain, Usage};

use std::sync::{Arc, Mutex};

use crate::bridge::is_served;
use crate::broadcast::{Broadcaster, Inbox, Ticket, Ticketed, Ticketing, Tuned};
use crate::carry::{Carry, lend, lock};
use crate::connect::connect;
use crate::export::attach::{Forward, Refusal};
use crate::export::serving::bridge;
use crate::import::{Relay, SharedAsker, Take, keep_attached, relay};
use crate::{Exported, Imported, IpcError, Remote, Wire};

/// The service a remote user module is served on.
fn to_module(port: &Name, module: &str) -> Name {
    Name::from(format!("{port}/to/{module}"))
}

/// On the owner's side, a remote user module's relay. Users of a `SENDALL` port do not
/// send on it: a request from one is answered with no reply.
struct Relayed {
    /// Relays while held.
    _relay: Relay,
}

impl<Req: Send + 'static, Rep: Send + 'static> Forward<Req, Rep> for Relayed {
    async fn forward(&mut self, _: Req) -> Option<Rep> {
        None
    }
}

/// On a user's side, the local port's owner end: each broadcast from the other process is
/// sent to the one local user, whose reply goes back. A message read in place is shared
/// with that user, not copied ([`Shared`]'s `Clone`).
impl<M: Clone + Send + 'static, R: Default + Send + 'static> Forward<M, R>
    for End<M, R, usage::SendAll>
{
    async fn forward(&mut self, request: M) -> Option<R> {
        self.peer_attached().await;
        let mut broadcast = self.send_all(request).await.ok()?;
        // Taken, not moved: the broadcast lets the other users' requests go when dropped.
        Some(std::mem::take(&mut broadcast.first))
    }
}

/// On a user's side, the local port's owner end: each query from the other process goes
/// to the one local user's response handler, which answers when that module's order says.
impl<M: Clone + Send + 'static, R: Default + Send + 'static> Forward<M, R>
    for End<M, R, usage::CallAll>
{
    async fn forward(&mut self, request: M) -> Option<R> {
        self.peer_attached().await;
        let mut broadcast = self.call_all(request).await.ok()?;
        // Taken, not moved: the broadcast lets the other users' requests go when dropped.
        Some(std::mem::take(&mut broadcast.first))
    }
}

/// Exports `port`, a `SENDALL` port, to the other processes of `remote`'s cell: its owner's
/// broadcasts reach their modules too, each of which answers as a user in this process
/// would. Call it within the tokio runtime the cell runs on.
pub(crate) fn export_send_all<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Req, Rep, usage::SendAll, L, N>,
) -> Result<Exported, IpcError> {
    export_relayed::<Req, Rep, Req, _, _, _, _, _, _, N>(
        remote,
        port,
        |port, module| port.user_named(module),
        None,
    )
}

/// Exports `port`, a `CALLALL` port, to the other processes of `remote`'s cell: its owner's
/// queries reach their modules too, each answered by that module's response handler when
/// its order says, as for a user in this process. Call it within the tokio runtime the cell
/// runs on.
pub(crate) fn export_call_all<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Req, Rep, usage::CallAll, L, N>,
) -> Result<Exported, IpcError> {
    export_relayed::<Req, Rep, Req, _, _, _, _, _, _, N>(remote, port, relayed_responder, None)
}

/// Exports `port`, a `SENDALL` port of messages built in place ([`Shared`]), as
/// [`export_send_all`] does a port of values, sending each broadcast once for every user
/// to read in place. The owner's loans ([`End::loan`]) are samples of shared memory: a
/// broadcast built in one crosses with nothing copied, and every user process reads that
/// one sample where it lies (one built on the heap is copied into a sample once).
/// The user module builds its reply in place ([`Shared::loan_reply`]), which the owner
/// reads where it lies. The sample is let go when every process has dropped its handles.
pub(crate) fn export_send_all_shared<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Shared<Req>, Shared<Rep>, usage::SendAll, L, N>,
) -> Result<Exported, IpcError> {
    export_broadcast::<Req, Rep, _, _, _, N>(remote, port, |port, module| port.user_named(module))
}

/// Exports `port`, a `CALLALL` port of messages built in place ([`Shared`]), as
/// [`export_call_all`] does a port of values, and as [`export_send_all_shared`] carries
/// them: each query sent once, read in place by every remote user's response handler,
/// whose answer, built in place, the owner reads where it lies.
pub(crate) fn export_call_all_shared<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Shared<Req>, Shared<Rep>, usage::CallAll, L, N>,
) -> Result<Exported, IpcError> {
    export_broadcast::<Req, Rep, _, _, _, N>(remote, port, relayed_responder)
}

/// How a remote module's end of the real port is attached.
type UserEnd<M, R, U, L, T, const N: usize> =
    fn(&Port<M, R, U, L, N>, &str) -> Result<T, WireError>;

/// Exports a `SENDALL` or `CALLALL` port of [`Shared`] messages: the owner's loans are
/// samples of the port's publisher, each broadcast is sent once, and a remote module's end
/// (`user_end`) is relayed the broadcast's ticket.
fn export_broadcast<Req, Rep, U, L, T, const N: usize>(
    remote: &Remote,
    port: &Port<Shared<Req>, Shared<Rep>, U, L, N>,
    user_end: UserEnd<Shared<Req>, Shared<Rep>, U, L, T, N>,
) -> Result<Exported, IpcError>
where
    Req: Wire,
    Rep: Wire,
    U: Usage,
    L: UserList,
    T: Take<Shared<Req>, Shared<Rep>>,
{
    let name = Name::from(port);
    let broadcaster = Broadcaster::<Req>::create(remote, &name, N)?;
    // The port's lender and hand outlive an export withdrawn: from then on loans are on the
    // heap, and a broadcast is copied for each user.
    let (lender, handing) = (Arc::downgrade(&broadcaster), Arc::downgrade(&broadcaster));
    let _lends = port
        .clone()
        .lend_with(move || match lender.upgrade() {
            Some(broadcaster) => broadcaster.loan(),
            None => Ok(Shared::default()),
        })
        // A broadcast built on the heap is copied into a sample once, for every user.
        .broadcast_with(move |message| match handing.upgrade() {
            Some(broadcaster) => broadcaster.adopt(message),
            None => message,
        });
    export_relayed::<Req, Rep, Ticket, Ticket, _, _, _, _, _, N>(
        remote,
        port,
        move |port, module| {
            Ok(Ticketing {
                taken: user_end(port, module)?,
                broadcaster: Arc::clone(&broadcaster),
            })
        },
        None,
    )
}

/// The client of the relay to the remote user module attached last: where an owner's loans
/// on a port of [`Shared`] messages come from.
type Lending<Req, Rep> = Arc<Mutex<Option<SharedAsker<Req, Rep>>>>;

/// A remote module's end of a `QUERY` or `CALLALL` port. Its handler never runs: the relay
/// takes each query and answers it with the other process's reply.
fn relayed_responder<M, R, U, L, const N: usize>(
    port: &Port<M, R, U, L, N>,
    module: &str,
) -> Result<ResponseEnd<M, R, ()>, WireError>
where
    M: Send + 'static,
    R: Default + Send + 'static,
    U: usage::Answers,
    L: UserList,
{
    port.answer(module, |_: &(), _: M| R::default())
}

/// Exports `port`, a `QUERY` port (the owner queries its users), to the other processes of
/// `remote`'s cell: the owner's query to a module there waits for that module's response
/// handler, which runs when the module's order says. Call it within the tokio runtime the
/// cell runs on.
pub(crate) fn export_query<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Req, Rep, usage::Query, L, N>,
) -> Result<Exported, IpcError> {
    export_relayed::<Req, Rep, Req, _, _, _, _, _, _, N>(remote, port, relayed_responder, None)
}

/// Exports `port`, a `QUERY` port of messages built in place ([`Shared`]), as
/// [`export_query`] does a port of values. The owner's loans ([`End::loan`]) are samples
/// of shared memory, of the user process attached last (on the heap until one is): a
/// query built there to that user crosses with nothing copied, and one to a user in
/// another process is copied once. The user module's response handler, in its own
/// process, reads the query where it lies and builds its answer in place
/// ([`Shared::loan_reply`]), which the owner reads where it lies.
pub(crate) fn export_query_shared<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Shared<Req>, Shared<Rep>, usage::Query, L, N>,
) -> Result<Exported, IpcError> {
    let lending = Lending::<Req, Rep>::default();
    let (from, name) = (Arc::clone(&lending), Name::from(port));
    let _lends = port.clone().lend_with(move || {
        let client = lock(&from).clone();
        match client {
            Some(client) => lend(&client, &name),
            None => Ok(Shared::default()),
        }
    });
    export_relayed::<Req, Rep, Req, _, _, _, _, _, _, N>(
        remote,
        port,
        relayed_responder,
        Some(lending),
    )
}

/// Exports a port whose owner starts each rendezvous: each remote module attached gets
/// `user_end` of the real port, whose every message or query (carried in the port as `M`)
/// is relayed to its process as `X`, of wire type `W`. The port's own types are `Req` and
/// `Rep` on the wire: what a connecting process is checked against.
fn export_relayed<Req, Rep, W, X, M, R, U, L, T, const N: usize>(
    remote: &Remote,
    port: &Port<M, R, U, L, N>,
    mut user_end: impl FnMut(&Port<M, R, U, L, N>, &str) -> Result<T, WireError> + Send + 'static,
    lending: Option<Lending<W, Rep>>,
) -> Result<Exported, IpcError>
where
    Req: Wire,
    Rep: Wire,
    W: Wire,
    X: Carry<W>,
    M: Send + 'static,
    R: Carry<Rep>,
    U: Usage,
    L: UserList,
    T: Take<X, R>,
{
    let name = Name::from(port);
    let runtime = tokio::runtime::Handle::try_current().map_err(|_| IpcError::Transport {
        port: name.clone(),
        detail: "export it from within the tokio runtime its cell runs on".into(),
    })?;
    let (port, owner, cell) = (port.clone(), port.owner_module().clone(), remote.clone());
    // As for `export`: the relays are tasks on this runtime.
    port.park_waits();
    let served = name.clone();
    // The owner starts each rendezvous here; its relays are parked.
    // Attaching a remote module connects a relay back to its process: a wait of its own,
    // kept off tokio's workers.
    let (exported, _) =
        bridge::<Req, Rep, Req, Rep, _, _>(remote, name, N, true, false, move |module: &str| {
            port.claim(module)?;
            // The relay back is the module's process's service: one that is not there is
            // refused. Its name, if the claim made it, counts among the names the process
            // keeps from peers (`Name::MOST_FROM_PEERS`).
            if !is_served(&cell, &format!("{served}/to/{module}")) {
                return Err(Refusal::Failed);
            }
            // The module's own end of the real port: what it receives goes to its process.
            let end = user_end(&port, module)?;
            let _entered = runtime.enter();
            let (relay, client) =
                relay::<W, Rep, X, R, T>(&cell, &to_module(&served, module), owner.as_str(), end)
                    .map_err(|_| Refusal::Failed)?;
            if let Some(lending) = &lending {
                *lock(lending) = Some(client);
            }
            Ok(Relayed { _relay: relay })
        })?;
    Ok(exported)
}

/// Imports a `SENDALL` port of another process for module `module` of this one: a port of
/// the same name and types, to which `module` attaches and receives the owner's
/// broadcasts as in one process. Connects at once, refused as [`crate::import`] is. Call it
/// within the tokio runtime the cell runs on.
pub(crate) fn import_send_all<Req: Wire, Rep: Wire>(
    remote: &Remote,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<Imported<Req, Rep, usage::SendAll>, IpcError> {
    import_relayed::<Req, Rep, Req, _, _, _, _, _>(remote, port, owner, module, |end| end)
}

/// Imports a `CALLALL` port of another process for module `module` of this one: a port of
/// the same name and types, on which `module` attaches its response handler as in one
/// process; the owner's queries wait for it, and it runs when `module`'s order says.
/// Connects at once, refused as [`crate::import`] is. Call it within the tokio runtime the
/// cell runs on.
pub(crate) fn import_call_all<Req: Wire, Rep: Wire>(
    remote: &Remote,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<Imported<Req, Rep, usage::CallAll>, IpcError> {
    import_relayed::<Req, Rep, Req, _, _, _, _, _>(remote, port, owner, module, |end| end)
}

/// Imports a `SENDALL` port of messages built in place ([`Shared`]), exported with
/// [`export_send_all_shared`], as [`import_send_all`] does a port of values: `module`
/// receives each broadcast where it lies in shared memory, and builds its reply in place
/// ([`Shared::loan_reply`]), which crosses back with nothing copied.
pub(crate) fn import_send_all_shared<Req: Wire, Rep: Wire>(
    remote: &Remote,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<Imported<Shared<Req>, Shared<Rep>, usage::SendAll>, IpcError> {
    import_tuned::<Req, Rep, _>(remote, port, owner, module)
}

/// Imports a `CALLALL` port of messages built in place ([`Shared`]), exported with
/// [`export_call_all_shared`], as [`import_call_all`] does a port of values: `module`'s
/// response handler reads each query where it lies, and builds its answer in place.
pub(crate) fn import_call_all_shared<Req: Wire, Rep: Wire>(
    remote: &Remote,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<Imported<Shared<Req>, Shared<Rep>, usage::CallAll>, IpcError> {
    import_tuned::<Req, Rep, _>(remote, port, owner, module)
}

/// Imports a `QUERY` port of another process for module `module` of this one, which
/// answers the owner's queries with its response handler as in one process, when its order
/// says. Connects at once, refused as [`crate::import`] is. Call it within the tokio
/// runtime the cell runs on.
pub(crate) fn import_query<Req: Wire, Rep: Wire>(
    remote: &Remote,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<Imported<Req, Rep, usage::Query>, IpcError> {
    import_relayed::<Req, Rep, Req, _, _, _, _, _>(remote, port, owner, module, |end| end)
}

/// Imports a `QUERY` port of messages built in place ([`Shared`]), exported with
/// [`export_query_shared`], as [`import_query`] does a port of values: `module`'s response
/// handler reads each query where it lies in shared memory, and builds its answer in place
/// ([`Shared::loan_reply`]), which crosses back with nothing copied.
pub(crate) fn import_query_shared<Req: Wire, Rep: Wire>(
    remote: &Remote,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<Imported<Shared<Req>, Shared<Rep>, usage::Query>, IpcError> {
    import_relayed::<Req, Rep, Req, _, _, _, _, _>(remote, port, owner, module, |end| end)
}

/// Imports a port whose owner starts each rendezvous, for `module`: the port's own types
/// are `Req` and `Rep` on the wire, carried in the local port as `M` and `R`; what its
/// owner's relay sends is `X`, of wire type `W`, which `serve` takes into the local port
/// through its owner end.
fn import_relayed<Req, Rep, W, X, M, R, U, E>(
    remote: &Remote,
    port: &str,
    owner: &str,
    module: &str,
    mut serve: impl FnMut(End<M, R, U>) -> E + Send + 'static,
) -> Result<Imported<M, R, U>, IpcError>
where
    Req: Wire,
    Rep: Wire,
    W: Wire,
    X: Carry<W>,
    M: Send + 'static,
    R: Carry<Rep>,
    U: Usage + Plain,
    E: Forward<X, R>,
{
    let name = Name::from(port);
    let local: Port<M, R, U, AnyUser, 1> =
        Port::new(PortSpec::new(name.clone(), owner).user_list([module]));
    // First the service the owner's process will relay to, so that it is there when the
    // owner answers the connection by relaying.
    let (serving, expected) = (local.clone(), Name::from(owner));
    // Its one user is the owner's relay.
    let (server, _) = bridge::<W, Rep, X, R, _, _>(
        remote,
        to_module(&name, module),
        1,
        false,
        false,
        move |relay_module: &str| {
            if relay_module != expected.as_str() {
                return Err(Refusal::NotOnUserList);
            }
            Ok(serve(serving.owner()?))
        },
    )?;
    // Then the connection, which keeps the module attached on the owner's side, and on
    // the side of an owner started again.
    let connection = connect::<Req, Rep>(remote, &name, module)?;
    Ok(Imported::serving(
        local,
        server,
        keep_attached(connection, module),
    ))
}

/// Imports a `SENDALL` or `CALLALL` port of [`Shared`] messages for `module`: each
/// broadcast is read where the owner wrote it, from this process's subscription.
fn import_tuned<Req, Rep, U>(
    remote: &Remote,
    port: &str,
    owner: &str,
    module: &str,
) -> Result<Imported<Shared<Req>, Shared<Rep>, U>, IpcError>
where
    Req: Wire,
    Rep: Wire,
    U: Usage + Plain,
    End<Shared<Req>, Shared<Rep>, U>: Forward<Shared<Req>, Shared<Rep>>,
{
    // Subscribed before connecting: every broadcast the owner relays to `module` from then
    // on reaches this subscription first.
    let inbox = Arc::new(Mutex::new(Inbox::<Req>::open(remote, &Name::from(port))?));
    import_relayed::<Req, Rep, Ticket, Ticketed, _, _, U, _>(remote, port, owner, module, {
        move |end| Tuned {
            end,
            inbox: Arc::clone(&inbox),
        }
    })
}
