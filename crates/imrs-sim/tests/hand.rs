//! The simulated hand: joints follow the mean of their commands, touch is felt only when a
//! fingertip meets a surface, the camera reports features without identities, and bad
//! numbers are refused by name.

use std::sync::Arc;
use std::time::Duration;

use imrs_ports::{Instant, VirtualClock};
use imrs_sim::hand::{Hand, HandConfig, HandError, Shape, Touch, finger_joints};

fn at(seconds: f64) -> Instant {
    Instant::from_start(Duration::from_secs_f64(seconds))
}

fn hand() -> (Hand, VirtualClock) {
    let clock = VirtualClock::new();
    let hand = Hand::new(HandConfig::seeded(3), Arc::new(clock.clone()));
    hand.spawn();
    (hand, clock)
}

#[tokio::test(start_paused = true)]
async fn a_joint_goes_to_the_mean_of_its_live_commands() {
    let (hand, clock) = hand();
    let [proximal, distal] = finger_joints(2);
    let (a, b) = (hand.source(), hand.source());
    hand.command(proximal, a, 0.2).unwrap();
    hand.command(proximal, b, 0.6).unwrap();
    hand.command(distal, a, -0.3).unwrap();
    imrs_core::time::drive(&clock, at(1.0)).await;
    assert!((hand.position(proximal).unwrap() - 0.4).abs() < 0.01);
    assert!((hand.position(distal).unwrap() + 0.3).abs() < 0.01);
    hand.release(proximal, b).unwrap();
    imrs_core::time::drive(&clock, at(2.0)).await;
    assert!((hand.position(proximal).unwrap() - 0.2).abs() < 0.01);
    // The other fingers were never commanded and hang straight.
    for finger in [1, 3, 4] {
        for joint in finger_joints(finger) {
            assert!(hand.position(joint).unwrap().abs() < 0.01);
        }
    }
}

#[tokio::test(start_paused = true)]
async fn the_wrist_moves_at_its_speed_and_reaches_its_target() {
    let (hand, clock) = hand();
    let source = hand.source();
    hand.command(1, source, 0.1).unwrap();
    hand.command(6, source, 0.5).unwrap();
    imrs_core::time::drive(&clock, at(0.25)).await;
    let halfway = hand.position(1).unwrap();
    assert!(
        halfway > 0.02 && halfway < 0.08,
        "x after 0.25 s: {halfway}"
    );
    imrs_core::time::drive(&clock, at(2.0)).await;
    let palm = hand.palm();
    assert!((palm.translation.x - 0.1).abs() < 0.002);
    assert!((palm.rotation.euler_angles().2 - 0.5).abs() < 0.01);
    assert!((hand.position(6).unwrap() - 0.5).abs() < 0.01);
}

#[tokio::test(start_paused = true)]
async fn touch_is_felt_only_where_a_fingertip_meets_a_surface() {
    let (hand, clock) = hand();
    let source = hand.source();
    // Over the cube, fingertips beside it at mid-height: close enough for rapier's
    // speculative contacts, not touching.
    hand.command(2, source, 0.0).unwrap();
    imrs_core::time::drive(&clock, at(1.5)).await;
    hand.command(3, source, 0.125).unwrap();
    imrs_core::time::drive(&clock, at(3.0)).await;
    for finger in 1..=4 {
        assert_eq!(hand.touch(finger).unwrap(), None, "finger {finger}");
    }
    // Close finger 3 only, a little past where it meets the cube: the spring presses it
    // on gently, less than the friction that holds the cube.
    for joint in finger_joints(3) {
        hand.command(joint, source, 0.12).unwrap();
    }
    imrs_core::time::drive(&clock, at(4.0)).await;
    assert_eq!(hand.touch(3).unwrap(), Some(Touch::Object(0)));
    assert_eq!(hand.touch(1).unwrap(), None);
}

#[tokio::test(start_paused = true)]
async fn the_camera_sees_every_object_in_no_fixed_order() {
    let (hand, _clock) = hand();
    let truth = hand.objects();
    assert_eq!(
        truth.iter().map(|o| o.shape).collect::<Vec<_>>(),
        [Shape::Cube, Shape::Ball, Shape::Cylinder]
    );
    let mut orders = std::collections::HashSet::new();
    for _ in 0..20 {
        let seen = hand.see();
        assert_eq!(seen.len(), truth.len());
        for object in &truth {
            assert!(seen.contains(object));
        }
        orders.insert(seen.iter().map(|o| o.shape as u8).collect::<Vec<_>>());
    }
    assert!(orders.len() > 1, "the camera always reports in table order");
}

#[tokio::test(start_paused = true)]
async fn numbers_the_hand_lacks_are_refused_by_name() {
    let (hand, _clock) = hand();
    assert_eq!(hand.command(15, 1, 0.0), Err(HandError::NoJoint(15)));
    assert_eq!(hand.position(0), Err(HandError::NoJoint(0)));
    assert_eq!(hand.touch(5), Err(HandError::NoFinger(5)));
    assert_eq!(hand.push(3, [0.0, 0.0]), Err(HandError::NoObject(3)));
    assert_eq!(
        HandError::NoJoint(15).to_string(),
        "the hand has no joint 15 (joints are 1 to 14)"
    );
}

/// A command that is not a number would put NaN into the physics and stop the world: it
/// is refused, and the joint keeps the command it had.
#[tokio::test(start_paused = true)]
async fn a_command_that_is_not_a_number_is_refused_and_changes_nothing() {
    let (hand, clock) = hand();
    let [joint, _] = finger_joints(1);
    hand.command(joint, 1, 0.3).unwrap();
    let error = hand.command(joint, 1, f32::NAN).unwrap_err();
    assert_eq!(error.to_string(), "NaN for joint 7 is not a finite number");
    assert!(hand.command(2, 1, f32::INFINITY).is_err());
    assert!(hand.push(0, [f32::NAN, 0.0]).is_err());
    imrs_core::time::drive(&clock, at(1.0)).await;
    assert!((hand.position(joint).unwrap() - 0.3).abs() < 0.01);
    assert!(hand.palm().translation.vector.iter().all(|v| v.is_finite()));
}
