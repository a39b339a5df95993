//! Each port's worst-case delay, once a cell's modules are placed on stations.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::time::Duration;

use imrs_ports::{Name, PortInfo};

use super::Bus;

/// What a packet adds to its message, as the seed counts it: one byte of message type and
/// 26 bytes of frame (preamble, addresses, length, checksum).
const PACKET_OVERHEAD: usize = 1 + 26;

/// Which station (processor on the bus) each module runs on.
#[derive(Debug, Clone, Default)]
pub struct Placement {
    stations: BTreeMap<Name, u32>,
}

impl Placement {
    /// No module placed yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Places `module` on `station`.
    pub fn place(mut self, module: impl Into<Name>, station: u32) -> Self {
        self.stations.insert(module.into(), station);
        self
    }

    fn station(&self, port: &Name, module: &Name) -> Result<u32, PlacementError> {
        self.stations
            .get(module)
            .copied()
            .ok_or_else(|| PlacementError {
                port: port.clone(),
                module: module.clone(),
            })
    }
}

/// A port names a module that was not placed on any station.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PlacementError {
    /// The port.
    pub port: Name,
    /// The module with no station.
    pub module: Name,
}

impl fmt::Display for PlacementError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "port {} names module {}, which is placed on no station",
            self.port, self.module
        )
    }
}

impl std::error::Error for PlacementError {}

/// One port's worst case on the bus.
#[derive(Debug, Clone, PartialEq)]
pub struct PortBound {
    /// The port.
    pub port: Name,
    /// The stations its owner and users are on.
    pub stations: BTreeSet<u32>,
    /// The longest a message on it waits for the bus: behind the packet that may already
    /// sit in its station's FIFO, then its own turn. Zero if it never leaves a station.
    pub one_way: Duration,
    /// A request and its reply.
    pub round_trip: Duration,
    /// The port's `TIMEOUT`.
    pub timeout: Option<Duration>,
}

impl PortBound {
    /// Whether the port's timeout is shorter than its worst round trip: a rendezvous that
    /// the network alone can make time out.
    pub fn timeout_too_short(&self) -> bool {
        self.timeout
            .is_some_and(|timeout| timeout < self.round_trip)
    }
}

impl fmt::Display for PortBound {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let micros = |d: Duration| d.as_secs_f64() * 1e6;
        write!(
            f,
            "{:<20} stations {:<12} one way {:>8.1} µs  round trip {:>8.1} µs",
            self.port.as_str(),
            format!("{:?}", self.stations),
            micros(self.one_way),
            micros(self.round_trip),
        )?;
        match self.timeout {
            Some(timeout) if self.timeout_too_short() => write!(
                f,
                "  WARNING: TIMEOUT {:.1} µs is below the worst round trip",
                micros(timeout)
            ),
            Some(timeout) => write!(f, "  TIMEOUT {:.1} µs", micros(timeout)),
            None => Ok(()),
        }
    }
}

/// Every port's worst case on `bus`, with the cell's modules placed by `placement`.
///
/// A port's users are those on its user list; a port with none may be used by any placed
/// module, and is judged as if it were. Each station's longest packet is the longest
/// message (request or reply, plus `PACKET_OVERHEAD`) of the ports that leave it; a
/// station with none still takes its turn in a resolution period, with an empty packet.
pub fn report(
    ports: &[PortInfo],
    placement: &Placement,
    bus: &Bus,
) -> Result<Vec<PortBound>, PlacementError> {
    let mut spans = Vec::new();
    let mut longest: BTreeMap<u32, usize> = placement
        .stations
        .values()
        .map(|&station| (station, 0))
        .collect();
    for port in ports {
        let mut stations = BTreeSet::from([placement.station(&port.name, &port.owner)?]);
        match &port.user_list {
            Some(users) => {
                for user in users {
                    stations.insert(placement.station(&port.name, user)?);
                }
            }
            None => stations.extend(placement.stations.values().copied()),
        }
        if stations.len() > 1 {
            let bytes = port.request_size.max(port.reply_size) + PACKET_OVERHEAD;
            for station in &stations {
                let entry = longest.entry(*station).or_default();
                *entry = (*entry).max(bytes);
            }
        }
        spans.push((port, stations));
    }
    let wait = bus.worst_wait(&longest.values().copied().collect::<Vec<_>>());
    Ok(spans
        .into_iter()
        .map(|(port, stations)| {
            // Behind at most the packet already in its station's FIFO, then its own turn:
            // `TransmitQueue::worst_wait` with nothing else queued.
            let one_way = if stations.len() > 1 {
                2 * wait
            } else {
                Duration::ZERO
            };
            PortBound {
                port: port.name.clone(),
                stations,
                one_way,
                round_trip: 2 * one_way,
                timeout: port.owner_timeout,
            }
        })
        .collect())
}
