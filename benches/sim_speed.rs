//! How fast the simulated cell runs: simulated seconds per wall second, for the chip cell's
//! world with both chip robots working and pallets flowing, on virtual time.

#[path = "config.rs"]
mod config;

use std::sync::Arc;
use std::time::{Duration, Instant};

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use imrs_core::time::drive;
use imrs_ports::{Instant as SimInstant, VirtualClock};
use imrs_sim::{FeederId, Line, RobotId, Role, Sim, SimConfig, Target};

/// Simulated seconds per iteration.
const SIMULATED: u64 = 60;

/// `iters` minutes of a busy cell; the wall time they took.
fn minutes(iters: u64) -> Duration {
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .start_paused(true)
        .build()
        .unwrap();
    runtime.block_on(async move {
        let clock = VirtualClock::new();
        let sim = Sim::new(SimConfig::seeded(1), Arc::new(clock.clone()));
        sim.spawn();
        for line in Line::ALL {
            let gate = sim.gate(line);
            tokio::spawn(async move {
                loop {
                    gate.release().await;
                }
            });
            let robot = sim.robot(RobotId::new(line, Role::ChipIt));
            tokio::spawn(async move {
                loop {
                    for feeder in 0..4 {
                        let _ = robot.move_to(Target::Feeder(FeederId(feeder))).await;
                        let _ = robot.move_to(Target::Card).await;
                    }
                }
            });
        }
        sim.log().forget_events();
        let start = Instant::now();
        drive(
            &clock,
            SimInstant::from_start(Duration::from_secs(SIMULATED * iters)),
        )
        .await;
        start.elapsed()
    })
}

fn benches(c: &mut Criterion) {
    let mut group = c.benchmark_group("sim_speed");
    // Elements are simulated seconds: criterion's "elem/s" is simulated seconds per wall second.
    group.throughput(Throughput::Elements(SIMULATED));
    group.bench_function("busy_cell_minute", |b| b.iter_custom(minutes));
    group.finish();
}

criterion_group! {
    name = sim_benches;
    config = config::long_run();
    targets = benches
}
criterion_main!(sim_benches);
