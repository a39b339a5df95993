//! Deadlock diagnosis: a graph of which module waits on which, through which port.
//!
//! When a task starts a send, a query or a waitfor, its module waits on the modules at the
//! other end. If that closes a cycle — every module in it waiting on the next — the cycle is
//! reported by module and port names. It is a diagnosis, checked when a wait begins: the
//! cycle may still be broken, by a timeout or by a handler whose rank lets it run.

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hash, Hasher};

use imrs_ports::Name;

/// One wait of a module, or a free entry kept for the next (`id` 0; `port` then names the
/// last wait's port and means nothing), so that a module's waits in steady state allocate
/// nothing: `on` keeps its capacity.
#[derive(Debug)]
struct Wait {
    id: u64,
    port: Name,
    on: Vec<Name>,
}

impl Wait {
    fn is_live(&self) -> bool {
        self.id != 0
    }
}

/// A module's name as the graph's key: hashed by address, which interned names make unique
/// per text, so that a lookup neither reads nor hashes the text (a cell of a thousand
/// modules looks up two or three of them per message). The map is never iterated, so its
/// order, which varies from run to run, shows nowhere.
#[derive(Debug, Clone, PartialEq, Eq)]
struct Key(Name);

impl Hash for Key {
    fn hash<H: Hasher>(&self, state: &mut H) {
        state.write_usize(self.0.as_str().as_ptr() as usize);
    }
}

/// Spreads an address over the hash's bits (Fibonacci hashing): addresses differ mostly in
/// their middle bits, which the table's low bits must see.
#[derive(Default)]
struct AddressHasher(u64);

impl Hasher for AddressHasher {
    fn write(&mut self, bytes: &[u8]) {
        for &byte in bytes {
            self.0 = (self.0.rotate_left(8) ^ u64::from(byte)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
    }

    fn write_usize(&mut self, n: usize) {
        self.0 = (n as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
    }

    fn finish(&self) -> u64 {
        self.0
    }
}

#[derive(Debug, Default)]
pub(crate) struct WaitGraph {
    next_id: u64,
    /// Each module's waits, live and free. A module's entry stays until the module ends
    /// ([`WaitGraph::forget`]), so that a wait allocates only when a module has more waits
    /// at once than it ever had.
    waits: HashMap<Key, Vec<Wait>, BuildHasherDefault<AddressHasher>>,
    /// The path of the search in progress, reused from one search to the next.
    path: Vec<(Name, Name)>,
}

impl WaitGraph {
    /// Module `module` starts waiting through `port` on the modules that `peers` puts in the
    /// list it is given. Returns the wait's id, and the cycle it closes, if any, as
    /// `(module, port)` pairs starting at `module`.
    pub(crate) fn begin(
        &mut self,
        module: &Name,
        port: &Name,
        peers: impl FnOnce(&mut Vec<Name>),
    ) -> (u64, Option<Vec<(Name, Name)>>) {
        self.next_id += 1;
        let id = self.next_id;
        let waits = self.waits.entry(Key(module.clone())).or_default();
        let at = match waits.iter().position(|wait| !wait.is_live()) {
            Some(free) => free,
            None => {
                waits.push(Wait {
                    id: 0,
                    port: port.clone(),
                    on: Vec::new(),
                });
                waits.len() - 1
            }
        };
        let wait = &mut waits[at];
        wait.id = id;
        wait.port = port.clone();
        peers(&mut wait.on);
        // A wait on the module's own port is served by another thread of the module, which
        // keeps running whatever the ranks (the scheduler's priority-inversion rule).
        wait.on.retain(|peer| peer != module);
        // A cycle needs a peer that waits itself; in the usual case none does, and the
        // search (which clones names into its path) is skipped.
        let waits = &self.waits[&Key(module.clone())];
        if !waits[at].on.iter().any(|peer| self.is_waiting(peer)) {
            return (id, None);
        }
        let mut path = std::mem::take(&mut self.path);
        let mut cycle = None;
        for next in &waits[at].on {
            path.clear();
            path.push((module.clone(), port.clone()));
            if self.path_to(next, module, &mut path) {
                cycle = Some(path.clone());
                break;
            }
        }
        path.clear();
        self.path = path;
        (id, cycle)
    }

    /// Whether `module` has a wait in progress.
    fn is_waiting(&self, module: &Name) -> bool {
        self.waits
            .get(&Key(module.clone()))
            .is_some_and(|waits| waits.iter().any(Wait::is_live))
    }

    /// The wait `id` of `module` has ended.
    pub(crate) fn end(&mut self, module: &Name, id: u64) {
        if let Some(wait) = self
            .waits
            .get_mut(&Key(module.clone()))
            .and_then(|waits| waits.iter_mut().find(|wait| wait.id == id))
        {
            wait.id = 0;
            wait.on.clear();
        }
    }

    /// `module` has ended for good: its entries go.
    pub(crate) fn forget(&mut self, module: &Name) {
        let key = Key(module.clone());
        if self
            .waits
            .get(&key)
            .is_some_and(|waits| !waits.iter().any(Wait::is_live))
        {
            self.waits.remove(&key);
        }
    }

    /// Depth-first: does a chain of waits lead from `from` to `target`? Extends `path` with
    /// the steps taken when it does.
    fn path_to(&self, from: &Name, target: &Name, path: &mut Vec<(Name, Name)>) -> bool {
        if from == target {
            return true;
        }
        if path.iter().any(|(module, _)| module == from) {
            return false;
        }
        let Some(waits) = self.waits.get(&Key(from.clone())) else {
            return false;
        };
        for wait in waits.iter().filter(|wait| wait.is_live()) {
            for next in &wait.on {
                path.push((from.clone(), wait.port.clone()));
                if self.path_to(next, target, path) {
                    return true;
                }
                path.pop();
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn name(text: &str) -> Name {
        text.into()
    }

    #[test]
    fn a_two_module_cycle_is_found_when_it_closes() {
        let mut graph = WaitGraph::default();
        let (_, none) = graph.begin(&name("CHIP_IT"), &name("SHARE_FEEDER"), |on| {
            on.push(name("CHIP_IT2"))
        });
        assert_eq!(none, None);
        let (_, cycle) = graph.begin(&name("CHIP_IT2"), &name("SHARE_FEEDER1"), |on| {
            on.push(name("CHIP_IT"))
        });
        assert_eq!(
            cycle,
            Some(vec![
                (name("CHIP_IT2"), name("SHARE_FEEDER1")),
                (name("CHIP_IT"), name("SHARE_FEEDER")),
            ])
        );
    }

    #[test]
    fn a_wait_on_the_modules_own_port_is_no_cycle() {
        let mut graph = WaitGraph::default();
        let (_, cycle) = graph.begin(&name("CHIP_IT"), &name("READY_TO_CHIP"), |on| {
            on.push(name("CHIP_IT"))
        });
        assert_eq!(cycle, None);
    }

    #[test]
    fn an_ended_wait_breaks_the_cycle() {
        let mut graph = WaitGraph::default();
        let (first, _) = graph.begin(&name("A"), &name("P"), |on| on.push(name("B")));
        graph.end(&name("A"), first);
        let (_, cycle) = graph.begin(&name("B"), &name("Q"), |on| on.push(name("A")));
        assert_eq!(cycle, None);
    }

    #[test]
    fn a_chain_without_a_cycle_is_not_reported() {
        let mut graph = WaitGraph::default();
        graph.begin(&name("A"), &name("P"), |on| on.push(name("B")));
        graph.begin(&name("B"), &name("Q"), |on| on.push(name("C")));
        let (_, cycle) = graph.begin(&name("C"), &name("R"), |on| on.push(name("D")));
        assert_eq!(cycle, None);
        let (_, cycle) = graph.begin(&name("D"), &name("S"), |on| on.push(name("B")));
        assert_eq!(cycle.map(|c| c.len()), Some(3));
    }

    #[test]
    fn an_ended_wait_is_reused_and_a_forgotten_module_leaves_nothing() {
        let mut graph = WaitGraph::default();
        for _ in 0..3 {
            let (id, _) = graph.begin(&name("A"), &name("P"), |on| on.push(name("B")));
            graph.end(&name("A"), id);
        }
        assert_eq!(graph.waits[&Key(name("A"))].len(), 1, "one entry, reused");
        let (id, _) = graph.begin(&name("A"), &name("P"), |on| on.push(name("B")));
        graph.forget(&name("A"));
        assert!(
            graph.waits.contains_key(&Key(name("A"))),
            "a live wait is kept"
        );
        graph.end(&name("A"), id);
        graph.forget(&name("A"));
        assert!(graph.waits.is_empty());
    }
}
