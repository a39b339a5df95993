//! The seed's worst case: ten stations (a coordinator and nine robots) on a 100 m bus, the
//! coordinator's longest packet a five-point trajectory (148 B), each robot's a position
//! (51 B). Prints `D_max` with IEEE 802.3's 10 Mb/s parameters, each parameter and its
//! source, and the difference from the 604 µs the seed reports; what each unstated parameter
//! would have to be, alone, to account for that difference; then the variants the seed
//! suggests; then the bus simulated slot by slot under the worst arrivals found. Run:
//! `cargo run --release --example network_bound`.

use std::time::Duration;

use imrs_coord::network::{
    Bus, Offer, SEED_CASE, SEED_D_MAX, simulate, slot_bound, worst_missed_slot,
};

fn us(d: Duration) -> f64 {
    d.as_secs_f64() * 1e6
}

fn main() {
    let bus = Bus::ieee_802_3(100.0);
    println!("IEEE 802.3, 10 Mb/s, 100 m of coax:");
    println!("  R    = {:>7.1} Mb/s  (10BASE5)", bus.rate / 1e6);
    println!(
        "  IFS  = {:>7.3} µs    (interFrameGap, 96 bit times)",
        us(bus.ifs)
    );
    println!("  jam  = {:>7.3} µs    (jamSize, 32 bits)", us(bus.jam));
    println!(
        "  τ    = {:>7.3} µs    (100 m at 0.77 c, 10BASE5 coax)",
        us(bus.propagation)
    );
    println!(
        "  ε    = {:>7.3} µs    (10BASE5 MAU collision signalling budget)",
        us(bus.detection)
    );
    println!("  γ    = {:>7.3} µs    (2τ + jam + ε)", us(bus.gamma()));
    println!(
        "stations: X_t = {} B, then {} × X_p = {} B",
        SEED_CASE[0],
        SEED_CASE.len() - 1,
        SEED_CASE[1]
    );
    let d = bus.d_max(&SEED_CASE);
    let seed = SEED_D_MAX;
    println!(
        "D_max = {:.1} µs; the seed: {:.0} µs; difference {:+.1} µs ({:+.2} %)",
        us(d),
        us(seed),
        us(d) - us(seed),
        (us(d) - us(seed)) / us(seed) * 100.0
    );
    // D_max is linear in each parameter: what each would have to be, alone, to make 604.
    let gap = us(seed) - us(d);
    let n = SEED_CASE.len() as f64;
    let bits: f64 = SEED_CASE.iter().map(|&bytes| bytes as f64 * 8.0).sum();
    println!(
        "each parameter alone, as it would have to be for {:.0} µs:",
        us(seed)
    );
    println!(
        "  ε    × 1         : {:.2} µs instead of {:.2}",
        us(bus.detection) + gap,
        us(bus.detection)
    );
    println!(
        "  jam  × 1         : {:.2} µs instead of {:.2}",
        us(bus.jam) + gap,
        us(bus.jam)
    );
    let tau = us(bus.propagation) + gap / (n + 3.0);
    println!(
        "  τ    × {:<2}        : {:.3} µs instead of {:.3} (100 m at {:.2} c)",
        n + 3.0,
        tau,
        us(bus.propagation),
        100.0 / (tau * 1e-6) / 299_792_458.0
    );
    println!(
        "  IFS  × {:<2}        : {:.2} µs instead of {:.2}",
        n + 1.0,
        us(bus.ifs) + gap / (n + 1.0),
        us(bus.ifs)
    );
    println!(
        "  R    ({} bits)  : {:.3} Mb/s instead of {:.1}",
        bits,
        bits / (bits / bus.rate * 1e6 + gap),
        bus.rate / 1e6
    );
    println!(
        "  bytes a packet   : {:.2} more each, where a whole byte adds {:.1} µs",
        gap / (n * 8.0 / bus.rate * 1e6),
        n * 8.0 / bus.rate * 1e6
    );
    let floor: f64 = SEED_CASE
        .iter()
        .map(|&bytes| us(bus.turn(bytes)).max(us(bus.slot)))
        .sum::<f64>()
        + us(bus.ifs + bus.gamma() + bus.propagation);
    println!(
        "  or every turn at least one slot time ({:.1} µs, so each robot's {:.1} µs turn \
         counts {:.1}): {:.1} µs",
        us(bus.slot),
        us(bus.turn(SEED_CASE[1])),
        us(bus.slot),
        floor
    );
    let padded = bus.padded().d_max(&SEED_CASE);
    println!(
        "with 802.3's minimum frame (X_p padded to 72 B): D_max = {:.1} µs ({:+.1} % of 604)",
        us(padded),
        (us(padded) - us(seed)) / us(seed) * 100.0
    );
    let faster = Bus {
        rate: 20e6,
        ifs: Duration::from_nanos(3_200),
        ..bus
    };
    println!(
        "the seed's non-standard parameters (20 Mb/s, IFS 3.2 µs): D_max = {:.1} µs",
        us(faster.d_max(&SEED_CASE))
    );
    println!(
        "the most urgent message, behind one packet already in its station's FIFO: at most \
         2 × D_max = {:.1} µs",
        us(2 * d)
    );

    println!("simulated slot by slot (each station sending once while another waits):");
    let everyone = Offer::everyone(SEED_CASE.len(), Duration::ZERO);
    let all = simulate(&bus, &SEED_CASE, bus.slot, &everyone).expect("ten stations");
    let worst = all.worst().expect("ten messages");
    println!(
        "  every station at once: the last waits {:.1} µs ({:.1} µs below D_max)",
        us(worst.delay()),
        us(d) - us(worst.delay())
    );
    let short = bus.jam + 2 * bus.propagation + Duration::from_nanos(1);
    for (what, slot) in [
        ("802.3's slot time", bus.slot),
        ("a slot of jam + 2τ", short),
    ] {
        let worst = worst_missed_slot(&bus, &SEED_CASE, slot)
            .expect("ten stations")
            .expect("messages delivered");
        println!(
            "  a message that just misses its own empty slot, {what} ({:.1} µs): station {} \
             waits {:.1} µs; D_max {:.1}, the model's bound {:.1}",
            us(slot),
            worst.offer.station,
            us(worst.delay()),
            us(d),
            us(slot_bound(&bus, &SEED_CASE, slot))
        );
    }
}
