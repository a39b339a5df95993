//! The four examples of Lyons & Arbib 1985, §5, judged by their physical outcome in rapier: contact
//! reached and fingers stopped; the wrist at the object; the matching object chosen; the
//! virtual finger's fingers moved and no other; and the guarded move over port arrays, two
//! joints on one sensor and one joint on two sensors.

use std::sync::{Arc, Condvar, Mutex};
use std::time::Duration;

use imrs_ports::{Clock, VirtualClock};
use imrs_schema::seed::{
    Closefinger, Desired, Features, Grasp, Grip, GuardedMove, Judge, ObjectQ, ObjectQOnce, Reach,
    Vf,
};
use imrs_schema::special::Vision;
use imrs_schema::{Ending, Network, Si};
use imrs_sim::hand::{FINGERS, Hand, HandConfig, Shape, Touch, finger_joints};

struct Bench {
    hand: Hand,
    net: Network,
    clock: VirtualClock,
}

impl Bench {
    /// A hand over the default table, its vision interface running.
    fn new() -> Self {
        let clock = VirtualClock::new();
        let hand = Hand::new(HandConfig::seeded(4), Arc::new(clock.clone()));
        hand.spawn();
        let net = Network::new("HAND", Arc::new(clock.clone()));
        net.instantiate(Vision::new(&hand)).unwrap();
        Self { hand, net, clock }
    }

    async fn run_for(&self, seconds: f64) {
        let until = self.clock.now() + Duration::from_secs_f64(seconds);
        imrs_core::time::drive(&self.clock, until).await;
    }

    /// The SEF the vision interface gives object `index` of the table: numbered in order
    /// of x at first sight.
    fn sef_of(&self, index: usize) -> u32 {
        let objects = self.hand.objects();
        let x = objects[index].position.x;
        1 + objects.iter().filter(|o| o.position.x < x).count() as u32
    }

    fn index_of(&self, shape: Shape) -> usize {
        self.hand
            .objects()
            .iter()
            .position(|o| o.shape == shape)
            .unwrap()
    }

    /// Reaches over object `index` (its SEF found by the camera), then down around it:
    /// coming straight down, the fingers never sweep into the object.
    async fn reach(&self, object: usize) -> Si<Reach> {
        self.run_for(0.1).await; // the camera's first frame
        let sef = self.sef_of(object);
        self.reach_to(sef, 0.2).await;
        self.reach_to(sef, 0.1).await
    }

    async fn reach_to(&self, sef: u32, above: f32) -> Si<Reach> {
        let reach = self
            .net
            .instantiate(Reach::new(&self.hand, sef, above))
            .unwrap();
        for _ in 0..100 {
            if !reach.is_live() {
                break;
            }
            self.run_for(0.1).await;
        }
        assert!(!reach.is_live(), "the reach never got there");
        reach
    }

    /// How far the palm is from `above` over object `index`, and its yaw.
    fn palm_error(&self, index: usize, above: f32) -> f32 {
        let object = self.hand.objects()[index].position;
        let palm = self.hand.palm().translation.vector;
        (palm - (object.coords + nalgebra::Vector3::new(0.0, 0.0, above))).norm()
    }

    fn angles(&self, finger: usize) -> [f32; 2] {
        finger_joints(finger).map(|j| self.hand.position(j).unwrap())
    }
}

/// No instance of the run failed: every one ended by `STOP`, by being stopped, or with its
/// components — none by a read or write that found its peer gone.
fn assert_none_failed(net: &Network) {
    let failed: Vec<String> = net
        .trace()
        .iter()
        .filter(|e| matches!(e.ended, Some(Ending::Failed(_))))
        .map(|e| e.to_string())
        .collect();
    assert!(failed.is_empty(), "{failed:#?}");
}

fn ended(net: &Network, instance: &str) -> Option<Ending> {
    net.trace()
        .into_iter()
        .find(|e| e.instance == instance && e.ended.is_some())
        .and_then(|e| e.ended)
}

#[tokio::test(start_paused = true)]
async fn example_1_the_guarded_move_closes_every_finger_until_it_touches() {
    let bench = Bench::new();
    let cube = bench.index_of(Shape::Cube);
    bench.reach(cube).await;
    let cube_before = bench.hand.objects()[cube].position;
    let joints = FINGERS.iter().flat_map(|&f| finger_joints(f));
    bench
        .net
        .instantiate(Grip::new(&bench.hand, joints, 0.01))
        .unwrap();
    bench.run_for(3.0).await;

    let held: Vec<[f32; 2]> = FINGERS.iter().map(|&f| bench.angles(f)).collect();
    bench.run_for(1.0).await;
    for (&finger, before) in FINGERS.iter().zip(&held) {
        assert_eq!(
            bench.hand.touch(finger).unwrap(),
            Some(Touch::Object(cube)),
            "finger {finger} never reached the cube"
        );
        assert!(
            before[0] > 0.02,
            "finger {finger} did not close: {before:?}"
        );
        let after = bench.angles(finger);
        for k in 0..2 {
            assert!(
                (after[k] - before[k]).abs() < 0.005,
                "finger {finger} kept moving after contact: {before:?} -> {after:?}"
            );
        }
        assert!(bench.hand.finger_speed(finger).unwrap() < 1e-3);
    }
    let moved = (bench.hand.objects()[cube].position - cube_before).norm();
    assert!(moved < 0.005, "the grip pushed the cube {moved} m");
    assert_none_failed(&bench.net);
}

#[tokio::test(start_paused = true)]
async fn example_2_reach_takes_the_wrist_to_the_object_its_sef_reports() {
    let bench = Bench::new();
    let ball = bench.index_of(Shape::Ball);
    let reach = bench.reach(ball).await;
    assert_eq!(
        ended(&bench.net, reach.name().as_str()),
        Some(Ending::Stopped)
    );
    bench.run_for(0.5).await;
    let error = bench.palm_error(ball, 0.1);
    assert!(
        error < 0.004,
        "the palm is {error} m from its target over the ball"
    );
    let yaw = bench.hand.palm().rotation.euler_angles().2;
    assert!(yaw.abs() < 0.02, "yaw {yaw}");
    for other in (0..3).filter(|&i| i != ball) {
        assert!(bench.palm_error(other, 0.1) > 0.1);
    }
    assert_none_failed(&bench.net);
}

#[tokio::test(start_paused = true)]
async fn example_3_object_search_tests_every_sef_in_parallel_and_reaches_the_match() {
    let bench = Bench::new();
    let ball = bench.index_of(Shape::Ball);
    let hand = bench.hand.clone();
    let desired = Desired {
        shape: Shape::Ball,
        size: 0.06,
        tolerance: 0.005,
    };
    bench.run_for(0.1).await;
    bench
        .net
        .instantiate(ObjectQ::new(desired, move |cx, sef| {
            // Tj: reach over the object found.
            cx.instantiate(Reach::new(&hand, sef, 0.2)).map(drop)
        }))
        .unwrap();
    bench.run_for(4.0).await;

    let trace = bench.net.trace();
    let tests: Vec<_> = trace
        .iter()
        .filter(|e| e.instance.as_str().starts_with("Objtest_") && e.ended.is_none())
        .collect();
    assert!(tests.len() >= 3, "not every SEF was tested: {tests:?}");
    assert!(
        tests[..3].iter().all(|e| e.at == tests[0].at),
        "the first tests did not start together"
    );
    assert_eq!(ended(&bench.net, "Object?_1"), Some(Ending::Stopped));
    assert_eq!(ended(&bench.net, "Reach_1"), Some(Ending::Stopped));
    let error = bench.palm_error(ball, 0.2);
    assert!(
        error < 0.004,
        "the palm is {error} m from its target over the ball"
    );
    assert_none_failed(&bench.net);
}

/// A test of the seed's features that takes its time: each of the first `expected` judges
/// waits, for real and at most `PATIENCE`, until all of them have come in, and the room
/// keeps the most it saw judging at once. Were the judges run one after the other, the
/// first would wait alone and give up, and the most would be 1.
#[derive(Clone)]
struct Meeting {
    desired: Desired,
    expected: usize,
    room: Arc<(Mutex<Room>, Condvar)>,
}

#[derive(Default)]
struct Room {
    arrived: usize,
    inside: usize,
    most: usize,
}

impl Meeting {
    const PATIENCE: Duration = Duration::from_secs(10);

    fn most(&self) -> usize {
        self.room.0.lock().unwrap().most
    }
}

impl Judge for Meeting {
    fn judge(&self, features: &Features) -> bool {
        let (room, changed) = &*self.room;
        let mut guard = room.lock().unwrap();
        guard.arrived += 1;
        guard.inside += 1;
        guard.most = guard.most.max(guard.inside);
        changed.notify_all();
        let (mut guard, _) = changed
            .wait_timeout_while(guard, Self::PATIENCE, |r| r.arrived < self.expected)
            .unwrap();
        guard.inside -= 1;
        self.desired.judge(features)
    }
}

/// The parallel search measured: the judges of every SEF are seen judging at the same
/// moment, each waiting in its test until the others have come in.
#[tokio::test(start_paused = true)]
async fn example_3_every_sef_is_judged_at_once() {
    let bench = Bench::new();
    let sefs = bench.hand.objects().len();
    let ball = bench.index_of(Shape::Ball);
    let meeting = Meeting {
        desired: Desired {
            shape: Shape::Ball,
            size: 0.06,
            tolerance: 0.005,
        },
        expected: sefs,
        room: Arc::default(),
    };
    let found = Arc::new(Mutex::new(None));
    let record = Arc::clone(&found);
    bench
        .net
        .instantiate(ObjectQ::new(meeting.clone(), move |_, sef| {
            *record.lock().unwrap() = Some(sef);
            Ok(())
        }))
        .unwrap();
    bench.run_for(1.0).await;
    assert_eq!(
        *found.lock().unwrap(),
        Some(bench.sef_of(ball)),
        "the search did not find the ball"
    );
    assert_eq!(
        meeting.most(),
        sefs,
        "the SEFs' judges did not all judge at once"
    );
    assert_eq!(ended(&bench.net, "Object?_1"), Some(Ending::Stopped));
    assert_none_failed(&bench.net);
}

/// A judge that panics fails its own `Objtest`, by name; the search goes on testing.
#[tokio::test(start_paused = true)]
async fn example_3_a_judge_that_panics_fails_its_test_by_name() {
    #[derive(Clone)]
    struct Panics;
    impl Judge for Panics {
        fn judge(&self, _: &Features) -> bool {
            panic!("a recognizer's bug")
        }
    }
    let bench = Bench::new();
    bench
        .net
        .instantiate(ObjectQ::new(Panics, |_, _| Ok(())))
        .unwrap();
    bench.run_for(0.5).await;
    let failed: Vec<_> = bench
        .net
        .trace()
        .into_iter()
        .filter_map(|e| match e.ended {
            Some(Ending::Failed(error)) => Some(error.to_string()),
            _ => None,
        })
        .collect();
    assert!(
        failed.contains(&"Objtest_2 failed: its judge panicked".to_string()),
        "{failed:#?}"
    );
    assert!(
        bench.net.forall::<ObjectQ<Panics>>().len() == 1,
        "the search ended"
    );
}

#[tokio::test(start_paused = true)]
async fn example_3_second_precondition_the_matching_test_starts_the_task_unit_on_its_sef() {
    let bench = Bench::new();
    let ball = bench.index_of(Shape::Ball);
    let hand = bench.hand.clone();
    let desired = Desired {
        shape: Shape::Ball,
        size: 0.06,
        tolerance: 0.005,
    };
    bench.run_for(0.1).await;
    bench
        .net
        .instantiate(ObjectQOnce::new(desired, move |cx, sef| {
            cx.instantiate(Reach::new(&hand, sef, 0.2)).map(drop)
        }))
        .unwrap();
    bench.run_for(4.0).await;

    let trace = bench.net.trace();
    let made: Vec<&str> = trace
        .iter()
        .filter(|e| e.ended.is_none())
        .map(|e| e.instance.as_str())
        .collect();
    let tests: Vec<&str> = made
        .iter()
        .copied()
        .filter(|name| name.starts_with("Objtest_"))
        .collect();
    // One test per SEF, the ball's among them, and no more: Object? made them and died.
    assert_eq!(tests.len(), bench.hand.objects().len(), "{made:?}");
    assert!(tests.contains(&format!("Objtest_{}", bench.sef_of(ball)).as_str()));
    assert_eq!(ended(&bench.net, "Object?_1"), Some(Ending::Stopped));
    let object_died = trace
        .iter()
        .position(|e| e.instance == "Object?_1" && e.ended.is_some())
        .unwrap();
    let first_test_ended = trace
        .iter()
        .position(|e| e.instance.as_str().starts_with("Objtest_") && e.ended.is_some())
        .unwrap();
    assert!(
        object_died < first_test_ended,
        "Object? waited for its tests"
    );
    // Each test died after testing; only the match started the task-unit, on its SEF.
    for test in &tests {
        assert_eq!(ended(&bench.net, test), Some(Ending::Stopped), "{test}");
    }
    let reaches: Vec<&str> = made
        .iter()
        .copied()
        .filter(|name| name.starts_with("Reach_") && !name.contains('/'))
        .collect();
    assert_eq!(reaches.len(), 1, "{made:?}");
    let error = bench.palm_error(ball, 0.2);
    assert!(
        error < 0.004,
        "the palm is {error} m from its target over the ball"
    );
    assert_none_failed(&bench.net);
}

#[tokio::test(start_paused = true)]
async fn example_4_a_virtual_finger_moves_its_fingers_and_no_other() {
    let bench = Bench::new();
    let cube = bench.index_of(Shape::Cube);
    bench.reach(cube).await;
    // f_2 = {1, 2, 4}
    for finger in [1, 2, 4] {
        bench.net.instantiate_as(finger, Vf::<2>).unwrap();
    }
    bench
        .net
        .instantiate(Grasp::<2>::new(&bench.hand, 0.01))
        .unwrap();
    bench.run_for(3.0).await;

    let closing: Vec<_> = bench
        .net
        .trace()
        .into_iter()
        .filter(|e| {
            let name = e.instance.as_str();
            name.starts_with("Closefinger_") && !name.contains('/') && e.ended.is_none()
        })
        .map(|e| e.instance.to_string())
        .collect();
    assert_eq!(closing, ["Closefinger_1", "Closefinger_2", "Closefinger_4"]);
    for finger in [1, 2, 4] {
        assert!(
            bench.angles(finger)[0] > 0.02,
            "finger {finger} did not move"
        );
        assert_eq!(bench.hand.touch(finger).unwrap(), Some(Touch::Object(cube)));
    }
    let still = bench.angles(3);
    assert!(
        still.iter().all(|a| a.abs() < 0.005),
        "finger 3 moved: {still:?}"
    );
    assert_eq!(bench.hand.touch(3).unwrap(), None);
    assert_none_failed(&bench.net);
}

#[tokio::test(start_paused = true)]
async fn a_guarded_move_over_port_arrays_closes_two_joints_on_one_sensor() {
    let bench = Bench::new();
    let cube = bench.index_of(Shape::Cube);
    bench.reach(cube).await;
    // Finger 1's two joints, guarded by its tip: Tin_1, Pin_1…2, Pout_1…2.
    let guarded = bench
        .net
        .instantiate(GuardedMove::new(&bench.hand, [1], finger_joints(1), 0.01))
        .unwrap();
    assert_eq!(guarded.ports().tin.names(), ["Tin_1"]);
    assert_eq!(guarded.ports().pout.names(), ["Pout_1", "Pout_2"]);
    bench.run_for(3.0).await;
    let [proximal, distal] = bench.angles(1);
    assert!(proximal > 0.02 && distal > 0.02, "{proximal} {distal}");
    assert_eq!(bench.hand.touch(1).unwrap(), Some(Touch::Object(cube)));
    // Held where it touched.
    let held = bench.angles(1);
    bench.run_for(1.0).await;
    let after = bench.angles(1);
    assert!((after[0] - held[0]).abs() < 0.005 && (after[1] - held[1]).abs() < 0.005);
    assert!(
        bench.angles(3).iter().all(|a| a.abs() < 0.005),
        "finger 3 moved"
    );
    assert_none_failed(&bench.net);
}

#[tokio::test(start_paused = true)]
async fn a_guarded_move_over_port_arrays_holds_one_joint_once_either_sensor_touches() {
    let bench = Bench::new();
    let cube = bench.index_of(Shape::Cube);
    bench.reach(cube).await;
    // Finger 4 closes on the cube first.
    bench
        .net
        .instantiate_as(4, Closefinger::new(&bench.hand, 0.01))
        .unwrap();
    bench.run_for(3.0).await;
    assert_eq!(bench.hand.touch(4).unwrap(), Some(Touch::Object(cube)));
    let joint = finger_joints(2)[0];
    let before = bench.hand.position(joint).unwrap();
    // Finger 2's first joint, guarded by finger 2's tip and finger 4's: 4 touches, so it
    // holds, though its own finger touches nothing.
    let both = bench
        .net
        .instantiate(GuardedMove::new(&bench.hand, [2, 4], [joint], 0.01))
        .unwrap();
    bench.run_for(1.0).await;
    let held = bench.hand.position(joint).unwrap();
    assert!(
        (held - before).abs() < 0.005,
        "moved from {before} to {held}"
    );
    assert_eq!(bench.hand.touch(2).unwrap(), None);
    // Guarded by its own tip alone, the same joint closes.
    both.stop();
    bench
        .net
        .instantiate(GuardedMove::new(&bench.hand, [2], [joint], 0.01))
        .unwrap();
    bench.run_for(2.0).await;
    let moved = bench.hand.position(joint).unwrap();
    assert!(moved > before + 0.02, "stayed at {moved}");
    assert_none_failed(&bench.net);
}
