//! Where the lines' hosts are, over zenoh, and the world's side of what carries the ports.

use super::lines::Heard;
use super::*;

#[cfg(feature = "zenoh")]
pub(super) use imrs_zenoh::netns::Netns;

/// A line's network namespace, of which a build without the `zenoh` feature has none: no
/// value of it can be made, so the code that would start a line inside one never runs.
#[cfg(not(feature = "zenoh"))]
#[derive(Debug)]
pub(super) enum Netns {}

#[cfg(not(feature = "zenoh"))]
impl Netns {
    pub(super) fn command(&self, _program: impl AsRef<std::ffi::OsStr>) -> Command {
        match *self {}
    }
}

/// Over zenoh, where the lines' hosts are: a network namespace each, joined to the world's
/// by a veth link, or (where namespaces cannot be made) this host's loopback.
pub(super) struct Hosts {
    /// Per line: its namespace, if made.
    pub(super) netns: Vec<Netns>,
    /// Per line: the world's endpoint as the line reaches it.
    pub(super) endpoints: [String; 2],
    /// How the report names them.
    pub(super) described: String,
}

/// The world's side of what carries the ports: iceoryx2 under the cell's name, or a zenoh
/// host listening for the lines' hosts.
pub(super) async fn world_carrier(
    config: &CellConfig,
    cell: &str,
) -> Result<(Carrier, Option<Hosts>), RunError> {
    match config.transport {
        Transport::Ipc => Ok((
            Carrier::Ipc(Remote::new(cell).map_err(carried("world"))?),
            None,
        )),
        #[cfg(not(feature = "zenoh"))]
        Transport::Zenoh => Err(refused(
            "world",
            crate::cli::not_built("--transport zenoh", "zenoh"),
        )),
        #[cfg(feature = "zenoh")]
        Transport::Zenoh => {
            let netns = Netns::make(0).and_then(|a| Ok(vec![a, Netns::make(1)?]));
            // The world listens only where its lines reach it: on each namespace's link, or
            // on loopback. A port found free may be taken before it is listened on: another
            // is tried.
            let mut tries = 0;
            loop {
                tries += 1;
                let port = free_port()?;
                let addresses: Vec<&str> = match &netns {
                    Ok(netns) => netns.iter().map(Netns::outside_address).collect(),
                    Err(_) => vec!["127.0.0.1"],
                };
                let mut builder = Host::builder(cell);
                for address in &addresses {
                    builder = builder.listen(format!("tcp/{address}:{port}"));
                }
                match builder.open().await {
                    Ok(host) => return Ok((Carrier::Zenoh(host), Some(hosts(netns, port)))),
                    Err(error) if tries >= 3 => return Err(refused("world", error)),
                    Err(_) => {}
                }
            }
        }
    }
}

/// A port of this host free now.
#[cfg(feature = "zenoh")]
fn free_port() -> Result<u16, RunError> {
    let probe = std::net::TcpListener::bind("0.0.0.0:0")
        .map_err(|error| refused("world", format!("no free port: {error}")))?;
    Ok(probe
        .local_addr()
        .map_err(|error| refused("world", error))?
        .port())
}

/// The lines' hosts: in `netns`, or on loopback (said loudly) where they could not be
/// made; the world listening on `port`.
#[cfg(feature = "zenoh")]
fn hosts(netns: Result<Vec<Netns>, String>, port: u16) -> Hosts {
    match netns {
        Ok(netns) => Hosts {
            endpoints: [0, 1].map(|i| format!("tcp/{}:{port}", netns[i].outside_address())),
            netns,
            described: "each a host of its own (a network namespace, joined to the \
                                world's by a veth link)"
                .into(),
        },
        Err(why) => {
            eprintln!(
                "\n*** HOSTS ON LOOPBACK, NOT APART: network namespaces could not be \
                         made ({why}); the lines run as processes of this host, over zenoh \
                         on 127.0.0.1 ***\n"
            );
            Hosts {
                netns: Vec::new(),
                endpoints: [0, 1].map(|_| format!("tcp/127.0.0.1:{port}")),
                described: format!(
                    "ON LOOPBACK, not hosts apart (network namespaces could not be \
                             made: {why})"
                ),
            }
        }
    }
}

/// Over zenoh, a watch of each line's host: one cut off is told as `UNSEEN`, as if its
/// process died. The watches end when their tasks are aborted.
#[cfg(feature = "zenoh")]
pub(super) async fn watch_hosts(
    carrier: &Carrier,
    exported: &[Exported],
    tell: &UnboundedSender<Heard>,
) -> Result<Vec<tokio::task::JoinHandle<()>>, RunError> {
    use super::lines::UNSEEN;

    let mut watchers = Vec::new();
    if !matches!(carrier, Carrier::Zenoh(_)) {
        return Ok(watchers);
    }
    for line in Line::ALL {
        let gate = Device::Gate(line);
        let exported_gate = exported
            .iter()
            .find_map(|exported| match exported {
                Exported::Zenoh(exported) if exported.port() == gate.port() => Some(exported),
                _ => None,
            })
            .ok_or_else(|| refused("world", format!("port {} is not exported", gate.port())))?;
        let mut watch = exported_gate
            .watch_user(&gate.user())
            .await
            .map_err(carried("world"))?;
        let tell = tell.clone();
        watchers.push(tokio::spawn(async move {
            loop {
                watch.gone().await;
                if tell.send((line, UNSEEN, Said::Unseen)).is_err() {
                    return;
                }
            }
        }));
    }
    Ok(watchers)
}

/// Without the `zenoh` feature every line is a process of this host: no host to watch.
#[cfg(not(feature = "zenoh"))]
pub(super) async fn watch_hosts(
    _carrier: &Carrier,
    _exported: &[Exported],
    _tell: &UnboundedSender<Heard>,
) -> Result<Vec<tokio::task::JoinHandle<()>>, RunError> {
    Ok(Vec::new())
}
