//! Deadlock among exclusive resources: exclusive zones and tools meet every condition for
//! it, so the coordinator looks for a cycle of robots each sleeping on what the next holds.
//! A right to move in a shared zone is in the graph too: a robot that keeps it while it
//! sleeps at another border (instead of giving it up, as the seed's robots do) can close a
//! mixed cycle.

use std::collections::BTreeMap;

use imrs_ports::Name;

use super::{Resources, ZoneError};

/// A cycle of robots, each asleep on a resource the next one holds, and the one chosen to
/// back off.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Deadlock {
    /// The robots in the cycle, each waiting for the next (the last for the first).
    pub cycle: Vec<Name>,
    /// The one that backs off: the last in name order, so the choice is reproducible.
    pub victim: Name,
}

impl Resources {
    /// The first cycle in the wait-for graph of exclusive zones, tools and shared-zone
    /// movement rights, if any.
    pub fn deadlock(&self) -> Option<Deadlock> {
        self.deadlock_among(|_| true)
    }

    /// The first cycle among the sleepers for which `asleep` holds: a robot that was woken
    /// and is on its way to ask again waits for nothing yet, and is looked at again when it
    /// sleeps.
    pub fn deadlock_among(&self, asleep: impl Fn(&Name) -> bool) -> Option<Deadlock> {
        let waits_for = self.waits_for(asleep);
        let robots: Vec<Name> = waits_for.keys().cloned().collect();
        for start in robots {
            let mut path = vec![start.clone()];
            if let Some(cycle) = find_cycle(&waits_for, &mut path) {
                let victim = cycle.iter().max_by_key(|r| r.as_str()).cloned()?;
                return Some(Deadlock { cycle, victim });
            }
        }
        None
    }

    /// Whether `sleeper`, asleep, waits (through the robots asleep for which `asleep`
    /// holds, one holding what the next sleeps on) for something `holder` holds. A robot
    /// in `sleeper`'s way that `sleeper` waits for in turn closes a cycle the books alone
    /// do not show: one waiting on the other's zone, the other on its space.
    pub fn waits_on(&self, sleeper: &str, holder: &str, asleep: impl Fn(&Name) -> bool) -> bool {
        let waits_for = self.waits_for(asleep);
        let mut seen: Vec<&Name> = Vec::new();
        let mut next: Vec<&Name> = waits_for
            .get_key_value(&Name::from(sleeper))
            .map(|(name, _)| vec![name])
            .unwrap_or_default();
        while let Some(robot) = next.pop() {
            if seen.contains(&robot) {
                continue;
            }
            seen.push(robot);
            for held_by in waits_for.get(robot).into_iter().flatten() {
                if *held_by == holder {
                    return true;
                }
                next.push(held_by);
            }
        }
        false
    }

    /// Each sleeper for which `asleep` holds, and who holds what it sleeps on.
    fn waits_for(&self, asleep: impl Fn(&Name) -> bool) -> BTreeMap<Name, Vec<Name>> {
        let mut waits_for: BTreeMap<Name, Vec<Name>> = BTreeMap::new();
        for (_, holders, sleepers) in self
            .exclusive_waits()
            .into_iter()
            .chain(self.shared_waits())
        {
            for sleeper in sleepers.iter().filter(|sleeper| asleep(sleeper)) {
                waits_for
                    .entry(sleeper.clone())
                    .or_default()
                    .extend(holders.iter().filter(|h| *h != sleeper).cloned());
            }
        }
        waits_for
    }

    /// Resolves `deadlock`: its victim stops waiting (leaves every queue, and, stopped,
    /// moves in no shared zone), which breaks the cycle. What it is inside and the tools it
    /// holds are freed only when it says it has left them or put them down: the books
    /// follow the robot, which must first get out. Returns who is woken.
    pub fn resolve(&mut self, deadlock: &Deadlock) -> Result<Vec<Name>, ZoneError> {
        self.stop_waiting(deadlock.victim.as_str())
    }
}

/// Depth-first: a cycle through the last robot of `path` back to one on it.
fn find_cycle(waits_for: &BTreeMap<Name, Vec<Name>>, path: &mut Vec<Name>) -> Option<Vec<Name>> {
    let last = path.last()?.clone();
    for next in waits_for.get(&last).into_iter().flatten() {
        if let Some(at) = path.iter().position(|r| r == next) {
            return Some(path[at..].to_vec());
        }
        path.push(next.clone());
        if let Some(cycle) = find_cycle(waits_for, path) {
            return Some(cycle);
        }
        path.pop();
    }
    None
}
