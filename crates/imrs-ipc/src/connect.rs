//! A user process's connection to a port's owner: the services opened as a client, and the
//! handshake by which the owner attaches a module or refuses it by name. Apart from the
//! import's bridge, since more than an imported port connects so: the relays back to a
//! module's process, and the owner's side, tested against a bare connection.

use std::time::{Duration, Instant};

use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use imrs_ports::{Name, WireError};

use crate::bridge::{Channel, Side, Svc, TICK};
use crate::carry::{Asker, Pending};
use crate::wire::{
    CONNECT, NOT_ON_USER_LIST, OK, REFUSED, ReplyMeta, RequestMeta, TIGHT, TOO_MANY_NAMES,
    TOO_MANY_USERS,
};
use crate::{IpcError, Remote, Wire};

/// How long the owner may take to accept the connection.
const CONNECT_TIMEOUT: Duration = Duration::from_secs(5);

/// A user process's connection to a port's owner: the services, the client, and the
/// event ports to wait for replies and to wake the owner.
pub(crate) struct Connection<Req: Wire, Rep: Wire> {
    pub(crate) channel: Channel<Req, Rep>,
    pub(crate) client: Asker<Req, Rep>,
    pub(crate) listener: Listener<Svc>,
    pub(crate) wake_owner: Notifier<Svc>,
    /// Whether the owner declared the port TIGHT: its sends spin, and so may the owner.
    pub(crate) tight: bool,
}

/// Opens port `name` of `remote` as a client and connects as module `module`: the owner
/// attaches it to its port, or refuses it by name.
pub(crate) fn connect<Req: Wire, Rep: Wire>(
    remote: &Remote,
    name: &Name,
    module: &str,
) -> Result<Connection<Req, Rep>, IpcError> {
    let channel = Channel::<Req, Rep>::open(remote, name, Side::User)?;
    let client =
        channel
            .service
            .client_builder()
            .create()
            .map_err(|error| IpcError::Transport {
                port: name.clone(),
                detail: format!("no room for another process ({error:?})"),
            })?;
    let listener = channel.listener(&channel.replied)?;
    let wake_owner = channel.notifier(&channel.requested)?;
    let tight = handshake(&client, &listener, &wake_owner, name, module)?;
    Ok(Connection {
        channel,
        client,
        listener,
        wake_owner,
        tight,
    })
}

/// Sends `module`'s connection request; its answer is to come.
pub(crate) fn ask_connect<Req: Wire, Rep: Wire>(
    client: &Asker<Req, Rep>,
    module: &str,
) -> Option<Pending<Req, Rep>> {
    let mut loan = client.loan_uninit().ok()?;
    *loan.user_header_mut() = RequestMeta::new(CONNECT, module);
    loan.write_payload(Req::default()).send().ok()
}

/// The handshake: the owner attaches `module` to its port, and says how the port waits; or
/// refuses it by name.
fn handshake<Req: Wire, Rep: Wire>(
    client: &Asker<Req, Rep>,
    listener: &Listener<Svc>,
    wake_owner: &Notifier<Svc>,
    port: &Name,
    module: &str,
) -> Result<bool, IpcError> {
    let transport = |detail: String| IpcError::Transport {
        port: port.clone(),
        detail,
    };
    let pending = ask_connect(client, module)
        .ok_or_else(|| transport("connecting: no room to send the request".into()))?;
    let _ = wake_owner.notify();
    let deadline = Instant::now() + CONNECT_TIMEOUT;
    while Instant::now() < deadline {
        if let Ok(Some(response)) = pending.receive() {
            return answered(*response.user_header(), port, module);
        }
        let _ = listener.timed_wait(|_| {}, TICK);
        let _ = wake_owner.notify();
    }
    Err(IpcError::NoOwner { port: port.clone() })
}

/// What the owner's answer to a connection says, as its header reads: whether the port is
/// TIGHT, or why the module was refused. A status the owner should not have written is a
/// transport error that names it.
pub(crate) fn answered(meta: ReplyMeta, port: &Name, module: &str) -> Result<bool, IpcError> {
    let transport = |detail: String| IpcError::Transport {
        port: port.clone(),
        detail,
    };
    let (port, module) = (port.clone(), Name::from(module));
    match meta.status {
        OK => Ok(meta.detail == TIGHT),
        NOT_ON_USER_LIST => Err(IpcError::Refused(WireError::NotOnUserList { port, module })),
        TOO_MANY_USERS => Err(IpcError::Refused(WireError::TooManyUsers {
            port,
            module,
            capacity: meta.detail as usize,
        })),
        TOO_MANY_NAMES => Err(transport(format!(
            "the owner's process keeps {} module names its peers made already and refused \
             {module}: give port {port} a user list",
            meta.detail
        ))),
        REFUSED => Err(transport(format!("the owner refused {module}"))),
        status => Err(transport(format!("the owner answered status {status}"))),
    }
}
