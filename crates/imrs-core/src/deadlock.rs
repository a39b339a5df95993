//! Deadlock diagnosis, off the message path: which module waits on which, through which
//! port.
//!
//! A send or a query that has to wait notes its port and peer in its thread's
//! [`WaitRecord`](crate::wait_record::WaitRecord), which no other module writes; a rendezvous
//! that completes at once notes nothing, and nothing cell-wide is touched for it. The graph is
//! built from those records only when it can show something: on any clock but a virtual
//! one, at each tick of the cell's watchdog after a wait has begun; on virtual time, as a
//! wait begins whose peer is itself waiting, so that a cycle is stamped with the instant it
//! closed even if a handler breaks it within that instant. A cycle — every module in it
//! waiting on the next — is reported once by module and port names, from the wait that
//! closed it (the last to begin). It is a diagnosis: the cycle may still be broken, by a
//! timeout or by a handler whose rank lets it run.

use std::cmp::Reverse;
use std::collections::{HashMap, HashSet};
use std::sync::Arc;

use imrs_ports::Name;

use crate::thread::Thread;
use crate::wait_record::Wait;

/// The threads of a module's running copy, for the diagnosis to read their waits: kept
/// with the module's entry among the cell's running modules, under that list's lock. The
/// first inline, so that a module of one task (most of them) allocates no list.
#[derive(Debug, Default)]
pub(crate) struct ModuleThreads {
    first: Option<Arc<Thread>>,
    more: Vec<Arc<Thread>>,
}

impl ModuleThreads {
    pub(crate) fn add(&mut self, thread: &Arc<Thread>) {
        match self.first {
            None => self.first = Some(Arc::clone(thread)),
            Some(_) => self.more.push(Arc::clone(thread)),
        }
    }

    pub(crate) fn remove(&mut self, thread: &Arc<Thread>) {
        if self
            .first
            .as_ref()
            .is_some_and(|first| Arc::ptr_eq(first, thread))
        {
            self.first = self.more.pop();
        } else {
            self.more.retain(|known| !Arc::ptr_eq(known, thread));
        }
    }

    /// The copy has ended: none of its threads waits any more.
    pub(crate) fn clear(&mut self) {
        self.first = None;
        self.more = Vec::new();
    }

    /// Whether any thread of the copy has a wait in progress.
    pub(crate) fn any_waiting(&self) -> bool {
        self.iter().any(|thread| thread.waits.is_waiting())
    }

    fn iter(&self) -> impl Iterator<Item = &Arc<Thread>> {
        self.first.iter().chain(&self.more)
    }
}

/// A cycle found: the module and task whose wait closed it, and the cycle as
/// `(module, port)` steps starting there.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Found {
    pub(crate) module: Name,
    pub(crate) task: Name,
    pub(crate) cycle: Vec<(Name, Name)>,
}

/// One wait in progress, as the graph sees it.
struct LiveWait {
    module: Name,
    task: Name,
    /// The port's [`Name::token`]: its name is looked up only for a cycle found.
    port: usize,
    on: Vec<Name>,
    seq: u32,
    /// The thread and wait number: the wait's identity while it lasts.
    key: (usize, u32),
}

/// The state the diagnosis keeps between two looks.
#[derive(Debug, Default)]
pub(crate) struct Diagnosis {
    /// The waits that closed a cycle already reported, kept while they last, so that a
    /// cycle that stands is named once.
    reported: HashSet<(usize, u32)>,
}

impl Diagnosis {
    /// Looks at every wait of `modules` in progress and returns the cycles not reported
    /// before. `users_of` names the running users of a port (by its token), whom its
    /// owner's post waits on.
    pub(crate) fn look<'m>(
        &mut self,
        modules: impl Iterator<Item = (&'m Name, &'m ModuleThreads)> + Clone,
        users_of: impl Fn(usize) -> &'m [Name],
    ) -> Vec<Found> {
        let waits = live_waits(modules, users_of);
        self.reported
            .retain(|key| waits.iter().any(|wait| wait.key == *key));
        let mut newest_first: Vec<usize> = (0..waits.len()).collect();
        newest_first.sort_by_key(|&index| Reverse(waits[index].seq));
        let mut found = Vec::new();
        for index in newest_first {
            let wait = &waits[index];
            if self.reported.contains(&wait.key) {
                continue;
            }
            let Some(path) = cycle_from(&waits, index) else {
                continue;
            };
            // A cycle is reported from its newest wait, once.
            if path.iter().any(|&step| waits[step].seq > wait.seq) {
                continue;
            }
            let Some(cycle) = path
                .iter()
                .map(|&step| {
                    Some((
                        waits[step].module.clone(),
                        Name::from_token(waits[step].port)?,
                    ))
                })
                .collect()
            else {
                continue;
            };
            self.reported.insert(wait.key);
            found.push(Found {
                module: wait.module.clone(),
                task: wait.task.clone(),
                cycle,
            });
        }
        found
    }
}

fn live_waits<'m>(
    modules: impl Iterator<Item = (&'m Name, &'m ModuleThreads)> + Clone,
    users_of: impl Fn(usize) -> &'m [Name],
) -> Vec<LiveWait> {
    let mut waits = Vec::new();
    let mut read: Vec<Wait> = Vec::new();
    // A module waited on that is not running cannot be in a cycle.
    let mut running: Option<HashMap<usize, &Name>> = None;
    for (module, threads) in modules.clone() {
        for thread in threads.iter() {
            read.clear();
            thread.waits.live(&mut read);
            for wait in &read {
                let mut on: Vec<Name> = match wait.peer {
                    0 => users_of(wait.port).to_vec(),
                    peer => {
                        let running = running.get_or_insert_with(|| {
                            let by_token = modules.clone().map(|(name, _)| (name.token(), name));
                            by_token.collect()
                        });
                        running
                            .get(&peer)
                            .map(|&name| name.clone())
                            .into_iter()
                            .collect()
                    }
                };
                // A wait on the module's own port is served by another thread of the
                // module, which keeps running whatever the ranks (the scheduler's
                // priority-inversion rule).
                on.retain(|peer| peer != module);
                if on.is_empty() {
                    continue;
                }
                waits.push(LiveWait {
                    module: module.clone(),
                    task: thread.task.clone(),
                    port: wait.port,
                    on,
                    seq: wait.seq,
                    key: (Arc::as_ptr(thread) as usize, wait.seq),
                });
            }
        }
    }
    waits
}

/// The waits of a cycle through wait `start`, beginning with it, if one leads back to its
/// module: depth-first, each module at most once.
fn cycle_from(waits: &[LiveWait], start: usize) -> Option<Vec<usize>> {
    let mut path = vec![start];
    for next in &waits[start].on {
        if path_to(waits, next, &waits[start].module, &mut path) {
            return Some(path);
        }
    }
    None
}

/// Does a chain of waits lead from module `from` to `target`? Extends `path` with the waits
/// taken when it does.
fn path_to(waits: &[LiveWait], from: &Name, target: &Name, path: &mut Vec<usize>) -> bool {
    if from == target {
        return true;
    }
    if path.iter().any(|&step| &waits[step].module == from) {
        return false;
    }
    for (index, wait) in waits.iter().enumerate() {
        if &wait.module != from {
            continue;
        }
        path.push(index);
        if wait
            .on
            .iter()
            .any(|next| path_to(waits, next, target, path))
        {
            return true;
        }
        path.pop();
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::order::Rank;
    use crate::wait_record::WaitId;

    fn name(text: &str) -> Name {
        text.into()
    }

    /// A module of one thread, waiting as `waits` says: (port, peer).
    fn module(thread: &str, waits: &[(&str, Option<&str>)]) -> (ModuleThreads, Vec<WaitId>) {
        let mut threads = ModuleThreads::default();
        let thread = Arc::new(Thread::new(name(thread), Rank::from_raw(0)));
        let ids = waits
            .iter()
            .map(|(port, peer)| thread.waits.begin(&name(port), peer.map(name).as_ref()))
            .collect();
        threads.add(&thread);
        (threads, ids)
    }

    fn look(diagnosis: &mut Diagnosis, modules: &[(Name, &ModuleThreads)]) -> Vec<Found> {
        diagnosis.look(
            modules.iter().map(|(module, threads)| (module, *threads)),
            |_| &[],
        )
    }

    #[test]
    fn a_two_module_cycle_is_named_from_the_wait_that_closed_it_and_only_once() {
        let (chip_it, _) = module("CHIP_IT", &[("SHARE_FEEDER1", Some("CHIP_IT2"))]);
        let (chip_it2, _) = module("CHIP_IT2", &[("SHARE_FEEDER", Some("CHIP_IT"))]);
        let modules = [(name("CHIP_IT"), &chip_it), (name("CHIP_IT2"), &chip_it2)];
        let mut diagnosis = Diagnosis::default();
        let found = look(&mut diagnosis, &modules);
        assert_eq!(
            found,
            [Found {
                module: name("CHIP_IT2"),
                task: name("CHIP_IT2"),
                cycle: vec![
                    (name("CHIP_IT2"), name("SHARE_FEEDER")),
                    (name("CHIP_IT"), name("SHARE_FEEDER1")),
                ],
            }]
        );
        assert_eq!(
            look(&mut diagnosis, &modules),
            [],
            "a standing cycle is named once"
        );
    }

    #[test]
    fn a_wait_on_the_modules_own_port_is_no_cycle() {
        let (chip_it, _) = module("CHIP_IT", &[("READY_TO_CHIP", Some("CHIP_IT"))]);
        let modules = [(name("CHIP_IT"), &chip_it)];
        assert_eq!(look(&mut Diagnosis::default(), &modules), []);
    }

    #[test]
    fn a_chain_without_a_cycle_is_not_reported_and_its_closing_is() {
        let (a, _) = module("A", &[("P", Some("B"))]);
        let (b, _) = module("B", &[("Q", Some("C"))]);
        let (c, _) = module("C", &[("R", Some("D"))]);
        let mut diagnosis = Diagnosis::default();
        let chain = [(name("A"), &a), (name("B"), &b), (name("C"), &c)];
        assert_eq!(look(&mut diagnosis, &chain), []);
        let (d, _) = module("D", &[("S", Some("B"))]);
        let closed = [
            (name("A"), &a),
            (name("B"), &b),
            (name("C"), &c),
            (name("D"), &d),
        ];
        let found = look(&mut diagnosis, &closed);
        assert_eq!(found.len(), 1);
        assert_eq!(found[0].module, name("D"));
        assert_eq!(found[0].cycle.len(), 3, "{found:?}");
    }

    #[test]
    fn an_ended_wait_breaks_the_cycle() {
        let (a, ids) = module("A", &[("P", Some("B"))]);
        let (b, _) = module("B", &[("Q", Some("A"))]);
        a.first.as_ref().unwrap().waits.end(ids[0]);
        let modules = [(name("A"), &a), (name("B"), &b)];
        assert_eq!(look(&mut Diagnosis::default(), &modules), []);
    }

    #[test]
    fn an_owners_post_waits_on_the_ports_running_users() {
        let (owner, _) = module("OWNER", &[("BROADCAST", None)]);
        let (user, _) = module("USER", &[("BACK", Some("OWNER"))]);
        let modules = [(name("OWNER"), &owner), (name("USER"), &user)];
        let users = [name("USER")];
        let found = Diagnosis::default().look(
            modules.iter().map(|(module, threads)| (module, *threads)),
            |port| {
                if port == name("BROADCAST").token() {
                    &users
                } else {
                    &[]
                }
            },
        );
        assert_eq!(found.len(), 1, "{found:?}");
    }
}
