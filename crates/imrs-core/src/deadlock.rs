//! Deadlock diagnosis: a graph of which module waits on which, through which port.
//!
//! When a task starts a send, a query or a waitfor, its module waits on the modules at the
//! other end. If that closes a cycle — every module in it waiting on the next — the cycle is
//! reported by module and port names. It is a diagnosis, checked when a wait begins: the
//! cycle may still be broken, by a timeout or by a handler whose rank lets it run.

use std::collections::BTreeMap;

use imrs_ports::Name;

#[derive(Debug)]
struct Wait {
    id: u64,
    port: Name,
    on: Vec<Name>,
}

#[derive(Debug, Default)]
pub(crate) struct WaitGraph {
    next_id: u64,
    waits: BTreeMap<Name, Vec<Wait>>,
}

impl WaitGraph {
    /// Module `module` starts waiting on `on` through `port`. Returns the wait's id, and the
    /// cycle it closes, if any, as `(module, port)` pairs starting at `module`.
    pub(crate) fn begin(
        &mut self,
        module: &Name,
        port: &Name,
        on: Vec<Name>,
    ) -> (u64, Option<Vec<(Name, Name)>>) {
        self.next_id += 1;
        let id = self.next_id;
        // A wait on the module's own port is served by another thread of the module, which
        // keeps running whatever the ranks (the scheduler's priority-inversion rule).
        let on: Vec<Name> = on.into_iter().filter(|peer| peer != module).collect();
        let on_for_search = on.clone();
        self.waits.entry(module.clone()).or_default().push(Wait {
            id,
            port: port.clone(),
            on,
        });
        let cycle = on_for_search.iter().find_map(|next| {
            let mut path = vec![(module.clone(), port.clone())];
            self.path_to(next, module, &mut path).then_some(path)
        });
        (id, cycle)
    }

    pub(crate) fn end(&mut self, module: &Name, id: u64) {
        if let Some(waits) = self.waits.get_mut(module) {
            waits.retain(|wait| wait.id != id);
            if waits.is_empty() {
                self.waits.remove(module);
            }
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
        let Some(waits) = self.waits.get(from) else {
            return false;
        };
        for wait in waits {
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
        let (_, none) = graph.begin(
            &name("CHIP_IT"),
            &name("SHARE_FEEDER"),
            vec![name("CHIP_IT2")],
        );
        assert_eq!(none, None);
        let (_, cycle) = graph.begin(
            &name("CHIP_IT2"),
            &name("SHARE_FEEDER1"),
            vec![name("CHIP_IT")],
        );
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
        let (_, cycle) = graph.begin(
            &name("CHIP_IT"),
            &name("READY_TO_CHIP"),
            vec![name("CHIP_IT")],
        );
        assert_eq!(cycle, None);
    }

    #[test]
    fn an_ended_wait_breaks_the_cycle() {
        let mut graph = WaitGraph::default();
        let (first, _) = graph.begin(&name("A"), &name("P"), vec![name("B")]);
        graph.end(&name("A"), first);
        let (_, cycle) = graph.begin(&name("B"), &name("Q"), vec![name("A")]);
        assert_eq!(cycle, None);
    }

    #[test]
    fn a_chain_without_a_cycle_is_not_reported() {
        let mut graph = WaitGraph::default();
        graph.begin(&name("A"), &name("P"), vec![name("B")]);
        graph.begin(&name("B"), &name("Q"), vec![name("C")]);
        let (_, cycle) = graph.begin(&name("C"), &name("R"), vec![name("D")]);
        assert_eq!(cycle, None);
        let (_, cycle) = graph.begin(&name("D"), &name("S"), vec![name("B")]);
        assert_eq!(cycle.map(|c| c.len()), Some(3));
    }
}
