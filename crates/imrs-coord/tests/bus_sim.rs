//! The CSMA/DCR bus simulated slot by slot on the seed's case (a coordinator and nine
//! robots on 100 m), under adversarial arrivals: every station at once, random bursts, and
//! the worst order for the slots (a message that just misses its own slot). Each delay is
//! held against the bound the model gives, and against the seed's `D_max`.

use std::time::Duration;

use imrs_coord::network::{self, Bus, Offer, SEED_CASE, simulate, slot_bound};

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
    let offers = Offer::everyone(SEED_CASE.len(), Duration::ZERO);
    let out = simulate(&bus, &SEED_CASE, bus.slot, &offers).unwrap();
    // One collision, then each station in its slot, in order.
    assert_eq!(out.collisions, 1);
    let order: Vec<usize> = out.deliveries.iter().map(|d| d.offer.station).collect();
    assert_eq!(order, (0..SEED_CASE.len()).collect::<Vec<_>>());
    let worst = out.worst().unwrap().delay();
    let d_max = bus.d_max(&SEED_CASE);
    // The last station waits the collision, its IFS, and every turn but its own trailing
    // IFS: the seed's formula less one IFS.
    assert_eq!(worst, d_max - bus.ifs);
    println!(
        "every station at once: worst {:.1} µs, D_max {:.1} µs",
        micros(worst),
        micros(d_max)
    );
}

/// With 802.3's 51.2 µs slot, a message that just misses its own empty slot waits it out:
/// up to about 45 µs beyond the seed's formula, which leaves room for an IFS there. With a slot as
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

/// A small generator of its own, so that the arrivals are the same on every run.
struct XorShift(u64);

impl XorShift {
    fn below(&mut self, n: u64) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0 % n
    }
}

/// Bursts 1.5 ms apart, longer than any wait: in each, every station sends at most once, at
/// any time within 700 µs of the burst's start, so that messages arrive in the middle of
/// resolution periods, after their own slot and before it. No station sends twice while
/// another message waits, as the bound assumes.
fn bursts(random: &mut XorShift) -> Vec<Offer> {
    let mut offers = Vec::new();
    for burst in 0..4 {
        for station in 0..SEED_CASE.len() {
            if random.below(3) > 0 {
                offers.push(Offer {
                    at: Duration::from_nanos(burst * 1_500_000 + random.below(700_000)),
                    station,
                });
            }
        }
    }
    offers
}

/// Random bursts, with 802.3's slot and a short one: every message is delivered once, and
/// within the model's bound; and some, with 802.3's slot, wait longer than `D_max`, so the
/// arrivals reach the case the bound is for.
#[test]
fn random_bursts_stay_within_the_slot_bound_and_reach_beyond_d_max() {
    let bus = Bus::ieee_802_3(100.0);
    let d_max = bus.d_max(&SEED_CASE);
    let mut random = XorShift(0x9E37_79B9_7F4A_7C15);
    for slot in [bus.slot, short_slot(&bus)] {
        let bound = slot_bound(&bus, &SEED_CASE, slot);
        let (mut worst, mut beyond) = (Duration::ZERO, 0);
        for _ in 0..2_000 {
            let offers = bursts(&mut random);
            let out = simulate(&bus, &SEED_CASE, slot, &offers).unwrap();
            assert_eq!(out.deliveries.len(), offers.len());
            for delivery in &out.deliveries {
                assert!(delivery.delay() <= bound, "{delivery:?} beyond {bound:?}");
                worst = worst.max(delivery.delay());
                beyond += usize::from(delivery.delay() > d_max);
            }
        }
        println!(
            "random bursts, slot {:.1} µs: worst {:.1} µs, {beyond} beyond D_max, bound {:.1} µs",
            micros(slot),
            micros(worst),
            micros(bound)
        );
        if slot == bus.slot {
            assert!(
                beyond > 0,
                "no arrival waited beyond D_max: the test misses the case"
            );
        } else {
            assert_eq!(beyond, 0);
        }
    }
}
