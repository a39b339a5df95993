//! The guarded move as port automata: a bounded abstraction of Grip and its `Closejoint_i`
//! in the seed's formal model, so that the composition can be explored, and a variant built
//! to deadlock.
//!
//! The abstraction adds to the seed's Grip what "ends" needs: in the seed `TClosejoint`
//! runs as long as its task-unit exists and Grip has no ports. Here each `Closejoint_i`
//! stops when it touches or reaches its limit and says so on a `Done` port, and Grip waits
//! for each `Done` in turn (as an assemblage ends when its components have).

use crate::automaton::{AutomatonError, Composition, PortAutomaton};

/// Grip's inputs, one per `Closejoint_i` it waits for.
const DONE: [&str; 8] = [
    "Done_1", "Done_2", "Done_3", "Done_4", "Done_5", "Done_6", "Done_7", "Done_8",
];

/// The most `Closejoint_i` these compositions take.
pub const MAX_JOINTS: u32 = DONE.len() as u32;

fn joints(n: u32) -> Result<(), AutomatonError> {
    if (1..=MAX_JOINTS).contains(&n) {
        Ok(())
    } else {
        Err(AutomatonError::NoPort {
            automaton: "Grip".into(),
            port: format!("Done_{n} (Grip waits for 1 to {MAX_JOINTS} joints)"),
        })
    }
}

/// `Closejoint_i`: at each of its joint's positions `p` (0 to `limit`) it reads its tactile
/// input `Tin`; touching, or at its limit, it writes `Done` and stops; else it drives its
/// joint one step on (`Pout` := `p + 1`, the seed's `Pin + Del`). With `ring`, it first
/// writes `Next` and reads `Prev` at every position: synchronized with its neighbours.
fn closejoint(i: u32, limit: u32, ring: bool) -> PortAutomaton {
    let mut automaton = PortAutomaton::new(format!("Closejoint_{i}"), "sync_0");
    for p in 0..=limit {
        let sense = format!("sense_{p}");
        if ring {
            automaton = automaton
                .write(
                    format!("sync_{p}"),
                    "Next",
                    i64::from(p),
                    format!("wait_{p}"),
                )
                .read(format!("wait_{p}"), "Prev", move |_| format!("sense_{p}"));
        } else {
            automaton = automaton.write(format!("sync_{p}"), "Pout", i64::from(p), sense.clone());
        }
        automaton = automaton.read(sense, "Tin", move |touching| {
            if touching != 0 || p == limit {
                "done".to_string()
            } else {
                format!("sync_{}", p + 1)
            }
        });
    }
    automaton.write("done", "Done", 1, "stop").stop("stop")
}

/// Grip: waits for each `Closejoint_i` to say it is done, in turn, then stops.
fn grip(n: u32) -> PortAutomaton {
    let mut automaton = PortAutomaton::new("Grip", "wait_1");
    for i in 1..=n {
        let next = if i == n {
            "stop".to_string()
        } else {
            format!("wait_{}", i + 1)
        };
        automaton = automaton.read(format!("wait_{i}"), DONE[i as usize - 1], move |_| {
            next.clone()
        });
    }
    automaton.stop("stop")
}

/// The automata of Grip with `n` `Closejoint_i` (1 to [`MAX_JOINTS`]) whose joints close
/// at most `limit` steps: each `Closejoint_i`, then Grip. `synchronized`: each
/// `Closejoint_i` synchronized with its neighbours in a ring, as
/// [`synchronized_grip_automata`] composes them.
pub fn grip_parts(
    n: u32,
    limit: u32,
    synchronized: bool,
) -> Result<Vec<PortAutomaton>, AutomatonError> {
    joints(n)?;
    let mut automata: Vec<PortAutomaton> = (1..=n)
        .map(|i| closejoint(i, limit, synchronized))
        .collect();
    automata.push(grip(n));
    Ok(automata)
}

/// Grip with `n` `Closejoint_i` (1 to [`MAX_JOINTS`]) whose joints close at most `limit`
/// steps: each `Tin` left to the environment (0 or 1 at every read), each `Pout` read by
/// the environment (the joint's motor), each `Done` connected to Grip. Every run ends.
pub fn grip_automata(n: u32, limit: u32) -> Result<Composition, AutomatonError> {
    let mut composition = Composition::new(grip_parts(n, limit, false)?)?;
    for i in 1..=n {
        let name = format!("Closejoint_{i}");
        composition = composition
            .environment((&name, "Tin"), [0, 1])?
            .sink((&name, "Pout"))?
            .connect((&name, "Done"), ("Grip", DONE[i as usize - 1]))?;
    }
    Ok(composition)
}

/// Built to deadlock: as [`grip_automata`], but the `Closejoint_i` linked in a ring, each
/// writing its step to the next before it reads the previous one's. Every write waits for a
/// read that waits behind a write. It is not the seed's option of synchronizing every
/// instance with every other, which can be written so that it works.
pub fn synchronized_grip_automata(n: u32, limit: u32) -> Result<Composition, AutomatonError> {
    let mut composition = Composition::new(grip_parts(n, limit, true)?)?;
    for i in 1..=n {
        let (name, next) = (
            format!("Closejoint_{i}"),
            format!("Closejoint_{}", i % n + 1),
        );
        composition = composition
            .environment((&name, "Tin"), [0, 1])?
            .connect((&name, "Next"), (&next, "Prev"))?
            .connect((&name, "Done"), ("Grip", DONE[i as usize - 1]))?;
    }
    Ok(composition)
}

/// The name of Grip's input for `Closejoint_i`'s `Done`.
pub fn grip_done_port(i: u32) -> Option<&'static str> {
    DONE.get(usize::try_from(i).ok()?.checked_sub(1)?).copied()
}
