//! The seed's worst case: ten stations (a coordinator and nine robots) on a 100 m bus, the
//! coordinator's longest packet a five-point trajectory (148 B), each robot's a position
//! (51 B). Prints `D_max` with IEEE 802.3's 10 Mb/s parameters, each parameter and its
//! source, and the difference from the 604 µs the seed reports; then the variants the seed
//! suggests. Run: `cargo run --release --example network_bound`.

use std::time::Duration;

use imrs_coord::network::{Bus, SEED_CASE, SEED_D_MAX};

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
}
