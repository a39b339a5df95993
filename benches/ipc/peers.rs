//! The peer processes: this same binary, started again with `IMRS_IPC_BENCH_PEER` set, and
//! what each serves: the IMRS ports it owns and echoes, the raw services, or the `SENDALL`
//! ports it listens to.

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::Duration;

use imrs_ipc::{Imported, IpcError, Remote, Wire, export, import};
use imrs_ports::{AnyUser, Port, PortSpec, ProcessType, Shared, usage};

use crate::raw::{Wait, raw_server, raw_task_server};
use crate::{Large, Small, runtime};

pub(super) const PEER: &str = "IMRS_IPC_BENCH_PEER";

const TIGHT: &str = "IMRS_IPC_BENCH_TIGHT";

/// Set, to the module's name, for a peer that listens to the `SENDALL` ports.
const LISTEN: &str = "IMRS_IPC_BENCH_LISTEN";

/// What a peer serves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Peer {
    /// Both IMRS ports and both raw services, all waiting on events.
    Parked,
    /// One raw service, spinning.
    RawSpinning,
    /// One IMRS port declared TIGHT.
    Tight,
    /// A user of `SENDALL` ports, echoing each broadcast: LISTENER, the one user of four
    /// and one of the two users of two more; or LISTENER_2, the other of those two.
    Listener(&'static str),
}

/// Starts a peer for `cell` serving `what`, and waits until it serves.
pub(super) fn start_peer(cell: &str, what: Peer) -> std::process::Child {
    let mut command = Command::new(std::env::current_exe().expect("this binary"));
    command.env(PEER, cell).stdout(Stdio::piped());
    match what {
        Peer::Parked => {}
        Peer::RawSpinning => {
            command.env(TIGHT, "raw");
        }
        Peer::Tight => {
            command.env(TIGHT, "imrs");
        }
        Peer::Listener(module) => {
            command.env(LISTEN, module);
        }
    }
    let mut child = command.spawn().expect("the peer starts");
    let mut line = String::new();
    BufReader::new(child.stdout.take().expect("piped"))
        .read_line(&mut line)
        .expect("the peer speaks");
    assert_eq!(line.trim(), "ready", "the peer failed: {line}");
    child
}

/// The peer: owns both IMRS ports (echoing), and serves both raw services; or serves one
/// spinning raw service; or owns one TIGHT IMRS port.
pub(super) fn peer(cell: &str) {
    let what = match std::env::var(TIGHT).as_deref() {
        Ok("raw") => Peer::RawSpinning,
        Ok(_) => Peer::Tight,
        Err(_) => match std::env::var(LISTEN).as_deref() {
            Ok("LISTENER") => Peer::Listener("LISTENER"),
            Ok(_) => Peer::Listener("LISTENER_2"),
            Err(_) => Peer::Parked,
        },
    };
    let raw: &[&str] = match what {
        Peer::Parked => &["small", "large", "small-one-id"],
        Peer::RawSpinning => &["small"],
        Peer::Tight | Peer::Listener(_) => &[],
    };
    let wait = if what == Peer::RawSpinning {
        Wait::Spin
    } else {
        Wait::Events
    };
    for part in raw {
        let (cell, part) = (cell.to_owned(), *part);
        std::thread::spawn(move || match part {
            "large" => raw_server::<Large>(&cell, part, wait),
            _ => raw_server::<Small>(&cell, part, wait),
        });
    }
    let runtime = runtime();
    runtime.block_on(async {
        let remote = Remote::new(cell).expect("a cell name");
        if what == Peer::Parked {
            tokio::spawn(raw_task_server(cell.to_owned()));
        }
        let _echoes = match what {
            Peer::Parked => vec![
                echo::<Small>(&remote, "SMALL", ProcessType::Indep),
                echo::<Large>(&remote, "LARGE", ProcessType::Indep),
                loaned_echo::<Small>(&remote, "SMALL_LOANED"),
                loaned_echo::<Large>(&remote, "LARGE_LOANED"),
            ],
            Peer::RawSpinning => Vec::new(),
            Peer::Tight => vec![echo::<Small>(&remote, "SMALL", ProcessType::Tight)],
            Peer::Listener("LISTENER") => vec![
                listen::<Small>(&remote, "NEWS_SMALL"),
                listen::<Large>(&remote, "NEWS_LARGE"),
                loaned_listen::<Small>(&remote, "NEWS_SMALL_LOANED", "LISTENER"),
                loaned_listen::<Large>(&remote, "NEWS_LARGE_LOANED", "LISTENER"),
                loaned_listen::<Small>(&remote, "PAIR_SMALL", "LISTENER"),
                loaned_listen::<Large>(&remote, "PAIR_LARGE", "LISTENER"),
            ],
            Peer::Listener(module) => vec![
                loaned_listen::<Small>(&remote, "PAIR_SMALL", module),
                loaned_listen::<Large>(&remote, "PAIR_LARGE", module),
            ],
        };
        // Give the raw servers a moment to open their services.
        tokio::time::sleep(Duration::from_millis(200)).await;
        println!("ready");
        // It serves until it is killed.
        std::future::pending::<()>().await;
    });
}

fn echo<T: Wire>(
    remote: &Remote,
    name: &str,
    process_type: ProcessType,
) -> tokio::task::JoinHandle<()> {
    let port: Port<T, T, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new(name, "ECHO").process_type(process_type));
    let exported = export(remote, &port).expect("exported");
    let mut owner = port.owner().expect("the owner's end");
    tokio::spawn(async move {
        let _exported = exported;
        while let Ok((message, reply)) = owner.receive().await {
            reply.reply(message);
        }
    })
}

/// The one user of `SENDALL` port `name` (owner CAMERA), LISTENER, answering each
/// broadcast with itself.
fn listen<T: Wire>(remote: &Remote, name: &str) -> tokio::task::JoinHandle<()> {
    echo_broadcasts(
        import::<Imported<T, T, usage::SendAll>, _>(remote, name, "CAMERA", "LISTENER"),
        "LISTENER",
    )
}

/// The same for `module`, a user of a port of messages built in place: each read where it
/// lies, and answered with itself, copied once into the reply's sample.
fn loaned_listen<T: Wire>(
    remote: &Remote,
    name: &str,
    module: &str,
) -> tokio::task::JoinHandle<()> {
    echo_broadcasts(
        import::<Imported<Shared<T>, Shared<T>, usage::SendAll>, _>(remote, name, "CAMERA", module),
        module,
    )
}

/// Answers each broadcast on `imported` with itself, as its user `module`.
fn echo_broadcasts<M: Send + 'static>(
    imported: Result<Imported<M, M, usage::SendAll>, IpcError>,
    module: &str,
) -> tokio::task::JoinHandle<()> {
    let imported = imported.expect("imported");
    let mut listener = imported.port().user_named(module).expect("the user's end");
    tokio::spawn(async move {
        let _imported = imported;
        while let Ok((message, reply)) = listener.receive().await {
            reply.reply(message);
        }
    })
}

/// An echo of messages built in place: each read where its sender built it, and answered
/// with itself, copied once into the reply's sample.
fn loaned_echo<T: Wire>(remote: &Remote, name: &str) -> tokio::task::JoinHandle<()> {
    let port: Port<Shared<T>, Shared<T>, usage::Receive, AnyUser, 1> =
        Port::new(PortSpec::new(name, "ECHO"));
    let exported = export(remote, &port).expect("exported");
    let mut owner = port.owner().expect("the owner's end");
    tokio::spawn(async move {
        let _exported = exported;
        while let Ok((message, reply)) = owner.receive().await {
            reply.reply(message);
        }
    })
}
