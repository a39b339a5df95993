//! What the four examples share: a hand over the default table on virtual time, its vision
//! interface running, and a report of what rapier measured.

// Each example uses only part of this module.
#![allow(dead_code)]

use std::sync::Arc;
use std::time::Duration;

use imrs_ports::{Clock, VirtualClock};
use imrs_schema::seed::Reach;
use imrs_schema::special::Vision;
use imrs_schema::{Network, Si};
use imrs_sim::hand::{FINGERS, Hand, HandConfig, Shape, Touch, finger_joints};

pub(crate) struct Bench {
    pub(crate) hand: Hand,
    pub(crate) net: Network,
    clock: VirtualClock,
}

impl Bench {
    /// The seed is the first argument, 1 by default.
    pub(crate) fn new() -> Self {
        let seed = std::env::args()
            .nth(1)
            .and_then(|s| s.parse().ok())
            .unwrap_or(1);
        let clock = VirtualClock::new();
        let hand = Hand::new(HandConfig::seeded(seed), Arc::new(clock.clone()));
        hand.spawn();
        let net = Network::new("HAND", Arc::new(clock.clone()));
        net.instantiate(Vision::new(&hand))
            .expect("the vision interface");
        Self { hand, net, clock }
    }

    pub(crate) async fn run_for(&self, seconds: f64) {
        let until = self.clock.now() + Duration::from_secs_f64(seconds);
        imrs_core::time::drive(&self.clock, until).await;
    }

    pub(crate) fn now(&self) -> f64 {
        self.clock.now().since_start().as_secs_f64()
    }

    pub(crate) fn index_of(&self, shape: Shape) -> usize {
        let objects = self.hand.objects();
        objects
            .iter()
            .position(|o| o.shape == shape)
            .expect("on the table")
    }

    /// The SEF the vision interface gave object `index`: numbered by x at first sight.
    pub(crate) fn sef_of(&self, index: usize) -> u32 {
        let objects = self.hand.objects();
        let x = objects[index].position.x;
        1 + objects.iter().filter(|o| o.position.x < x).count() as u32
    }

    /// Runs a reach for `SEF_sef` to its end.
    pub(crate) async fn reach(&self, sef: u32, above: f32) -> Si<Reach> {
        let reach = self
            .net
            .instantiate(Reach::new(&self.hand, sef, above))
            .expect("a reach");
        while reach.is_live() && self.now() < 60.0 {
            self.run_for(0.05).await;
        }
        reach
    }

    pub(crate) fn palm_report(&self, index: usize) {
        let object = self.hand.objects()[index];
        let palm = self.hand.palm();
        let offset = palm.translation.vector - object.position.coords;
        println!(
            "palm at ({:.4}, {:.4}, {:.4}) m, yaw {:.4} rad; object {:?} at ({:.4}, {:.4}, {:.4}): \
             palm - object = ({:.4}, {:.4}, {:.4})",
            palm.translation.x,
            palm.translation.y,
            palm.translation.z,
            palm.rotation.euler_angles().2,
            object.shape,
            object.position.x,
            object.position.y,
            object.position.z,
            offset.x,
            offset.y,
            offset.z
        );
    }

    pub(crate) fn finger_report(&self) {
        println!("finger  proximal  distal   touches      tip speed");
        for finger in FINGERS {
            let [p, d] = finger_joints(finger).map(|j| self.hand.position(j).unwrap());
            let touch = match self.hand.touch(finger).unwrap() {
                Some(Touch::Object(i)) => format!("{:?}", self.hand.objects()[i].shape),
                Some(Touch::Table) => "table".into(),
                None => "-".into(),
            };
            println!(
                "{finger:>6}  {p:>8.4}  {d:>6.4}   {touch:<12} {:.2e} m/s",
                self.hand.finger_speed(finger).unwrap()
            );
        }
    }

    pub(crate) fn trace_report(&self) {
        println!("top-level instances:");
        for entry in self.net.trace() {
            if !entry.instance.as_str().contains('/') {
                println!("  {entry}");
            }
        }
    }
}

pub(crate) fn runtime() -> tokio::runtime::Runtime {
    tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .start_paused(true)
        .build()
        .expect("a runtime")
}
