//! The owner's side: a port exported to other processes. A bridge thread waits on
//! iceoryx2's request events; each request goes into the real port as a send from the
//! remote module's own end, on tokio, and its reply goes back through shared memory.

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::thread::JoinHandle;

use iceoryx2::active_request::ActiveRequest;
use iceoryx2::port::notifier::Notifier;
use imrs_core::imrs_ports::{End, Name, Port, UserList, WireError, usage};

use crate::bridge::{Channel, Svc, TICK};
use crate::wire::{
    CONNECT, MALFORMED, NO_REPLY, NOT_ON_USER_LIST, OK, REFUSED, ReplyMeta, RequestMeta, SEND,
    TOO_MANY_USERS,
};
use crate::{IpcError, Remote, Wire};

type Active<Req, Rep> = ActiveRequest<Svc, Req, RequestMeta, Rep, ReplyMeta>;
type UserEnd<Req, Rep> = Arc<tokio::sync::Mutex<End<Req, Rep, usage::Send>>>;

/// A port exported to other processes: served while this is held, withdrawn when dropped.
pub struct Exported {
    port: Name,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl Exported {
    /// The port.
    pub fn port(&self) -> &Name {
        &self.port
    }
}

impl Drop for Exported {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Release);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// Exports `port` (a port its owner receives on) to the other processes of `remote`'s
/// cell. Call it within the tokio runtime the cell runs on: the remote users' sends run
/// there. Refused if another process already exports the port, or if the processes
/// disagree on its types.
pub fn export<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Req, Rep, usage::Receive, L, N>,
) -> Result<Exported, IpcError> {
    let name = Name::from(port);
    let runtime = tokio::runtime::Handle::try_current().map_err(|_| IpcError::Transport {
        port: name.clone(),
        detail: "export it from within the tokio runtime its cell runs on".into(),
    })?;
    let channel = Channel::<Req, Rep>::open(remote, &name)?;
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
    let notifier = Arc::new(Mutex::new(channel.notifier(&channel.replied)?));
    let stop = Arc::new(AtomicBool::new(false));
    let (port, halt) = (port.clone(), Arc::clone(&stop));
    let thread = std::thread::Builder::new()
        .name(format!("imrs-ipc {name}"))
        .spawn(move || {
            // The channel lives as long as the thread: its node keeps the services open.
            let _channel = channel;
            let mut users: HashMap<String, UserEnd<Req, Rep>> = HashMap::new();
            while !halt.load(Ordering::Acquire) {
                // Blocks until a request event or the tick: no polling of the data.
                if listener.timed_wait(|_| {}, TICK).is_err() {
                    break;
                }
                loop {
                    match server.receive() {
                        Ok(Some(active)) => take(active, &port, &mut users, &runtime, &notifier),
                        Ok(None) => break,
                        // A connection iceoryx2 could not make yet: the next wake-up retries.
                        Err(_) => break,
                    }
                }
            }
        })
        .map_err(|error| IpcError::Transport {
            port: name.clone(),
            detail: format!("starting its bridge thread: {error}"),
        })?;
    Ok(Exported {
        port: name,
        stop,
        thread: Some(thread),
    })
}

/// One request from another process.
fn take<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    active: Active<Req, Rep>,
    port: &Port<Req, Rep, usage::Receive, L, N>,
    users: &mut HashMap<String, UserEnd<Req, Rep>>,
    runtime: &tokio::runtime::Handle,
    notifier: &Arc<Mutex<Notifier<Svc>>>,
) {
    let meta = *active.user_header();
    // A header a peer wrote garbage into is refused; the bridge goes on serving.
    let Some(module) = meta.module().map(str::to_owned) else {
        respond(active, MALFORMED, 0, Rep::default(), notifier);
        return;
    };
    match meta.kind {
        CONNECT => match attach(port, users, &module) {
            Ok(_) => respond(active, OK, 0, Rep::default(), notifier),
            Err((status, detail)) => respond(active, status, detail, Rep::default(), notifier),
        },
        SEND => {
            // A module this copy of the owner has not seen yet — the owner was restarted
            // since the module connected — is attached now, as at its connection.
            let end = match attach(port, users, &module) {
                Ok(end) => end,
                Err((status, detail)) => {
                    respond(active, status, detail, Rep::default(), notifier);
                    return;
                }
            };
            let request = *active.payload();
            let notifier = Arc::clone(notifier);
            // Each send waits on tokio, so that several remote modules' sends are pending at
            // once and the owner's order decides which it takes.
            runtime.spawn(async move {
                let result = end.lock().await.send(request).await;
                match result {
                    Ok(reply) => respond(active, OK, 0, reply, &notifier),
                    Err(_) => respond(active, NO_REPLY, 0, Rep::default(), &notifier),
                }
            });
        }
        _ => respond(active, MALFORMED, 0, Rep::default(), notifier),
    }
}

/// The end of remote module `module`, attached at its first request; or the status of
/// the port's refusal.
fn attach<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    port: &Port<Req, Rep, usage::Receive, L, N>,
    users: &mut HashMap<String, UserEnd<Req, Rep>>,
    module: &str,
) -> Result<UserEnd<Req, Rep>, (u32, u32)> {
    if let Some(end) = users.get(module) {
        return Ok(Arc::clone(end));
    }
    match port.user_named(module) {
        Ok(end) => {
            let end = Arc::new(tokio::sync::Mutex::new(end));
            users.insert(module.to_owned(), Arc::clone(&end));
            Ok(end)
        }
        Err(WireError::NotOnUserList { .. }) => Err((NOT_ON_USER_LIST, 0)),
        Err(WireError::TooManyUsers { capacity, .. }) => {
            Err((TOO_MANY_USERS, u32::try_from(capacity).unwrap_or(u32::MAX)))
        }
        Err(_) => Err((REFUSED, 0)),
    }
}

/// Replies through shared memory, then wakes the users' bridges.
fn respond<Req: Wire, Rep: Wire>(
    active: Active<Req, Rep>,
    status: u32,
    detail: u32,
    reply: Rep,
    notifier: &Mutex<Notifier<Svc>>,
) {
    if let Ok(mut response) = active.loan_uninit() {
        *response.user_header_mut() = ReplyMeta { status, detail };
        // A user that died meanwhile cannot be answered; nothing else is lost.
        let _ = response.write_payload(reply).send();
    }
    let _ = notifier
        .lock()
        .unwrap_or_else(PoisonError::into_inner)
        .notify();
}
