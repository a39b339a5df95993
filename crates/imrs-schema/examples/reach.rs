//! Seed 004, Example II: Reach, a motor command parameterized by an object. The wrist goes
//! to the pose `SEF_k` reports for the ball, by `Del` per pass, and `Reach` stops there:
//! first 20 cm over the ball, then down to 10 cm, so that the fingers come down around it
//! instead of sweeping into it. Run: `cargo run --release --example reach [SEED]`.

mod common;

use common::{Bench, runtime};
use imrs_sim::hand::Shape;

fn main() {
    runtime().block_on(async {
        let bench = Bench::new();
        bench.run_for(0.1).await;
        let ball = bench.index_of(Shape::Ball);
        let sef = bench.sef_of(ball);
        for above in [0.2, 0.1] {
            println!("the ball is SEF_{sef}: Reach with handlength (0, 0, -{above})");
            let reach = bench.reach(sef, above).await;
            println!("t = {:.2} s: {} ended", bench.now(), reach.name());
            bench.palm_report(ball);
        }
        bench.trace_report();
    });
}
