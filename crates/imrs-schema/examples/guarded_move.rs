//! Seed 004, Example I: the guarded move. The hand reaches over the cube and down around
//! it, then `Grip` — one `Closejoint` task-unit per finger joint — closes every finger
//! until its tip touches. Run: `cargo run --release --example guarded_move [SEED]`.

mod common;

use common::{Bench, runtime};
use imrs_schema::seed::Grip;
use imrs_sim::hand::{FINGERS, Shape, finger_joints};

fn main() {
    runtime().block_on(async {
        let bench = Bench::new();
        bench.run_for(0.1).await;
        let cube = bench.index_of(Shape::Cube);
        let sef = bench.sef_of(cube);
        bench.reach(sef, 0.2).await;
        bench.reach(sef, 0.1).await;
        println!("t = {:.2} s: over the cube", bench.now());
        bench.palm_report(cube);
        let joints = FINGERS.into_iter().flat_map(finger_joints);
        bench
            .net
            .instantiate(Grip::new(&bench.hand, joints, 0.01))
            .expect("Grip");
        bench.run_for(3.0).await;
        println!(
            "t = {:.2} s: Grip of {} Closejoint task-units",
            bench.now(),
            8
        );
        bench.finger_report();
        bench.trace_report();
    });
}
