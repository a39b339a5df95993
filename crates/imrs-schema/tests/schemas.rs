//! The model's rules, tried from outside: instantiation and numbering, FORALL, STOP,
//! assemblages and task-units ending as the seed says, connections by name, the mean of
//! several `Jmotor_i`, visual continuity of SEFs, virtual fingers of their own however many,
//! and reproducible runs.

use std::sync::Arc;
use std::time::Duration;

use imrs_ports::{Clock, VirtualClock};
use imrs_schema::seed::Vf;
use imrs_schema::special::{Jmotor, Sef, Vision};
use imrs_schema::{Behavior, Cx, Declare, Ending, Flow, Kind, Network, Schema, SchemaError, ports};
use imrs_sim::hand::{Hand, HandConfig, finger_joints};

fn network() -> (Network, VirtualClock) {
    let clock = VirtualClock::new();
    (Network::new("SCHEMAS", Arc::new(clock.clone())), clock)
}

async fn run_for(clock: &VirtualClock, seconds: f64) {
    let until = clock.now() + Duration::from_secs_f64(seconds);
    imrs_core::time::drive(clock, until).await;
}

ports! {
    /// A counter's output.
    struct CountPorts { out count: u32 = "count" }
}

ports! {
    /// A sink's input.
    struct SinkPorts { in value: u32 = "value" }
}

/// Writes 1, 2, 3, … up to `until`, one per 10 ms, then stops.
struct Count {
    next: u32,
    until: u32,
}

impl Schema for Count {
    const NAME: &'static str = "Count";
    type Ports = CountPorts;
    fn set_up(&mut self, cx: &Cx) -> Result<CountPorts, SchemaError> {
        Ok(Declare::declare(cx.me()))
    }
    async fn behavior(&mut self, p: &CountPorts, cx: &Cx) -> Behavior {
        cx.delay(Duration::from_millis(10)).await;
        self.next += 1;
        p.count.write(self.next).await?;
        Ok(if self.next == self.until {
            Flow::Stop
        } else {
            Flow::Continue
        })
    }
}

/// Reads for ever, keeping what it read.
struct Sink(Arc<std::sync::Mutex<Vec<u32>>>);

impl Schema for Sink {
    const NAME: &'static str = "Sink";
    type Ports = SinkPorts;
    fn set_up(&mut self, cx: &Cx) -> Result<SinkPorts, SchemaError> {
        Ok(Declare::declare(cx.me()))
    }
    async fn behavior(&mut self, p: &SinkPorts, _: &Cx) -> Behavior {
        let value = p.value.read().await?;
        self.0.lock().unwrap().push(value);
        Ok(Flow::Continue)
    }
}

/// Two counters, as one assemblage: it ends when both have.
struct Pair;

impl Schema for Pair {
    const NAME: &'static str = "Pair";
    const KIND: Kind = Kind::Assemblage;
    type Ports = ();
    fn set_up(&mut self, cx: &Cx) -> Result<(), SchemaError> {
        let sink = Arc::new(std::sync::Mutex::new(Vec::new()));
        let reader = cx.instantiate(Sink(sink))?;
        for until in [2, 5] {
            let counter = cx.instantiate(Count { next: 0, until })?;
            cx.connect(&counter.ports().count, &reader.ports().value);
        }
        // The sink reads for ever: stop it once both counters are done.
        cx.instantiate(StopWhenDone)?;
        Ok(())
    }
}

/// Stops the sink beside it once no counter is left.
struct StopWhenDone;

impl Schema for StopWhenDone {
    const NAME: &'static str = "StopWhenDone";
    type Ports = ();
    fn set_up(&mut self, _: &Cx) -> Result<(), SchemaError> {
        Ok(())
    }
    async fn behavior(&mut self, _: &(), cx: &Cx) -> Behavior {
        cx.delay(Duration::from_millis(10)).await;
        if cx.forall::<Count>().is_empty() {
            cx.forall::<Sink>().iter().for_each(|s| s.stop());
            return Ok(Flow::Stop);
        }
        Ok(Flow::Continue)
    }
}

/// A task-unit: a counter as sensing component, an r-schema that stops after three reads.
struct ThreeReads;

impl Schema for ThreeReads {
    const NAME: &'static str = "ThreeReads";
    const KIND: Kind = Kind::TaskUnit;
    type Ports = SinkPorts;
    fn set_up(&mut self, cx: &Cx) -> Result<SinkPorts, SchemaError> {
        let ports: SinkPorts = Declare::declare(cx.me());
        let counter = cx.instantiate(Count {
            next: 0,
            until: 1000,
        })?;
        cx.connect(&counter.ports().count, &ports.value);
        Ok(ports)
    }
    async fn behavior(&mut self, p: &SinkPorts, _: &Cx) -> Behavior {
        Ok(if p.value.read().await? == 3 {
            Flow::Stop
        } else {
            Flow::Continue
        })
    }
}

fn endings(net: &Network) -> Vec<(String, Ending)> {
    net.trace()
        .into_iter()
        .filter_map(|e| e.ended.map(|ended| (e.instance.to_string(), ended)))
        .collect()
}

#[tokio::test(start_paused = true)]
async fn numbers_are_local_to_the_assemblage_and_an_explicit_one_is_never_taken_twice() {
    let (net, _clock) = network();
    let first = net.instantiate(Count { next: 0, until: 9 }).unwrap();
    let third = net.instantiate_as(3, Count { next: 0, until: 9 }).unwrap();
    let second = net.instantiate(Count { next: 0, until: 9 }).unwrap();
    assert_eq!([first.number(), second.number(), third.number()], [1, 2, 3]);
    assert_eq!(third.name(), "Count_3");
    let error = net
        .instantiate_as(3, Count { next: 0, until: 9 })
        .unwrap_err();
    assert_eq!(error.to_string(), "Count_3 already exists in assemblage /");
    assert_eq!(
        net.instantiate_as(0, Count { next: 0, until: 9 })
            .unwrap_err(),
        SchemaError::ZeroInstance { schema: "Count" }
    );
    let numbers: Vec<u32> = net.forall::<Count>().iter().map(|c| c.number()).collect();
    assert_eq!(numbers, [1, 2, 3], "FORALL");
    assert!(net.forall::<Sink>().is_empty());
}

#[tokio::test(start_paused = true)]
async fn every_virtual_finger_has_a_name_of_its_own_and_forall_tells_them_apart() {
    let names = [
        Vf::<1>::NAME,
        Vf::<5>::NAME,
        Vf::<12>::NAME,
        Vf::<4_294_967_295>::NAME,
    ];
    assert_eq!(names, ["VF_1", "VF_5", "VF_12", "VF_4294967295"]);
    let (net, _clock) = network();
    // Physical finger 1 belongs to virtual fingers 5 and 6, finger 2 to 6 alone.
    net.instantiate_as(1, Vf::<5>).unwrap();
    net.instantiate_as(1, Vf::<6>).unwrap();
    net.instantiate_as(2, Vf::<6>).unwrap();
    let five: Vec<u32> = net.forall::<Vf<5>>().iter().map(|f| f.number()).collect();
    let six: Vec<u32> = net.forall::<Vf<6>>().iter().map(|f| f.number()).collect();
    assert_eq!((five, six), (vec![1], vec![1, 2]));
}

#[tokio::test(start_paused = true)]
async fn an_assemblage_ends_when_all_its_components_have() {
    let (net, clock) = network();
    let pair = net.instantiate(Pair).unwrap();
    run_for(&clock, 0.03).await;
    assert!(pair.is_live(), "ended while a counter still ran");
    run_for(&clock, 0.2).await;
    assert!(!pair.is_live());
    let endings = endings(&net);
    assert!(endings.contains(&("Pair_1/Count_1".into(), Ending::Stopped)));
    assert!(endings.contains(&("Pair_1/Count_2".into(), Ending::Stopped)));
    assert_eq!(
        endings.last(),
        Some(&("Pair_1".into(), Ending::ComponentsEnded))
    );
}

#[tokio::test(start_paused = true)]
async fn a_task_unit_ends_with_its_r_schema_and_stops_its_components() {
    let (net, clock) = network();
    let unit = net.instantiate(ThreeReads).unwrap();
    run_for(&clock, 1.0).await;
    assert!(!unit.is_live());
    let endings = endings(&net);
    assert!(
        endings.contains(&("ThreeReads_1/Count_1".into(), Ending::Deinstantiated)),
        "{endings:?}"
    );
    assert_eq!(
        endings.last(),
        Some(&("ThreeReads_1".into(), Ending::Stopped))
    );
}

#[tokio::test(start_paused = true)]
async fn stop_deinstantiates_at_once_and_closes_the_ports() {
    let (net, clock) = network();
    let counter = net
        .instantiate(Count {
            next: 0,
            until: 1000,
        })
        .unwrap();
    let seen = Arc::new(std::sync::Mutex::new(Vec::new()));
    let sink = net.instantiate(Sink(Arc::clone(&seen))).unwrap();
    net.cx()
        .connect_any(counter.port("count").unwrap(), sink.port("value").unwrap())
        .unwrap();
    run_for(&clock, 0.055).await;
    counter.stop();
    run_for(&clock, 0.1).await;
    assert_eq!(*seen.lock().unwrap(), [1, 2, 3, 4, 5]);
    assert!(!counter.is_live());
    // The sink's only writer is gone: its read fails, naming it, and it ends.
    assert!(!sink.is_live());
    let endings = endings(&net);
    assert_eq!(endings[0], ("Count_1".into(), Ending::Deinstantiated));
    match &endings[1] {
        (name, Ending::Failed(error)) if name == "Sink_1" => {
            assert!(error.to_string().contains("Sink_1(value)"), "{error}");
        }
        other => panic!("{other:?}"),
    }
}

#[tokio::test(start_paused = true)]
async fn a_connection_by_name_is_checked_and_names_both_ends() {
    let (net, _clock) = network();
    let counter = net.instantiate(Count { next: 0, until: 9 }).unwrap();
    let hand = Hand::new(HandConfig::seeded(1), Arc::new(VirtualClock::new()));
    let motor = net.instantiate_as(7, Jmotor::new(&hand)).unwrap();
    let error = net
        .cx()
        .connect_any(
            counter.port("count").unwrap(),
            motor.port("desired").unwrap(),
        )
        .unwrap_err();
    assert_eq!(
        error.to_string(),
        "cannot connect Count_1(count) to Jmotor_7(desired): Count_1(count) writes u32, \
         Jmotor_7(desired) reads f32"
    );
    let Err(error) = motor.port("Desired") else {
        panic!("a port that does not exist was found");
    };
    assert_eq!(error.to_string(), "Jmotor_7 has no port Desired");
    let error = net.instantiate_as(15, Jmotor::new(&hand)).unwrap_err();
    assert_eq!(
        error.to_string(),
        "Jmotor_15: the hand has no joint 15 (joints are 1 to 14)"
    );
    assert!(net.forall::<Jmotor>().iter().all(|m| m.number() == 7));
}

ports! {
    /// A constant command.
    struct HoldPorts { out value: f32 = "value" }
}

/// Writes `0` for ever.
struct Hold(f32);

impl Schema for Hold {
    const NAME: &'static str = "Hold";
    type Ports = HoldPorts;
    fn set_up(&mut self, cx: &Cx) -> Result<HoldPorts, SchemaError> {
        Ok(Declare::declare(cx.me()))
    }
    async fn behavior(&mut self, p: &HoldPorts, _: &Cx) -> Behavior {
        p.value.write(self.0).await?;
        Ok(Flow::Continue)
    }
}

/// Two `Jmotor_i` in two assemblages drive one joint: it goes to the mean of their
/// commands, as rapier measures it; when one is deinstantiated, to the other's.
#[tokio::test(start_paused = true)]
async fn a_joint_gets_the_mean_of_every_live_jmotor_of_its_number() {
    let (net, clock) = network();
    let hand = Hand::new(HandConfig::seeded(1), Arc::new(clock.clone()));
    hand.spawn();
    let [joint, _] = finger_joints(3);

    struct Drive(Hand, f32);
    impl Schema for Drive {
        const NAME: &'static str = "Drive";
        const KIND: Kind = Kind::Assemblage;
        type Ports = ();
        fn set_up(&mut self, cx: &Cx) -> Result<(), SchemaError> {
            let [joint, _] = finger_joints(3);
            let motor = cx.instantiate_as(joint as u32, Jmotor::new(&self.0))?;
            let hold = cx.instantiate(Hold(self.1))?;
            cx.connect(&hold.ports().value, &motor.ports().desired);
            Ok(())
        }
    }
    let a = net.instantiate(Drive(hand.clone(), 0.2)).unwrap();
    net.instantiate(Drive(hand.clone(), 0.6)).unwrap();
    run_for(&clock, 1.0).await;
    let angle = hand.position(joint).unwrap();
    assert!(
        (angle - 0.4).abs() < 0.01,
        "joint at {angle}, not the mean 0.4"
    );
    a.stop();
    run_for(&clock, 1.0).await;
    let angle = hand.position(joint).unwrap();
    assert!(
        (angle - 0.6).abs() < 0.01,
        "joint at {angle} after one Jmotor left"
    );
}

/// `SEF_k` stands for the same object while it moves, as long as it moves less than the
/// gate between frames; an object taken away loses its SEF after a few frames, and one put
/// down far away gets a new number.
#[tokio::test(start_paused = true)]
async fn each_sef_keeps_standing_for_its_object_as_the_object_moves() {
    let (net, clock) = network();
    let hand = Hand::new(HandConfig::seeded(9), Arc::new(clock.clone()));
    hand.spawn();
    net.instantiate(Vision::new(&hand)).unwrap();
    run_for(&clock, 0.1).await;
    let numbers =
        |net: &Network| -> Vec<u32> { net.forall::<Sef>().iter().map(|s| s.number()).collect() };
    assert_eq!(numbers(&net), [1, 2, 3]);

    // The ball (SEF_3: the vision numbers objects by x at first sight) is pushed 2 cm per
    // frame across the table.
    let ball = 1;
    let watch = Arc::new(std::sync::Mutex::new(None));
    ports! { struct WatchPorts { in at: nalgebra::Point3<f32> = "at" } }
    struct Watch(Arc<std::sync::Mutex<Option<nalgebra::Point3<f32>>>>);
    impl Schema for Watch {
        const NAME: &'static str = "Watch";
        type Ports = WatchPorts;
        fn set_up(&mut self, cx: &Cx) -> Result<WatchPorts, SchemaError> {
            Ok(Declare::declare(cx.me()))
        }
        async fn behavior(&mut self, p: &WatchPorts, _: &Cx) -> Behavior {
            *self.0.lock().unwrap() = Some(p.at.read().await?);
            Ok(Flow::Continue)
        }
    }
    let watcher = net.instantiate(Watch(Arc::clone(&watch))).unwrap();
    let sef_3 = &net.forall::<Sef>()[2];
    net.cx().connect(&sef_3.ports().f1, &watcher.ports().at);
    for k in 1..=10 {
        hand.push(ball, [0.18 - 0.02 * k as f32, 0.12]).unwrap();
        run_for(&clock, 0.05).await;
    }
    run_for(&clock, 0.1).await;
    assert_eq!(numbers(&net), [1, 2, 3], "a moving object got a new SEF");
    let seen = watch.lock().unwrap().expect("SEF_3 reported nothing");
    let truth = hand.objects()[ball].position;
    assert!(
        (seen - truth).norm() < 0.01,
        "SEF_3 reports {seen}, the ball is at {truth}"
    );

    // Taken far away in one jump: the old SEF is lost, a new number comes.
    hand.push(ball, [0.3, -0.3]).unwrap();
    run_for(&clock, 0.5).await;
    assert_eq!(numbers(&net), [1, 2, 4]);
    let endings = endings(&net);
    assert!(endings.contains(&("SEF_3".into(), Ending::Deinstantiated)));
}

/// The same seed gives the same run: the same trace, to the nanosecond, and the same joint
/// angles, to the bit.
#[tokio::test(start_paused = true)]
async fn a_run_on_virtual_time_is_reproducible() {
    async fn run() -> (Vec<String>, Vec<u32>) {
        let (net, clock) = network();
        let hand = Hand::new(HandConfig::seeded(5), Arc::new(clock.clone()));
        hand.spawn();
        net.instantiate(Vision::new(&hand)).unwrap();
        run_for(&clock, 0.1).await;
        net.instantiate(imrs_schema::seed::Reach::new(&hand, 2, 0.1))
            .unwrap();
        run_for(&clock, 2.0).await;
        let joints = finger_joints(1).into_iter().chain(finger_joints(2));
        net.instantiate(imrs_schema::seed::Grip::new(&hand, joints, 0.01))
            .unwrap();
        run_for(&clock, 1.5).await;
        let trace = net.trace().iter().map(|e| e.to_string()).collect();
        let angles = (1..=14)
            .map(|j| hand.position(j).unwrap().to_bits())
            .collect();
        net.stop();
        (trace, angles)
    }
    let (first, second) = (run().await, run().await);
    assert!(first.0.len() > 50);
    assert_eq!(first, second);
}

/// A connection map given at instantiation is checked then; a refused couplet leaves no
/// instance behind (and no half-made connection that could take values), and names both
/// ends.
#[tokio::test(start_paused = true)]
async fn a_connection_map_is_checked_at_instantiation_and_a_refused_instance_does_not_stay() {
    use imrs_schema::Couplet;
    use imrs_schema::seed::TClosejoint;
    let (net, clock) = network();
    let hand = Hand::new(HandConfig::seeded(1), Arc::new(clock.clone()));
    let motor = net.instantiate_as(7, Jmotor::new(&hand)).unwrap();
    let refused = net.cx().instantiate_with(
        None,
        TClosejoint { del: 0.01 },
        &[
            Couplet::output("Pout", motor.port("desired").unwrap()),
            Couplet::input("Tin", motor.port("actual").unwrap()),
        ],
    );
    assert_eq!(
        refused.unwrap_err().to_string(),
        "cannot connect Jmotor_7(actual) to TClosejoint_1(Tin): Jmotor_7(actual) writes f32, \
         TClosejoint_1(Tin) reads bool"
    );
    run_for(&clock, 0.01).await;
    assert!(net.forall::<TClosejoint>().is_empty());
    assert!(endings(&net).contains(&("TClosejoint_1".into(), Ending::Deinstantiated)));
    let Err(error) = net.cx().instantiate_with(
        Some(2),
        TClosejoint { del: 0.01 },
        &[Couplet::input("Nope", motor.port("actual").unwrap())],
    ) else {
        panic!("a couplet on a port the schema lacks was accepted");
    };
    assert_eq!(error.to_string(), "TClosejoint_2 has no port Nope");
    let kept = net
        .cx()
        .instantiate_with(
            None,
            TClosejoint { del: 0.01 },
            &[Couplet::output("Pout", motor.port("desired").unwrap())],
        )
        .unwrap();
    assert_eq!(
        kept.number(),
        1,
        "the refused instance's number was not freed"
    );
}

/// Takes one value and stops.
struct TakeOne;

impl Schema for TakeOne {
    const NAME: &'static str = "TakeOne";
    type Ports = SinkPorts;
    fn set_up(&mut self, cx: &Cx) -> Result<SinkPorts, SchemaError> {
        Ok(Declare::declare(cx.me()))
    }
    async fn behavior(&mut self, p: &SinkPorts, _: &Cx) -> Behavior {
        p.value.read().await?;
        Ok(Flow::Stop)
    }
}

/// Instantiates a `TakeOne` on the counter's output, waits for it to end, and again, for
/// ever — as `Object?` keeps making `Objtest`s.
struct Spawner(imrs_schema::Output<u32>);

impl Schema for Spawner {
    const NAME: &'static str = "Spawner";
    type Ports = ();
    fn set_up(&mut self, _: &Cx) -> Result<(), SchemaError> {
        Ok(())
    }
    async fn behavior(&mut self, _: &(), cx: &Cx) -> Behavior {
        let taker = cx.instantiate(TakeOne)?;
        cx.connect(&self.0, &taker.ports().value);
        taker.ended().await;
        Ok(Flow::Continue)
    }
}

/// A network that instantiates without end runs in fixed memory: the trace keeps its
/// capacity, the instances that ended are gone, and the counter's output keeps no list of
/// its dead readers — the same after a run ten times longer.
#[tokio::test(start_paused = true)]
async fn a_network_that_instantiates_without_end_stays_in_fixed_memory() {
    let (net, clock) = network();
    net.log().set_capacity(100);
    let counter = net
        .instantiate(Count {
            next: 0,
            until: u32::MAX,
        })
        .unwrap();
    let output = counter.ports().count.clone();
    net.instantiate(Spawner(output.clone())).unwrap();
    let mut seen = Vec::new();
    for seconds in [1.0, 10.0] {
        run_for(&clock, seconds).await;
        assert!(net.log().len() <= 100);
        assert!(net.forall::<TakeOne>().len() <= 1);
        assert!(
            output.connections() <= 1,
            "{} readers kept",
            output.connections()
        );
        seen.push(net.log().forgotten());
    }
    // One taker per 10 ms: 100 in the first second, 1 000 in the next ten.
    assert!(seen[0] > 100 && seen[1] > 10 * seen[0] - 200, "{seen:?}");
}
