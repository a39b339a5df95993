//! A rendezvous across hosts, beside raw zenoh in the same run.
//!
//! `cargo run --release -p imrs-zenoh --example rendezvous_across_hosts -- [--rounds N] [--netns]`
//!
//! The program starts a copy of itself as the owner's host (in a network namespace of its
//! own with `--netns`, as root), which exports DOUBLE (a port of `u64`s whose owner
//! replies `2n`) and declares a raw zenoh queryable that does the same work: it decodes the
//! CDR `u64` and answers `2n` in CDR. This host then times, in alternating blocks of 1,000,
//! a module's `send` on the imported port and a raw `get` of the queryable, each awaited on
//! the same multi-thread tokio runtime, and prints p50 and p99 of each and their ratios.

mod common;

use std::process::Stdio;
use std::time::Instant;

use common::{cdr, command_in, read, rounds, table};
use imrs_ports::{AnyUser, Port, PortSpec, usage};
use imrs_zenoh::netns::Netns;
use imrs_zenoh::{Host, Imported, export, import};
use tokio::io::{AsyncBufReadExt, BufReader};

const CELL: &str = "bench_cell";
const RAW: &str = "bench/raw/DOUBLE";
const BLOCK: usize = 1_000;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()?;
    if let [flag, endpoint] = args.as_slice()
        && flag == "--serve"
    {
        return runtime.block_on(serve(endpoint));
    }
    let rounds = rounds(&args, 20_000)?;
    let netns = args.iter().any(|a| a == "--netns");
    runtime.block_on(measure(rounds, netns))
}

/// The owner's host: DOUBLE on IMRS, and the raw queryable beside it.
async fn serve(endpoint: &str) -> Result<(), Box<dyn std::error::Error>> {
    let host = Host::builder(CELL).listen(endpoint).open().await?;
    let port: Port<u64, u64, usage::Receive, AnyUser, 2> =
        Port::new(PortSpec::new("DOUBLE", "DOUBLER"));
    let _exported = export(&host, &port).await?;
    let mut doubler = port.owner()?;
    tokio::spawn(async move {
        while let Ok((n, reply)) = doubler.receive().await {
            reply.reply(2 * n);
        }
    });
    let raw = host
        .session()
        .declare_queryable(RAW)
        .await
        .map_err(|e| e.to_string())?;
    println!("ready");
    while let Ok(query) = raw.recv_async().await {
        let n = query.payload().map_or(0, |p| read(&p.to_bytes()));
        query
            .reply(RAW, cdr(2 * n))
            .await
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

async fn measure(rounds: usize, netns: bool) -> Result<(), Box<dyn std::error::Error>> {
    let namespace = netns.then(|| Netns::make(0)).transpose()?;
    let endpoint = match &namespace {
        Some(ns) => format!("tcp/{}:7447", ns.inside_address()),
        None => {
            let probe = std::net::TcpListener::bind("127.0.0.1:0")?;
            format!("tcp/127.0.0.1:{}", probe.local_addr()?.port())
        }
    };
    let me = std::env::current_exe()?;
    let mut command = command_in(namespace.as_ref(), &me);
    let mut owner = command
        .args(["--serve", &endpoint])
        .stdout(Stdio::piped())
        .kill_on_drop(true)
        .spawn()?;
    let mut lines = BufReader::new(owner.stdout.take().ok_or("no stdout")?).lines();
    if lines.next_line().await?.as_deref() != Some("ready") {
        return Err("the owner's host did not start".into());
    }
    let host = Host::builder(CELL).connect(&endpoint).open().await?;
    let imported: Imported<u64, u64, usage::Receive> =
        import(&host, "DOUBLE", "DOUBLER", "ASKER").await?;
    let mut asker = imported.port().user_named("ASKER")?;
    let session = host.session().clone();
    // Declared once, as IMRS declares each request's key: the wire carries a number.
    let raw_key = session
        .declare_keyexpr(RAW)
        .await
        .map_err(|e| e.to_string())?;
    let raw = |n: u64| {
        let (session, raw_key) = (session.clone(), raw_key.clone());
        async move {
            let replies = session
                .get(&raw_key)
                .payload(cdr(n))
                .await
                .map_err(|e| e.to_string())?;
            let reply = replies.recv_async().await.map_err(|e| e.to_string())?;
            let sample = reply.into_result().map_err(|e| format!("{e:?}"))?;
            Ok::<u64, String>(read(&sample.payload().to_bytes()))
        }
    };
    let (mut imrs, mut zenoh) = (Vec::with_capacity(rounds), Vec::with_capacity(rounds));
    // Warm both paths, then alternate blocks so that drift in the machine hits both alike.
    for n in 1..=BLOCK as u64 {
        assert_eq!(asker.send(n).await?, 2 * n);
        assert_eq!(raw(n).await?, 2 * n);
    }
    while imrs.len() < rounds {
        for n in 1..=BLOCK as u64 {
            let start = Instant::now();
            let doubled = asker.send(n).await?;
            imrs.push(start.elapsed());
            assert_eq!(doubled, 2 * n);
        }
        for n in 1..=BLOCK as u64 {
            let start = Instant::now();
            let doubled = raw(n).await?;
            zenoh.push(start.elapsed());
            assert_eq!(doubled, 2 * n);
        }
    }
    let where_ = if netns {
        "two network namespaces, a veth link"
    } else {
        "two processes, loopback"
    };
    println!("{} round trips each, {where_}:\n", imrs.len());
    table(
        "IMRS `send` on an imported port",
        &mut imrs,
        "raw zenoh `get` of a queryable",
        &mut zenoh,
    );
    owner.start_kill()?;
    Ok(())
}
