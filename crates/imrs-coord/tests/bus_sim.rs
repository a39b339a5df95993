//! The CSMA/DCR bus simulated slot by slot on the seed's case (a coordinator and nine
//! robots on 100 m), under adversarial arrivals: every station at once, random bursts, and
//! the worst order for the slots (a message that just misses its own slot). Each delay is
//! held against the bound the model gives, and against the seed's `D_max`.

use std::time::Duration;

use imrs_coord::network::{self, Bus, Offer, SEED_CASE, simulate, slot_bound};
use proptest::prelude::*;

fn micros(d: Duration) -> f64 {
    d.as_secs_f64() * 1e6
}

/// The slot the seed says a short bus may use: just over `jam + 2τ`.
fn short_slot(bus: &Bus) -> Duration {
    bus.jam + 2 * bus.propagation + Duration::from_nanos(1)
}

/// The longest wait of the worst order for the slots, over every station and every set
/// of others.
fn worst_missed_slot(bus: &Bus, slot: Duration) -> Duration {
    network::worst_missed_slot(bus, &SEED_CASE, slot)
        .expect("every offer names a station")
        .expect("a message was delivered")
        .delay()
}

#[test]
fn every_station_at_once_is_within_the_seeds_d_max() {
    let bus = Bus::ieee_802_3(100.0);
    let offers: Vec<Offer> = (0..SEED_CASE.len())
        .map(|station| Offer {
            at: Duration::ZERO,
            station,
        })
        .collect();
    let out = simulate(&bus, &SEED_CASE, bus.slot, &offers).unwrap();
    let worst = out.worst().unwrap().delay();
    let d_max = bus.d_max(&SEED_CASE);
    // The last station waits the collision and every turn but its own trailing IFS: the
    // seed's formula less two IFS.
    assert_eq!(worst, d_max - 2 * bus.ifs);
    println!(
        "every station at once: worst {:.1} µs, D_max {:.1} µs",
        micros(worst),
        micros(d_max)
    );
}

/// With 802.3's 51.2 µs slot, a message that just misses its own empty slot waits it out:
/// up to about 35 µs beyond the seed's formula, which counts an IFS there. With a slot as
/// short as the seed says a 100 m bus allows, the formula holds.
#[test]
fn a_message_that_misses_its_own_slot_is_within_the_slot_bound_not_the_formula() {
    let bus = Bus::ieee_802_3(100.0);
    let d_max = bus.d_max(&SEED_CASE);

    let standard = bus.slot;
    let worst = worst_missed_slot(&bus, standard);
    let bound = slot_bound(&bus, &SEED_CASE, standard);
    println!(
        "slot {:.1} µs: worst {:.1} µs, bound {:.1} µs, D_max {:.1} µs",
        micros(standard),
        micros(worst),
        micros(bound),
        micros(d_max)
    );
    assert!(worst <= bound, "{worst:?} beyond {bound:?}");
    assert!(
        worst > d_max,
        "the formula held: {worst:?} within {d_max:?}"
    );
    // The bound is tight to within the two robots' slots the pattern must use.
    assert!(bound - worst < Duration::from_micros(1));

    let short = short_slot(&bus);
    let worst = worst_missed_slot(&bus, short);
    let bound = slot_bound(&bus, &SEED_CASE, short);
    println!(
        "slot {:.1} µs: worst {:.1} µs, bound {:.1} µs, D_max {:.1} µs",
        micros(short),
        micros(worst),
        micros(bound),
        micros(d_max)
    );
    assert!(
        worst <= bound && bound <= d_max,
        "{worst:?} {bound:?} {d_max:?}"
    );
}

/// Bursts 750 µs apart (longer than any wait), each of any stations at once, within a few
/// microseconds: no station sends twice while another message waits, as the bound assumes.
fn bursts() -> impl Strategy<Value = Vec<Offer>> {
    let burst = (
        0u64..50,
        proptest::collection::vec((any::<bool>(), 0u64..5), 10),
    );
    proptest::collection::vec(burst, 1..5).prop_map(|bursts| {
        bursts
            .into_iter()
            .enumerate()
            .flat_map(|(n, (offset, stations))| {
                let start = n as u64 * 750 + offset;
                stations
                    .into_iter()
                    .enumerate()
                    .filter(|(_, (sends, _))| *sends)
                    .map(move |(station, (_, jitter))| Offer {
                        at: Duration::from_micros(start + jitter),
                        station,
                    })
            })
            .collect()
    })
}

/// The bound's assumption, broken: the coordinator sends twice in a row, once alone and
/// once in the resolution period that follows, while a robot's message waits behind both.
#[test]
fn a_station_that_sends_twice_while_another_waits_delays_it_beyond_the_bound() {
    let bus = Bus::ieee_802_3(100.0);
    let slot = bus.slot;
    let offers = [
        Offer {
            at: Duration::ZERO,
            station: 0,
        },
        Offer {
            at: Duration::ZERO,
            station: 0,
        },
        Offer {
            at: Duration::from_micros(1),
            station: 8,
        },
    ];
    let out = simulate(&bus, &SEED_CASE, slot, &offers).unwrap();
    let robot = out
        .deliveries
        .iter()
        .find(|d| d.offer.station == 8)
        .unwrap();
    let bound = slot_bound(&bus, &SEED_CASE, slot);
    println!(
        "twice in a row: the robot waits {:.1} µs, bound {:.1} µs",
        micros(robot.delay()),
        micros(bound)
    );
    assert!(robot.delay() > bound);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    /// Random bursts: every message, waiting from when it is its station's next, is
    /// delivered within the slot bound, and every message offered is delivered once.
    #[test]
    fn random_bursts_stay_within_the_slot_bound(offers in bursts(), short in any::<bool>()) {
        let bus = Bus::ieee_802_3(100.0);
        let slot = if short { short_slot(&bus) } else { bus.slot };
        let out = simulate(&bus, &SEED_CASE, slot, &offers).unwrap();
        prop_assert_eq!(out.deliveries.len(), offers.len());
        let bound = slot_bound(&bus, &SEED_CASE, slot);
        for delivery in &out.deliveries {
            prop_assert!(delivery.delay() <= bound, "{:?} beyond {:?}", delivery, bound);
        }
    }
}
