//! A sped-up wall clock shared through an epoch: what processes of one cell agree on.

use std::time::{Duration, SystemTime};

use imrs_ports::{Clock, RealClock};

#[test]
fn two_clocks_from_one_epoch_read_the_same_sped_up_time() {
    let epoch = SystemTime::now() - Duration::from_secs(10);
    let a = RealClock::from_epoch(epoch, 60.0).expect("a valid epoch and speed");
    let b = RealClock::from_epoch(epoch, 60.0).expect("a valid epoch and speed");
    let (at_a, at_b) = (a.now().since_start(), b.now().since_start());
    // Ten wall seconds at sixty times: ten simulated minutes, read a moment apart.
    assert!(at_a >= Duration::from_secs(600), "{at_a:?}");
    assert!(at_a < Duration::from_secs(660), "{at_a:?}");
    let apart = at_a.abs_diff(at_b);
    assert!(
        apart < Duration::from_secs(6),
        "the two clocks differ by {apart:?}"
    );
    assert_eq!(a.speed(), 60.0);
}

#[test]
fn a_clock_whose_epoch_is_still_to_come_reads_zero() {
    let clock = RealClock::from_epoch(SystemTime::now() + Duration::from_secs(3600), 100.0)
        .expect("an epoch within a year");
    assert_eq!(clock.now().since_start(), Duration::ZERO);
}

#[test]
fn a_speed_or_an_epoch_that_means_nothing_is_refused() {
    let now = SystemTime::now();
    for speed in [
        0.0,
        0.5,
        -2.0,
        f64::NAN,
        f64::INFINITY,
        RealClock::MAX_SPEED * 2.0,
    ] {
        assert!(RealClock::from_epoch(now, speed).is_none(), "speed {speed}");
    }
    let two_years = Duration::from_secs(2 * 365 * 24 * 3600);
    assert!(RealClock::from_epoch(now + two_years, 10.0).is_none());
    assert!(RealClock::from_epoch(now - two_years, 10.0).is_none());
    assert!(RealClock::from_epoch(now, RealClock::MAX_SPEED).is_some());
}

#[tokio::test]
async fn a_sleep_on_a_sped_up_clock_ends_at_its_deadline_on_that_clock() {
    // 200 simulated milliseconds at a thousand times: a fifth of a wall millisecond.
    let clock = RealClock::from_epoch(SystemTime::now(), 1000.0).expect("valid");
    let deadline = clock.now() + Duration::from_millis(200);
    clock.sleep_until(deadline).await;
    assert!(clock.now() >= deadline);
}
