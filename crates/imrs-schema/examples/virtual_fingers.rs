//! Seed 004, Example IV: virtual fingers. `VF_2` instances 1, 2 and 4 say that
//! f_2 = {1, 2, 4}; `FORALL VF_2_i DO Closefinger(i) ENDFOR` closes those three fingers on
//! the cube, and finger 3 stays as it was. Run:
//! `cargo run --release --example virtual_fingers [SEED]`.

mod common;

use common::{Bench, runtime};
use imrs_schema::seed::{Grasp, Vf};
use imrs_sim::hand::Shape;

fn main() {
    runtime().block_on(async {
        let bench = Bench::new();
        bench.run_for(0.1).await;
        let cube = bench.index_of(Shape::Cube);
        let sef = bench.sef_of(cube);
        bench.reach(sef, 0.2).await;
        bench.reach(sef, 0.1).await;
        for finger in [1, 2, 4] {
            bench.net.instantiate_as(finger, Vf::<2>).expect("VF_2");
        }
        bench
            .net
            .instantiate(Grasp::<2>::new(&bench.hand, 0.01))
            .expect("Grasp");
        bench.run_for(3.0).await;
        println!("t = {:.2} s: f_2 = {{1, 2, 4}} closed", bench.now());
        bench.finger_report();
        bench.trace_report();
    });
}
