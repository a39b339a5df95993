//! The CSMA/DCR bus simulated slot by slot, to measure the delays that [`Bus::d_max`] is
//! meant to bound, and to find where it does not.
//!
//! The model is the seed's ("Communications", Figure 5), with 802.3's timing:
//!
//! - A station with a message transmits as soon as the bus has been idle for `IFS`
//!   (1-persistent carrier sense). A station that becomes ready within `τ` of another's start
//!   has not yet heard it, and transmits too.
//! - One transmitter: its packet is on the wire for `X/R`, and has reached every station `τ`
//!   later; the bus is idle from then.
//! - Two or more: a collision. All stations sense the bus idle `γ + τ` after it began, and
//!   wait `IFS` more.
//! - Then a resolution period: one slot per station, in the stations' order. A station
//!   with a message ready at the start of its slot transmits its oldest, and the slot lasts
//!   its turn, `X/R + τ + IFS`; an empty slot lasts the bus's slot time. After the last slot
//!   the bus is idle, and the stations contend again.
//!
//! A message's delay runs from the moment it is its station's next to send (offered, and
//! every earlier message of its station sent) to the moment its packet has reached every
//! station: the wait [`Bus::d_max`] is meant to bound. Messages that queue behind their
//! station's earlier ones wait in its transmit queue as well
//! ([`TransmitQueue`](super::TransmitQueue)). Times saturate at `Duration::MAX`.

use std::collections::VecDeque;
use std::time::Duration;

use super::Bus;

/// A message a station has ready to send at `at`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub struct Offer {
    /// When the station has it ready.
    pub at: Duration,
    /// The station, an index into the stations' packet lengths.
    pub station: usize,
}

impl Offer {
    /// One message from each of `stations` stations, all ready at `at`: the seed's
    /// "every station at once".
    pub fn everyone(stations: usize, at: Duration) -> Vec<Offer> {
        (0..stations).map(|station| Offer { at, station }).collect()
    }
}

/// What the simulation measured of one message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Delivery {
    /// The message, as offered.
    pub offer: Offer,
    /// When it was its station's next to send: offered, and the station's earlier
    /// messages delivered.
    pub next: Duration,
    /// When its packet had reached every station.
    pub delivered: Duration,
}

impl Delivery {
    /// From its station's next to delivered.
    pub fn delay(&self) -> Duration {
        self.delivered - self.next
    }
}

/// How a simulated bus spent its time, beside the deliveries.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Simulated {
    /// Every message, in the order their packets went on the wire.
    pub deliveries: Vec<Delivery>,
    /// Collisions, each followed by a resolution period.
    pub collisions: usize,
    /// Slots of resolution periods that no station used.
    pub empty_slots: usize,
}

impl Simulated {
    /// The longest delay of any message, if any was sent.
    pub fn worst(&self) -> Option<Delivery> {
        self.deliveries.iter().copied().max_by_key(Delivery::delay)
    }
}

/// An offer named a station the bus does not have.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NoStation {
    /// The offer.
    pub offer: Offer,
    /// How many stations the bus has.
    pub stations: usize,
}

impl std::fmt::Display for NoStation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "a message offered at {:?} by station {}, on a bus of {} stations (0 to {})",
            self.offer.at,
            self.offer.station,
            self.stations,
            self.stations.saturating_sub(1)
        )
    }
}

impl std::error::Error for NoStation {}

type Incoming = std::iter::Peekable<std::vec::IntoIter<Offer>>;

/// Moves the messages ready by `until` into their stations' queues.
fn arrive(incoming: &mut Incoming, until: Duration, pending: &mut [VecDeque<Duration>]) {
    while let Some(offer) = incoming.next_if(|offer| offer.at <= until) {
        pending[offer.station].push_back(offer.at);
    }
}

/// Simulates `bus` with stations whose packets are `packets` bytes long (one per station,
/// as [`Bus::d_max`] takes them), an empty slot lasting `slot`, carrying `offers` (in any
/// order). An offer that names no station is refused, by its station, before anything runs.
pub fn simulate(
    bus: &Bus,
    packets: &[usize],
    slot: Duration,
    offers: &[Offer],
) -> Result<Simulated, NoStation> {
    if let Some(&offer) = offers.iter().find(|offer| offer.station >= packets.len()) {
        return Err(NoStation {
            offer,
            stations: packets.len(),
        });
    }
    let mut offers = offers.to_vec();
    offers.sort();
    let mut incoming: Incoming = offers.into_iter().peekable();
    let mut pending: Vec<VecDeque<Duration>> = vec![VecDeque::new(); packets.len()];
    let mut out = Simulated::default();
    let mut last = vec![Duration::ZERO; packets.len()];
    let mut deliver = |out: &mut Simulated, at: Duration, station: usize, delivered: Duration| {
        out.deliveries.push(Delivery {
            offer: Offer { at, station },
            next: at.max(last[station]),
            delivered,
        });
        last[station] = delivered;
    };
    // The bus is idle, and may be taken, from `free` on.
    let mut free = Duration::ZERO;
    loop {
        arrive(&mut incoming, free, &mut pending);
        // The first transmission starts with the oldest ready message, once the bus is free.
        let oldest = pending
            .iter()
            .filter_map(|queue| queue.front().copied())
            .min();
        let start = match (oldest, incoming.peek()) {
            (Some(at), _) => at.max(free),
            (None, Some(next)) => next.at.max(free),
            (None, None) => break,
        };
        // Everyone ready before they could hear it transmits too.
        let deaf = start.saturating_add(bus.propagation);
        arrive(&mut incoming, deaf, &mut pending);
        let contenders: Vec<usize> = (0..packets.len())
            .filter(|&station| pending[station].front().is_some_and(|&at| at <= deaf))
            .collect();
        if let [station] = contenders[..] {
            let at = pending[station]
                .pop_front()
                .expect("a contender has a message");
            let delivered = start
                .saturating_add(bus.transmission(packets[station]))
                .saturating_add(bus.propagation);
            deliver(&mut out, at, station, delivered);
            free = delivered.saturating_add(bus.ifs);
            continue;
        }
        // A collision, then one slot per station in order.
        out.collisions += 1;
        let mut slot_start = start
            .saturating_add(bus.gamma())
            .saturating_add(bus.propagation)
            .saturating_add(bus.ifs);
        for (station, &bytes) in packets.iter().enumerate() {
            arrive(&mut incoming, slot_start, &mut pending);
            match pending[station].front().copied() {
                Some(at) if at <= slot_start => {
                    pending[station].pop_front();
                    let delivered = slot_start
                        .saturating_add(bus.transmission(bytes))
                        .saturating_add(bus.propagation);
                    deliver(&mut out, at, station, delivered);
                    slot_start = delivered.saturating_add(bus.ifs);
                }
                _ => {
                    out.empty_slots += 1;
                    slot_start = slot_start.saturating_add(slot);
                }
            }
        }
        free = slot_start;
    }
    Ok(out)
}

/// A bound on every message's delay under this model, where [`Bus::d_max`] is not one.
///
/// The seed's formula counts one turn per station, its own included, and one `IFS` (here,
/// after the collision). But a message that becomes its station's next just after the
/// station's own slot began, empty, waits that slot out (up to `slot`), where the formula's
/// own turn leaves room for an `IFS` only; then every other station's slot, whichever period
/// it falls in; then the collision and its `IFS`; then its own packet. Each other station's
/// share is the longer of its turn and an empty slot. So, for the worst station `k`:
///
/// ```text
/// B = max_k [ max(slot, IFS) + Σ_{j≠k} max(turn_j, slot) + γ + τ + IFS + X_k/R + τ ]
/// ```
///
/// Where an empty slot is no longer than `IFS` and no turn is shorter than a slot, this is
/// [`Bus::d_max`]; with 802.3's 51.2 µs slot time it is more.
///
/// Like the seed's formula, it holds for traffic in which no station sends more than one
/// message while another message waits (the seed's robots send one position per sampling
/// period, about 1 ms). A station that sends twice in that time, once alone and once in the
/// resolution period that follows, counts twice, and the wait can exceed the bound.
pub fn slot_bound(bus: &Bus, packets: &[usize], slot: Duration) -> Duration {
    let share = |bytes: usize| bus.turn(bytes).max(slot);
    let all: Duration = packets.iter().map(|&bytes| share(bytes)).sum();
    packets
        .iter()
        .map(|&bytes| {
            slot.max(bus.ifs)
                + (all - share(bytes))
                + bus.gamma()
                + bus.propagation
                + bus.ifs
                + bus.transmission(bytes)
                + bus.propagation
        })
        .max()
        .unwrap_or_default()
}

/// The worst order for the slots: station `k`'s message becomes its next just after its own
/// slot began, empty, in a resolution period, while the stations of `others` send once in
/// that period and once in the next, each no more than once while `k`'s message waits.
pub fn missed_slot(
    bus: &Bus,
    packets: &[usize],
    slot: Duration,
    k: usize,
    others: &[usize],
) -> Vec<Offer> {
    let share = |i: usize| {
        if others.contains(&i) {
            packets.get(i).map_or(slot, |&bytes| bus.turn(bytes))
        } else {
            slot
        }
    };
    let slot_start = bus.gamma() + bus.propagation + bus.ifs + (0..k).map(share).sum::<Duration>();
    let mut offers = vec![Offer {
        at: slot_start + Duration::from_nanos(1),
        station: k,
    }];
    for &station in others {
        for at in [Duration::ZERO, slot_start + Duration::from_nanos(2)] {
            offers.push(Offer { at, station });
        }
    }
    offers
}

/// The most stations [`worst_missed_slot`] searches: it runs 2^N patterns a station.
pub const MAX_SEARCHED: usize = 16;

/// The longest wait [`missed_slot`] gives, over every station and every set of two or more
/// others, with the pattern's delivery. A bus of more than [`MAX_SEARCHED`] stations is
/// refused, naming its last station, which is past the search.
pub fn worst_missed_slot(
    bus: &Bus,
    packets: &[usize],
    slot: Duration,
) -> Result<Option<Delivery>, NoStation> {
    let n = packets.len();
    if n > MAX_SEARCHED {
        return Err(NoStation {
            offer: Offer {
                at: Duration::ZERO,
                station: n - 1,
            },
            stations: MAX_SEARCHED,
        });
    }
    let mut worst: Option<Delivery> = None;
    for k in 0..n {
        for mask in 0u64..(1 << n) {
            let others: Vec<usize> = (0..n).filter(|&i| i != k && mask & (1 << i) != 0).collect();
            if others.len() < 2 || mask & (1 << k) != 0 {
                continue;
            }
            let out = simulate(
                bus,
                packets,
                slot,
                &missed_slot(bus, packets, slot, k, &others),
            )?;
            let mine = out
                .deliveries
                .iter()
                .find(|d| d.offer.station == k)
                .copied();
            if let Some(mine) = mine
                && worst.is_none_or(|w| mine.delay() > w.delay())
            {
                worst = Some(mine);
            }
        }
    }
    Ok(worst)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::network::SEED_CASE;

    #[test]
    fn a_lone_message_goes_at_once() {
        let bus = Bus::ieee_802_3(100.0);
        let offer = Offer {
            at: Duration::from_micros(5),
            station: 3,
        };
        let out = simulate(&bus, &SEED_CASE, bus.slot, &[offer]).unwrap();
        assert_eq!(out.collisions, 0);
        let delay = out.deliveries[0].delay();
        assert_eq!(delay, bus.transmission(51) + bus.propagation);
    }

    #[test]
    fn an_offer_naming_no_station_is_refused_by_it() {
        let bus = Bus::ieee_802_3(100.0);
        let offer = Offer {
            at: Duration::ZERO,
            station: 7,
        };
        let refused = simulate(&bus, &[51, 51], bus.slot, &[offer]).unwrap_err();
        assert_eq!(refused, NoStation { offer, stations: 2 });
        assert!(
            refused
                .to_string()
                .contains("station 7, on a bus of 2 stations")
        );
    }
}
