//! A host of its own for the tests across hosts: `zenoh_peer CELL ENDPOINT` listens on
//! ENDPOINT and exports DOUBLE (owned by DOUBLER, a port of `u64`s), answering each `n`
//! with `2n` — except 0, whose reply it holds for ever, so that a test can cut the host
//! off mid-rendezvous. When its user's host is gone, it drops the replies it held and serves
//! the next user that comes. It prints `ready` once the port is exported, and runs until
//! killed.

use std::process::ExitCode;

use imrs_ports::{AnyUser, Port, PortSpec, ReceiveError, usage};
use imrs_zenoh::{Host, export};

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [cell, endpoint] = args.as_slice() else {
        eprintln!("usage: zenoh_peer CELL ENDPOINT");
        return ExitCode::from(2);
    };
    let runtime = match tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
    {
        Ok(runtime) => runtime,
        Err(error) => {
            eprintln!("zenoh_peer: no runtime: {error}");
            return ExitCode::FAILURE;
        }
    };
    match runtime.block_on(serve(cell, endpoint)) {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("zenoh_peer: {error}");
            ExitCode::FAILURE
        }
    }
}

async fn serve(cell: &str, endpoint: &str) -> Result<(), Box<dyn std::error::Error>> {
    let host = Host::builder(cell).listen(endpoint).open().await?;
    let port: Port<u64, u64, usage::Receive, AnyUser, 4> =
        Port::new(PortSpec::new("DOUBLE", "DOUBLER"));
    let _exported = export(&host, &port).await?;
    let mut doubler = port.owner()?;
    println!("ready");
    let mut held = Vec::new();
    loop {
        match doubler.receive().await {
            Ok((0, reply)) => held.push(reply),
            Ok((n, reply)) => {
                let _ = reply.reply(2 * n);
            }
            // Its user's host is gone: it lets go of what it held (a user place is free
            // only once its last request is answered) and serves the next user that comes.
            Err(ReceiveError::PeerGone { .. }) => {
                held.clear();
                doubler.peer_attached().await;
            }
            Err(error) => return Err(error.into()),
        }
    }
}
