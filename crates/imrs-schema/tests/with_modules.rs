//! A schema network and an imrs-core module in one cell: the module PLACER owns two
//! synchronous ports connected to the network's `MoveWrist`, sends it a target and reads
//! where the wrist is, until the wrist is there. The module runs on the network's
//! processor, beside the schema instances.

use std::time::Duration;

use imrs_core::prelude::*;
use imrs_schema::special::MoveWrist;
use imrs_schema::{Input, Network, Output};
use imrs_sim::hand::{Hand, HandConfig};
use nalgebra::Vector3;

#[tokio::test(start_paused = true)]
async fn a_module_drives_a_schema_network_through_its_ports() {
    let (cell, clock) = Cell::virtual_clock();
    let hand = Hand::new(HandConfig::seeded(2), cell.clock().clone());
    hand.spawn();
    let net = Network::new("HAND", cell.clock().clone());
    let wrist = net.instantiate(MoveWrist::new(&hand)).unwrap();

    let target = Output::<Vector3<f32>>::new("TARGET", "PLACER");
    let at = Input::<Vector3<f32>>::new("AT", "PLACER");
    net.cx().connect(&target, &wrist.ports().desired);
    net.cx().connect(&wrist.ports().actual, &at);
    let goal = Vector3::new(0.1, 0.05, 0.2);
    let placer = ModuleSpec::new("PLACER", 0u32).task("PLACE", move |ctx| {
        let (target, at) = (target.clone(), at.clone());
        async move {
            loop {
                target.write(goal).await?;
                let now = at.read().await?;
                ctx.state().update(|passes| *passes += 1);
                if (now - goal).norm() < 0.002 {
                    return Ok(());
                }
                ctx.delay(Duration::from_millis(20)).await;
            }
        }
    });
    let passes = placer.view();
    let mut placer = cell.start_on(net.processor(), placer).unwrap();
    imrs_core::time::drive(&clock, Instant::from_start(Duration::from_secs(3))).await;

    assert_eq!(placer.finished().await, ModuleOutcome::Finished);
    assert!(
        passes.inspect(|n| *n) > 5,
        "the module never waited for the wrist"
    );
    let palm = hand.palm().translation.vector;
    assert!(
        (palm - goal).norm() < 0.003,
        "the palm is at {palm}, not {goal}"
    );
}
