//! Port automata as a formal object: Grip with its `Closejoint_i` composed into one
//! automaton and explored (every run ends), a synchronized variant found to deadlock, bad
//! declarations refused by name, and each composition's run set beside the same automata
//! behaving as schemas on synchronous ports, on the same inputs.

use std::collections::BTreeMap;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use imrs_ports::{Clock, VirtualClock};
use imrs_schema::automaton::{AutomatonError, AutomatonSchema, Composition, PortAutomaton};
use imrs_schema::seed::{
    MAX_JOINTS, grip_automata, grip_done_port, grip_parts, synchronized_grip_automata,
};
use imrs_schema::{Input, Network, Output};

#[test]
fn grip_with_any_number_of_closejoints_ends_in_every_run() {
    for n in 1..=3 {
        let found = grip_automata(n, 4).unwrap().explore().unwrap();
        assert!(found.always_ends, "n = {n}: {found:?}");
        assert_eq!(found.deadlock, None);
        // Not a composition that ends because nothing can happen: each joint closes up to
        // five positions in any order of contacts, and Grip waits on each.
        assert!(
            found.states > 5usize.pow(n),
            "n = {n}: {} states",
            found.states
        );
    }
}

#[test]
fn the_synchronized_variant_is_found_to_deadlock_where_it_starts() {
    let found = synchronized_grip_automata(3, 4).unwrap().explore().unwrap();
    assert!(!found.always_ends);
    let stuck = found.deadlock.expect("a deadlock");
    // Every Closejoint writes to the next before reading the previous: no move at all.
    assert!(stuck.path.is_empty(), "{:?}", stuck.path);
    let states: Vec<(&str, &str)> = stuck
        .states
        .iter()
        .map(|(a, s)| (a.as_str(), s.as_str()))
        .collect();
    assert_eq!(
        states,
        [
            ("Closejoint_1", "sync_0"),
            ("Closejoint_2", "sync_0"),
            ("Closejoint_3", "sync_0"),
            ("Grip", "wait_1"),
        ]
    );
}

#[test]
fn a_deadlock_found_later_comes_with_the_moves_that_lead_to_it() {
    // B answers A's first request, then waits for a second that A never writes.
    let a = PortAutomaton::new("A", "ask")
        .write("ask", "Req", 1, "hear")
        .read("hear", "Rep", |_| "stop")
        .stop("stop");
    let b = PortAutomaton::new("B", "serve")
        .read("serve", "Req", |_| "answer")
        .write("answer", "Rep", 2, "serve");
    let found = Composition::new([a, b])
        .unwrap()
        .connect(("A", "Req"), ("B", "Req"))
        .unwrap()
        .connect(("B", "Rep"), ("A", "Rep"))
        .unwrap()
        .explore()
        .unwrap();
    let stuck = found.deadlock.expect("B waits for ever");
    assert_eq!(
        stuck.path,
        [
            "A writes 1 on Req, B reads it on Req",
            "B writes 2 on Rep, A reads it on Rep"
        ]
    );
    assert_eq!(stuck.states[1], ("B".to_string(), "serve".to_string()));
}

#[test]
fn bad_declarations_are_refused_by_name() {
    let lost = PortAutomaton::new("Lost", "start").write("start", "Out", 1, "nowhere");
    assert_eq!(
        Composition::new([lost]).unwrap_err(),
        AutomatonError::NoState {
            automaton: "Lost".into(),
            state: "nowhere".into()
        }
    );
    let twice = || PortAutomaton::new("Twice", "s").stop("s");
    assert_eq!(
        Composition::new([twice(), twice()]).unwrap_err(),
        AutomatonError::Duplicate("Twice".into())
    );
    let refused = grip_automata(3, 4)
        .unwrap()
        .connect(("Closejoint_1", "Nope"), ("Grip", "Done_1"))
        .unwrap_err();
    assert_eq!(
        refused.to_string(),
        "no port Nope on an automaton Closejoint_1 of this composition"
    );
    // A name that could not name an instance.
    for name in ["", "Grip/Closejoint"] {
        let bad = PortAutomaton::new(name, "s").stop("s");
        assert_eq!(
            Composition::new([bad]).unwrap_err(),
            AutomatonError::BadName(name.into())
        );
    }
    assert!(grip_automata(0, 4).is_err());
    assert!(grip_automata(MAX_JOINTS + 1, 4).is_err());
    // A transition to a state that does not exist is found when it is taken.
    let wrong = PortAutomaton::new("Wrong", "read").read("read", "In", |_| "gone");
    let error = Composition::new([wrong])
        .unwrap()
        .environment(("Wrong", "In"), [0])
        .unwrap()
        .explore()
        .unwrap_err();
    assert_eq!(
        error,
        AutomatonError::NoState {
            automaton: "Wrong".into(),
            state: "gone".into()
        }
    );
}

/// Each Closejoint's tactile readings: the first touches at its third read, the second at
/// once, the third never (it stops at its limit).
fn contacts() -> Vec<(&'static str, Vec<i64>)> {
    vec![
        ("Closejoint_1", vec![0, 0, 1]),
        ("Closejoint_2", vec![1]),
        ("Closejoint_3", vec![0, 0, 0, 0, 0]),
    ]
}

/// Runs `parts` as schemas on synchronous ports for `seconds` of virtual time: each
/// `Closejoint_i`'s `Done` to Grip, `Next` to the next one's `Prev` (if it has them), `Tin`
/// written with `contacts`, `Pout` read for ever. Returns whether every instance ended, and
/// the states each went through.
async fn behave(
    parts: Vec<PortAutomaton>,
    contacts: Vec<(&'static str, Vec<i64>)>,
    seconds: u64,
) -> (bool, BTreeMap<String, Vec<String>>) {
    let clock = VirtualClock::new();
    let net = Network::new("AUTOMATA", Arc::new(clock.clone()));
    let n = (parts.len() - 1) as u32;
    let mut visited = BTreeMap::new();
    let mut instances = BTreeMap::new();
    for (number, part) in parts.into_iter().enumerate() {
        let name = part.name().to_string();
        let schema = AutomatonSchema::new(part);
        visited.insert(name.clone(), schema.visited());
        let instance = net.instantiate_as(number as u32 + 1, schema).unwrap();
        // Each instance is named after its automaton.
        assert_eq!(
            instance.name().as_str(),
            format!("{name}_{}", number + 1),
            "an automaton's instance"
        );
        instances.insert(name, instance);
    }
    let cx = net.cx();
    for i in 1..=n {
        let me = &instances[&format!("Closejoint_{i}")];
        let grip = &instances["Grip"];
        cx.connect(
            me.ports().output("Done").unwrap(),
            grip.ports().input(grip_done_port(i).unwrap()).unwrap(),
        );
        if let Some(next) = me.ports().output("Next") {
            let after = &instances[&format!("Closejoint_{}", i % n + 1)];
            cx.connect(next, after.ports().input("Prev").unwrap());
        }
        if let Some(pout) = me.ports().output("Pout") {
            let motor = Input::<i64>::new("desired", "MOTOR");
            cx.connect(pout, &motor);
            tokio::spawn(async move { while motor.read().await.is_ok() {} });
        }
    }
    let mut writers = Vec::new();
    for (name, values) in contacts {
        let sensor = Output::<i64>::new("contact", "TACTILE");
        cx.connect(&sensor, instances[name].ports().input("Tin").unwrap());
        writers.push(tokio::spawn(async move {
            for value in values {
                if sensor.write(value).await.is_err() {
                    break;
                }
            }
            // Kept open: a read beyond the script waits, as the composition's does.
            std::future::pending::<()>().await;
        }));
    }
    let until = clock.now() + Duration::from_secs(seconds);
    imrs_core::time::drive(&clock, until).await;
    let ended = instances.values().all(|instance| !instance.is_live());
    writers.iter().for_each(tokio::task::JoinHandle::abort);
    net.stop();
    let visited = visited
        .into_iter()
        .map(|(name, states): (String, Arc<Mutex<Vec<String>>>)| {
            let states = states.lock().unwrap().clone();
            (name, states)
        })
        .collect();
    (ended, visited)
}

fn script(contacts: &[(&'static str, Vec<i64>)]) -> Vec<((&'static str, &'static str), Vec<i64>)> {
    contacts
        .iter()
        .map(|(name, values)| ((*name, "Tin"), values.clone()))
        .collect()
}

#[tokio::test(start_paused = true)]
async fn the_schemas_go_through_the_states_the_composition_runs_through() {
    let model = grip_automata(3, 4)
        .unwrap()
        .run(&script(&contacts()))
        .unwrap();
    assert!(model.ended);
    let (ended, visited) = behave(grip_parts(3, 4, false).unwrap(), contacts(), 5).await;
    assert!(ended, "{visited:?}");
    assert_eq!(visited, model.visited);
    // What the run went through, for the reader: the third joint stopped at its limit.
    assert_eq!(
        visited["Closejoint_3"].last().map(String::as_str),
        Some("stop")
    );
    assert!(visited["Closejoint_3"].contains(&"sense_4".to_string()));
}

#[tokio::test(start_paused = true)]
async fn the_synchronized_schemas_hang_where_the_composition_deadlocks() {
    let model = synchronized_grip_automata(3, 4)
        .unwrap()
        .run(&script(&contacts()))
        .unwrap();
    assert!(!model.ended);
    let (ended, visited) = behave(grip_parts(3, 4, true).unwrap(), contacts(), 5).await;
    assert!(!ended);
    assert_eq!(visited, model.visited);
    assert!(
        visited.values().all(|states| states.len() == 1),
        "{visited:?}"
    );
}

#[test]
fn a_run_that_goes_round_for_ever_is_reported_not_ended() {
    // A and B pass a value back and forth without end, reading nothing from outside.
    let a = PortAutomaton::new("A", "send")
        .write("send", "X", 1, "hear")
        .read("hear", "Y", |_| "send");
    let b = PortAutomaton::new("B", "hear")
        .read("hear", "X", |_| "send")
        .write("send", "Y", 2, "hear");
    let network = Composition::new([a, b])
        .unwrap()
        .connect(("A", "X"), ("B", "X"))
        .unwrap()
        .connect(("B", "Y"), ("A", "Y"))
        .unwrap();
    let run = network.run(&[]).unwrap();
    assert!(!run.ended);
    assert_eq!(run.visited["A"], ["send", "hear", "send"]);
    let found = network.explore().unwrap();
    assert!(found.deadlock.is_none() && !found.always_ends);
}
