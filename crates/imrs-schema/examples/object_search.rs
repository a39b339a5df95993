//! Seed 004, Example III: `Object?`, a parallel search of every SEF through fan-in. One
//! `Objtest` per SEF tests its features against a ball 6 cm wide; the first match triggers
//! a `Reach` over it. Run: `cargo run --release --example object_search [SEED]`.

mod common;

use common::{Bench, runtime};
use imrs_schema::seed::{Desired, ObjectQ, Reach};
use imrs_sim::hand::Shape;

fn main() {
    runtime().block_on(async {
        let bench = Bench::new();
        bench.run_for(0.1).await;
        let desired = Desired {
            shape: Shape::Ball,
            size: 0.06,
            tolerance: 0.005,
        };
        let hand = bench.hand.clone();
        bench
            .net
            .instantiate(ObjectQ::new(desired, move |cx, sef| {
                println!("Object? matched SEF_{sef}: starting Reach");
                cx.instantiate(Reach::new(&hand, sef, 0.2)).map(drop)
            }))
            .expect("Object?");
        bench.run_for(4.0).await;
        println!("t = {:.2} s", bench.now());
        bench.palm_report(bench.index_of(Shape::Ball));
        bench.trace_report();
    });
}
