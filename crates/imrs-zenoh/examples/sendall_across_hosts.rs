//! A broadcast to three hosts, beside raw zenoh in the same run.
//!
//! `cargo run --release -p imrs-zenoh --example sendall_across_hosts -- [--rounds N] [--netns]`
//!
//! This process is the owner's host: it exports ALARM, a `SENDALL` port of `u64`s, and
//! starts three copies of itself as hosts of their own (each in a network namespace of its
//! own, joined to this one by a veth link, with `--netns`, as root), each importing ALARM for a module
//! that answers every broadcast `n` with `n`, and declaring beside it a raw zenoh queryable
//! that does the same work (decode the CDR `u64`, answer it). It then times, in alternating
//! blocks of 500, a `send_all` until all three replies are in, and a raw `get` of the three
//! queryables until all three replies are in, and prints p50 and p99 of each and their
//! ratios.

mod common;

use std::process::Stdio;
use std::time::Instant;

use common::{cdr, command_in, read, rounds, table};
use imrs_ports::{AnyUser, Port, PortSpec, usage};
use imrs_zenoh::netns::Netns;
use imrs_zenoh::{Host, Imported, export, import};
use tokio::io::{AsyncBufReadExt, BufReader};
use zenoh::query::{ConsolidationMode, QueryTarget};

const CELL: &str = "sendall_bench_cell";
const MODULES: [&str; 3] = ["PANEL_1", "PANEL_2", "PANEL_3"];
const BLOCK: usize = 500;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()?;
    if let [flag, endpoint, module] = args.as_slice()
        && flag == "--listen"
    {
        return runtime.block_on(listen(endpoint, module));
    }
    let rounds = rounds(&args, 5_000)?;
    let netns = args.iter().any(|a| a == "--netns");
    runtime.block_on(measure(rounds, netns))
}

/// A listener's host: ALARM imported for `module`, and the raw queryable beside it.
async fn listen(endpoint: &str, module: &str) -> Result<(), Box<dyn std::error::Error>> {
    let host = Host::builder(CELL).connect(endpoint).open().await?;
    let imported: Imported<u64, u64, usage::SendAll> =
        import(&host, "ALARM", "LINE", module).await?;
    let mut panel = imported.port().user_named(module)?;
    tokio::spawn(async move {
        while let Ok((n, reply)) = panel.receive().await {
            let _ = reply.reply(n);
        }
    });
    let key = format!("bench/raw/{module}");
    let raw = host
        .session()
        .declare_queryable(&key)
        .await
        .map_err(|e| e.to_string())?;
    println!("ready");
    while let Ok(query) = raw.recv_async().await {
        let n = query.payload().map_or(0, |p| read(&p.to_bytes()));
        query.reply(&key, cdr(n)).await.map_err(|e| e.to_string())?;
    }
    Ok(())
}

async fn measure(rounds: usize, netns: bool) -> Result<(), Box<dyn std::error::Error>> {
    let namespaces = if netns {
        (0..MODULES.len() as u32)
            .map(|k| Netns::make(k as u8))
            .collect::<Result<Vec<_>, _>>()?
    } else {
        Vec::new()
    };
    let probe = std::net::TcpListener::bind("0.0.0.0:0")?;
    let port = probe.local_addr()?.port();
    drop(probe);
    let host = Host::builder(CELL)
        .listen(format!("tcp/0.0.0.0:{port}"))
        .open()
        .await?;
    let alarm: Port<u64, u64, usage::SendAll, AnyUser, 3> =
        Port::new(PortSpec::new("ALARM", "LINE").user_list(MODULES));
    let _exported = export(&host, &alarm).await?;
    let me = std::env::current_exe()?;
    let mut listeners = Vec::new();
    for (i, module) in MODULES.into_iter().enumerate() {
        // Each listener reaches this host over its own link, or over loopback.
        let netns = namespaces.get(i);
        let address = netns.map_or("127.0.0.1", Netns::outside_address);
        let mut command = command_in(netns, &me);
        let endpoint = format!("tcp/{address}:{port}");
        let mut child = command
            .args(["--listen", &endpoint, module])
            .stdout(Stdio::piped())
            .kill_on_drop(true)
            .spawn()?;
        let mut lines = BufReader::new(child.stdout.take().ok_or("no stdout")?).lines();
        if lines.next_line().await?.as_deref() != Some("ready") {
            return Err(format!("{module}'s host did not start").into());
        }
        listeners.push(child);
    }
    while alarm.users_attached() < MODULES.len() {
        tokio::task::yield_now().await;
    }
    let mut line = alarm.owner()?;
    let session = host.session().clone();
    // Declared once, as IMRS declares each module's `deliver` key.
    let raw_key = session
        .declare_keyexpr("bench/raw/*")
        .await
        .map_err(|e| e.to_string())?;
    let (mut imrs, mut zenoh) = (Vec::with_capacity(rounds), Vec::with_capacity(rounds));
    let mut block = 0;
    while imrs.len() < rounds {
        for n in 1..=BLOCK as u64 {
            let start = Instant::now();
            let mut broadcast = line.send_all(n).await?;
            let mut sum = broadcast.first;
            while let Some((_, reply)) = broadcast.next_reply().await {
                sum += reply;
            }
            let took = start.elapsed();
            assert_eq!(sum, 3 * n);
            if block > 0 {
                imrs.push(took);
            }
        }
        for n in 1..=BLOCK as u64 {
            let start = Instant::now();
            let replies = session
                .get(&raw_key)
                .payload(cdr(n))
                .target(QueryTarget::All)
                .consolidation(ConsolidationMode::None)
                .await
                .map_err(|e| e.to_string())?;
            let mut sum = 0;
            while let Ok(reply) = replies.recv_async().await {
                let sample = reply.into_result().map_err(|e| format!("{e:?}"))?;
                sum += read(&sample.payload().to_bytes());
            }
            let took = start.elapsed();
            assert_eq!(sum, 3 * n);
            if block > 0 {
                zenoh.push(took);
            }
        }
        // The first block of each warms the paths and is not counted.
        block += 1;
    }
    let where_ = if netns {
        "three network namespaces, a veth link each"
    } else {
        "processes, loopback"
    };
    println!(
        "{} broadcasts each, to three hosts ({where_}):\n",
        imrs.len()
    );
    table(
        "IMRS `send_all`, until the three replies",
        &mut imrs,
        "raw zenoh `get` of three queryables, until the three replies",
        &mut zenoh,
    );
    Ok(())
}
