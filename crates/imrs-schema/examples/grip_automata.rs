//! Grip and its `Closejoint_i` as port automata, composed and explored: every run of the
//! guarded move ends; the variant that synchronizes the joints in a ring deadlocks at once.
//! Run: `cargo run --release --example grip_automata`.

use imrs_schema::automaton::AutomatonError;
use imrs_schema::seed::{grip_automata, synchronized_grip_automata};

fn main() -> Result<(), AutomatonError> {
    const LIMIT: u32 = 4;
    for n in 1..=4 {
        let found = grip_automata(n, LIMIT)?.explore()?;
        println!(
            "Grip with {n} Closejoint (each at most {LIMIT} steps): {} states, every run ends: {}",
            found.states, found.always_ends
        );
    }
    let found = synchronized_grip_automata(3, LIMIT)?.explore()?;
    println!(
        "synchronized in a ring, 3 Closejoint: {} states, every run ends: {}",
        found.states, found.always_ends
    );
    if let Some(stuck) = found.deadlock {
        let states: Vec<String> = stuck
            .states
            .iter()
            .map(|(automaton, state)| format!("{automaton} in {state}"))
            .collect();
        println!(
            "  deadlock after {} moves: {}",
            stuck.path.len(),
            states.join(", ")
        );
    }
    Ok(())
}
