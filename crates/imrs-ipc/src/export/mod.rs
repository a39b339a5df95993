//! The owner's side: a port exported to other processes. The bridge, woken by iceoryx2's
//! request events, takes each request into the real port from the remote module's own end
//! — a send, or a query its owner's order answers — and, woken again when the reply comes,
//! sends it back through shared memory. It does so where it is woken ([`crate::dispatch`]):
//! in the reactor's thread as the request comes, in the module's as it answers. On a TIGHT
//! port the owner's spinning receive does the same in its turns.
//!
//! The functions that export a port are here; the handle that keeps it exported is in
//! `exported`; a remote module's end of the real port, and why one is refused, in `attach`;
//! and the bridge that serves the requests in `serving`.

pub(crate) mod attach;
pub(crate) mod exported;
pub(crate) mod serving;

use imrs_ports::transport::{EndTransport as _, PortTransport as _};
use imrs_ports::usage::{Plain, Usage};
use imrs_ports::{End, Name, Port, ProcessType, Shared, UserList, usage};

use self::attach::Forward;
use self::exported::Exported;
use self::serving::bridge;
use crate::carry::Carry;
use crate::turn::Turn;
use crate::{IpcError, Remote, Wire};

/// Exports `port` (a port its owner receives on) to the other processes of `remote`'s
/// cell: their modules' sends arrive at its owner's `receive`. Call it within the tokio
/// runtime the cell runs on: the remote users' sends run there. Refused if another process
/// already exports the port, or if the processes disagree on its types.
pub(crate) fn export<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Req, Rep, usage::Receive, L, N>,
) -> Result<Exported, IpcError> {
    export_port::<Req, Rep, _, _, _, _, N>(remote, port)
}

/// Exports `port`, a port of messages built in place ([`Shared`]), as [`export`] does a
/// port of values: a remote module's request is read where its sender built it, in shared
/// memory, with nothing copied on the way. The owner's reply, built in a loan made for the
/// request ([`Shared::loan_reply`]), crosses back the same way; one built on the heap is
/// copied once into its sample.
pub(crate) fn export_shared<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Shared<Req>, Shared<Rep>, usage::Receive, L, N>,
) -> Result<Exported, IpcError> {
    export_port::<Req, Rep, _, _, _, _, N>(remote, port)
}

/// Exports `port` (a `RESPONSE` port) to the other processes of `remote`'s cell: their
/// modules' queries wait for its owner's response handler, which runs when the owner's
/// order says, as for a query from its own process.
pub(crate) fn export_response<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Req, Rep, usage::Response, L, N>,
) -> Result<Exported, IpcError> {
    export_port::<Req, Rep, _, _, _, _, N>(remote, port)
}

/// Exports `port`, a `RESPONSE` port of messages built in place ([`Shared`]), as
/// [`export_response`] does a port of values: a remote module's query is read in place by
/// the owner's response handler, which runs when the owner's order says and can build its
/// answer in place too ([`Shared::loan_reply`]).
pub(crate) fn export_response_shared<Req: Wire, Rep: Wire, L: UserList, const N: usize>(
    remote: &Remote,
    port: &Port<Shared<Req>, Shared<Rep>, usage::Response, L, N>,
) -> Result<Exported, IpcError> {
    export_port::<Req, Rep, _, _, _, _, N>(remote, port)
}

/// Exports `port`, whose remote users' requests (wire type `Req`, carried in the port as
/// `M`) go in through each remote module's own end. On a TIGHT port the owner's spinning
/// waits also do the bridge's work, in the owner's thread.
fn export_port<Req, Rep, M, R, U, L, const N: usize>(
    remote: &Remote,
    port: &Port<M, R, U, L, N>,
) -> Result<Exported, IpcError>
where
    Req: Wire,
    Rep: Wire,
    M: Carry<Req>,
    R: Carry<Rep>,
    U: Usage,
    U::Complement: Plain,
    L: UserList,
    End<M, R, U::Complement>: Forward<M, R>,
{
    let tight = port.process_type() == ProcessType::Tight;
    let attached = port.clone();
    let (exported, side) = bridge::<Req, Rep, M, R, _, _>(
        remote,
        Name::from(port),
        N,
        false,
        tight,
        move |module: &str| {
            // Refused by its name's text before the name is made: see `Port::claim`.
            let module = attached.claim(module)?;
            // The remote module's end waits in the bridge's task, which a spinning wait
            // would keep off its worker: it parks, whatever the port's process type.
            let mut end = attached.user_named(module)?;
            end.park_waits();
            Ok(end)
        },
    )?;
    if tight {
        port.pump_with(Turn(side));
    }
    Ok(exported)
}

#[cfg(test)]
mod tests {
    use std::pin::{Pin, pin};
    use std::task::Poll;

    use imrs_ports::{AnyUser, PortSpec};

    use super::*;
    use crate::connect::connect;
    use crate::wire::{RequestMeta, SEND};
    use crate::{FromBytes, ZeroCopySend};

    #[derive(Debug, Clone, Copy, Default, PartialEq, ZeroCopySend, FromBytes)]
    #[repr(C)]
    #[type_name("imrs_ipc_unit::Number")]
    struct Number {
        value: u64,
    }

    /// Polls `future` once, without yielding: a spinning wait's one poll.
    async fn poll_once<F: Future + Unpin>(future: &mut F) -> Poll<F::Output> {
        std::future::poll_fn(|cx| Poll::Ready(Pin::new(&mut *future).poll(cx))).await
    }

    #[test]
    fn a_spinning_owner_takes_a_waiting_request_at_its_first_poll_however_many_came_before() {
        // One thread: the bridge's task cannot run while the owner's task spins, so every
        // request must go in through the owner's own turns.
        let runtime = tokio::runtime::Builder::new_current_thread()
            .enable_all()
            .build()
            .unwrap();
        runtime.block_on(async {
            let remote = Remote::new(&format!("unit-turns-{}", std::process::id())).unwrap();
            let port: Port<Number, Number, usage::Receive, AnyUser, 1> =
                Port::new(PortSpec::new("DOUBLE", "DOUBLER").process_type(ProcessType::Tight));
            let _exported = export(&remote, &port).unwrap();
            let mut owner = port.owner().unwrap();
            // The handshake waits for the bridge's task, which runs on this thread meanwhile.
            let connection = tokio::task::spawn_blocking({
                let remote = remote.clone();
                move || connect::<Number, Number>(&remote, &Name::from("DOUBLE"), "ASKER")
            })
            .await
            .unwrap()
            .unwrap();
            let ask = |value: u64| {
                let mut loan = connection.client.loan_uninit().unwrap();
                *loan.user_header_mut() = RequestMeta::new(SEND, "ASKER");
                loan.write_payload(Number { value }).send().unwrap()
            };
            // All in one poll of this task, as a module that never waits long: more requests
            // than tokio's budget for one poll (128), each sent with no wake-up, so that only
            // the owner's spinning receive can take it.
            let mut answered = None;
            for value in 1..=400 {
                let pending = ask(value);
                let mut receive = pin!(owner.receive());
                let Poll::Ready(Ok((request, reply))) = poll_once(&mut receive).await else {
                    panic!("request {value} waited in shared memory past the owner's spin");
                };
                assert_eq!(request.value, value);
                reply.reply(Number { value: 2 * value });
                // The turn that took this request sent the reply to the one before.
                if let Some((value, pending)) = answered.replace((value, pending)) {
                    let response = pending.receive().unwrap().expect("the reply was sent");
                    assert_eq!(response.payload().value, 2 * value);
                }
            }
            // The last reply goes at the next wait's first turn.
            let mut receive = pin!(owner.receive());
            assert!(poll_once(&mut receive).await.is_pending());
            let (value, pending) = answered.unwrap();
            let response = pending.receive().unwrap().expect("the reply was sent");
            assert_eq!(response.payload().value, 2 * value);
        });
    }
}
