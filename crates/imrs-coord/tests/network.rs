//! The network bound: the seed's formula and case, the non-preemptive transmit queue, and a
//! report on a cell's ports once its modules are placed on stations.

use std::time::Duration;

use imrs_coord::network::{Bus, Placement, SEED_CASE, SEED_D_MAX, TransmitQueue, report};
use imrs_core::prelude::*;
use proptest::prelude::*;

fn micros(d: Duration) -> f64 {
    d.as_secs_f64() * 1e6
}

/// The seed's second formula, term by term, with its own numbers: a trajectory packet
/// (148 B), nine position packets (51 B), 10 Mb/s, 802.3's IFS and jam, 100 m of coax.
#[test]
fn the_seed_case_is_the_seed_formula_and_within_one_percent_of_604_us() {
    let bus = Bus::ieee_802_3(100.0);
    let tau = 100.0 / (0.77 * 299_792_458.0) * 1e6; // µs
    let (ifs, jam, eps) = (9.6, 3.2, 0.9);
    let gamma = 2.0 * tau + jam + eps;
    let by_hand = (148.0 * 8.0 / 10.0 + tau + ifs)
        + 9.0 * (51.0 * 8.0 / 10.0 + tau + ifs)
        + ifs
        + gamma
        + tau;
    let d = micros(bus.d_max(&SEED_CASE));
    assert!((d - by_hand).abs() < 0.01, "{d} µs against {by_hand} µs");
    let off = (d - micros(SEED_D_MAX)) / micros(SEED_D_MAX);
    assert!(
        off.abs() < 0.01,
        "{d:.1} µs is {:.2} % off the seed's 604 µs",
        off * 100.0
    );
    // 802.3 pads a 51-byte packet to its minimum frame: the bound grows by 9 × 21 bytes.
    let padded = micros(bus.padded().d_max(&SEED_CASE));
    assert!((padded - d - 9.0 * 21.0 * 0.8).abs() < 0.01);
}

#[test]
fn with_equal_packets_it_is_the_seeds_first_formula() {
    let bus = Bus::ieee_802_3(250.0);
    for stations in 1..=12 {
        let x = 100;
        let n = stations as u32;
        let expected = n * (bus.transmission(x) + bus.propagation + bus.ifs)
            + bus.ifs
            + bus.gamma()
            + bus.propagation;
        assert_eq!(bus.d_max(&vec![x; stations]), expected);
    }
    assert_eq!(bus.d_max(&[]), Duration::ZERO);
}

proptest! {
    /// More stations, longer packets or a longer bus never shorten the bound.
    #[test]
    fn the_bound_grows_with_stations_packets_and_length(
        packets in proptest::collection::vec(1usize..1500, 1..20),
        extra in 1usize..1500,
        length in 1.0f64..2500.0,
    ) {
        let bus = Bus::ieee_802_3(length);
        let d = bus.d_max(&packets);
        let mut more = packets.clone();
        more.push(extra);
        prop_assert!(bus.d_max(&more) > d);
        let mut longer = packets.clone();
        longer[0] += extra;
        prop_assert!(bus.d_max(&longer) > d);
        prop_assert!(Bus::ieee_802_3(length + 10.0).d_max(&packets) > d);
    }

    /// The queue serves the most urgent first, FIFO within a priority, never displaces the
    /// loaded packet, and a packet waits behind no more than what `ahead_of` counted when it
    /// came, plus the more urgent packets that came after it.
    #[test]
    fn the_transmit_queue_is_priority_ordered_and_non_preemptive(
        ops in proptest::collection::vec(prop_oneof![(1u32..4).prop_map(Some), Just(None)], 1..200),
    ) {
        let mut queue = TransmitQueue::new();
        // For each packet: its priority, what was ahead of it, when it came.
        let mut packets: Vec<(u32, usize, usize)> = Vec::new();
        // Each transmission: which packet, when.
        let mut sent: Vec<(usize, usize)> = Vec::new();
        // The model: the loaded packet, then the rest by priority number, then arrival.
        let mut model_loaded: Option<usize> = None;
        let mut model_waiting: Vec<usize> = Vec::new();
        for (t, op) in ops.into_iter().enumerate() {
            match op {
                Some(p) => {
                    let ahead = queue.ahead_of(Priority::declared(p));
                    queue.push(Priority::declared(p), packets.len());
                    packets.push((p, ahead, t));
                    let id = packets.len() - 1;
                    if model_loaded.is_none() {
                        model_loaded = Some(id);
                    } else {
                        model_waiting.push(id);
                        model_waiting.sort_by_key(|&other| (packets[other].0, other));
                    }
                }
                None => {
                    let queued = queue.len();
                    let id = queue.transmit();
                    prop_assert_eq!(id, model_loaded, "not the packet that was loaded");
                    model_loaded = (!model_waiting.is_empty()).then(|| model_waiting.remove(0));
                    if let Some(id) = id {
                        sent.push((id, t));
                    }
                    prop_assert_eq!(queue.len(), queued.saturating_sub(1));
                }
            }
        }
        for &(id, at) in &sent {
            let (p, ahead, came) = packets[id];
            let behind: Vec<usize> = sent
                .iter()
                .filter(|&&(_, t)| t > came && t < at)
                .map(|&(other, _)| other)
                .collect();
            let overtakers = behind
                .iter()
                .filter(|&&other| packets[other].2 > came && packets[other].0 < p)
                .count();
            prop_assert!(
                behind.len() <= ahead + overtakers,
                "packet {} (priority {}) waited behind {} packets; {} were ahead, {} overtook",
                id, p, behind.len(), ahead, overtakers
            );
            // FIFO within a priority: no earlier packet of its priority goes after it.
            for &(other, t) in &sent {
                prop_assert!(!(packets[other].0 == p && other < id && t > at));
            }
        }
    }
}

#[test]
fn the_most_urgent_message_waits_two_periods_at_most_whatever_is_queued() {
    let d = Duration::from_micros(600);
    let mut queue = TransmitQueue::new();
    for _ in 0..5 {
        queue.push(Priority::declared(3), "routine");
    }
    assert_eq!(queue.worst_wait(Priority::declared(1), d), 2 * d);
    queue.push(Priority::declared(1), "stop");
    assert_eq!(
        queue.transmit(),
        Some("routine"),
        "the loaded packet was displaced"
    );
    assert_eq!(queue.transmit(), Some("stop"));
    assert_eq!(queue.worst_wait(Priority::declared(3), d), 5 * d);
}

/// A cell of a coordinator and two robots on three stations: every port that crosses
/// stations gets its bound; a port whose TIMEOUT is below its round trip is flagged; a
/// module on no station is named.
#[test]
fn a_placed_cell_gets_each_ports_worst_case_and_a_warning_for_short_timeouts() {
    let (cell, _clock) = Cell::virtual_clock();
    let _grant: Port<[f32; 30], u8, usage::Send> = cell
        .port(
            PortSpec::new("ZONE_GRANT", "COORDINATOR")
                .user_list(["ROBOT_1", "ROBOT_2"])
                .owner_timeout(Duration::from_millis(10)),
        )
        .unwrap();
    let _stop: Port<u8, (), usage::Send> = cell
        .port(
            PortSpec::new("EMERGENCY_STOP", "COORDINATOR")
                .user_list(["ROBOT_1", "ROBOT_2"])
                .priority(1)
                .owner_timeout(Duration::from_micros(900)),
        )
        .unwrap();
    let _local: Port<u32, u32, usage::Query> = cell
        .port(PortSpec::new("GRIPPER", "ROBOT_1").user_list(["ROBOT_1_HAND"]))
        .unwrap();
    let placement = Placement::new()
        .place("COORDINATOR", 0)
        .place("ROBOT_1", 1)
        .place("ROBOT_1_HAND", 1)
        .place("ROBOT_2", 2);
    let bus = Bus::ieee_802_3(100.0);
    let rows = report(&cell.ports(), &placement, &bus).unwrap();
    let row = |name: &str| rows.iter().find(|r| r.port == name).unwrap();

    // Three stations; the longest packets: 120 + 27 bytes for each, as ZONE_GRANT reaches all.
    // Each waits for the bus at most the simulated model's bound, which with 802.3's slot is
    // beyond the seed's formula (a message may miss its own empty slot).
    let wait = bus.worst_wait(&[147, 147, 147]);
    assert!(wait > bus.d_max(&[147, 147, 147]));
    assert_eq!(row("ZONE_GRANT").one_way, 2 * wait);
    assert_eq!(row("ZONE_GRANT").round_trip, 4 * wait);
    assert!(!row("ZONE_GRANT").timeout_too_short());
    assert!(row("EMERGENCY_STOP").timeout_too_short());
    assert!(row("EMERGENCY_STOP").to_string().contains("WARNING"));
    assert_eq!(
        row("GRIPPER").one_way,
        Duration::ZERO,
        "a port inside one station"
    );

    let error = report(
        &cell.ports(),
        &Placement::new().place("COORDINATOR", 0),
        &bus,
    )
    .unwrap_err();
    assert_eq!(
        error.to_string(),
        "port EMERGENCY_STOP names module ROBOT_1, which is placed on no station"
    );
}
