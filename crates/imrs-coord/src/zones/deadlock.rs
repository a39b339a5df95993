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
    /// What each robot of the cycle sleeps on, in the same order: a zone or a tool.
    pub waiting_on: Vec<Name>,
    /// The one that backs off: the last in name order, so the choice is reproducible.
    pub victim: Name,
    /// What the cycle runs through.
    pub kind: DeadlockKind,
}

/// What a deadlock's robots sleep on, as the seed tells the cases apart. A cycle through
/// more than one kind is of the highest it runs through, in the order `Zone < Tool <
/// Mixed`; a cycle of rights to move alone is `Mixed` too.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum DeadlockKind {
    /// Exclusive zones only: the case in which "all the necessary conditions for deadlock
    /// hold".
    Zone,
    /// A tool, and no right to move: tools "are still exclusive use shared resources",
    /// whatever the zones.
    Tool,
    /// A right to move in a shared zone, kept by a robot asleep at another border: the
    /// seed's robots give it up there, and then no such cycle can form.
    Mixed,
}

impl std::fmt::Display for DeadlockKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Zone => "zone",
            Self::Tool => "tool",
            Self::Mixed => "mixed",
        })
    }
}

/// An edge of the wait-for graph: who holds the resource a sleeper sleeps on.
#[derive(Debug, Clone)]
struct Edge {
    holder: Name,
    resource: Name,
    /// What kind of wait it is: for an exclusive zone, a tool, or a right to move.
    kind: DeadlockKind,
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
        for start in waits_for.keys() {
            let mut path = vec![(start.clone(), None)];
            if let Some(cycle) = find_cycle(&waits_for, &mut path) {
                let victim = cycle.iter().map(|(r, _)| r).max_by_key(|r| r.as_str())?;
                let kinds = cycle.iter().map(|(_, edge)| edge.kind);
                let kind = kinds.max().unwrap_or(DeadlockKind::Zone);
                return Some(Deadlock {
                    victim: victim.clone(),
                    waiting_on: cycle.iter().map(|(_, e)| e.resource.clone()).collect(),
                    cycle: cycle.into_iter().map(|(robot, _)| robot).collect(),
                    kind,
                });
            }
        }
        None
    }

    /// Whether `sleeper`, asleep, waits (through the robots asleep for which `asleep`
    /// holds, one holding what the next sleeps on) for something `holder` holds: if so,
    /// the highest kind of wait on the first such chain found (as for [`DeadlockKind`]). A robot in `sleeper`'s way that `sleeper`
    /// waits for in turn closes a cycle the books alone do not show: one waiting on the
    /// other's zone or tool, the other on its space.
    pub fn waits_on(
        &self,
        sleeper: &str,
        holder: &str,
        asleep: impl Fn(&Name) -> bool,
    ) -> Option<DeadlockKind> {
        let waits_for = self.waits_for(asleep);
        let mut seen: Vec<&Name> = Vec::new();
        let mut next: Vec<(&Name, DeadlockKind)> = waits_for
            .get_key_value(&Name::from(sleeper))
            .map(|(name, _)| vec![(name, DeadlockKind::Zone)])
            .unwrap_or_default();
        while let Some((robot, kind)) = next.pop() {
            if seen.contains(&robot) {
                continue;
            }
            seen.push(robot);
            for edge in waits_for.get(robot).into_iter().flatten() {
                let kind = kind.max(edge.kind);
                if edge.holder == holder {
                    return Some(kind);
                }
                next.push((&edge.holder, kind));
            }
        }
        None
    }

    /// Each sleeper for which `asleep` holds, and who holds what it sleeps on.
    fn waits_for(&self, asleep: impl Fn(&Name) -> bool) -> BTreeMap<Name, Vec<Edge>> {
        let mut waits_for: BTreeMap<Name, Vec<Edge>> = BTreeMap::new();
        let exclusive = self
            .exclusive_waits()
            .into_iter()
            .map(|(resource, holders, sleepers)| {
                let kind = if self.is_tool(resource.as_str()) {
                    DeadlockKind::Tool
                } else {
                    DeadlockKind::Zone
                };
                (resource, holders, sleepers, kind)
            });
        let shared = (self.shared_waits().into_iter()).map(|(resource, holders, sleepers)| {
            (resource, holders, sleepers, DeadlockKind::Mixed)
        });
        for (resource, holders, sleepers, kind) in exclusive.chain(shared) {
            for sleeper in sleepers.iter().filter(|sleeper| asleep(sleeper)) {
                let edges = holders.iter().filter(|h| *h != sleeper).map(|holder| Edge {
                    holder: holder.clone(),
                    resource: resource.clone(),
                    kind,
                });
                waits_for.entry(sleeper.clone()).or_default().extend(edges);
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

/// Depth-first: a cycle through the last robot of `path` back to one on it. Each robot on
/// the path comes with the edge that led to it; each robot of the cycle found comes with
/// the edge it waits on.
fn find_cycle(
    waits_for: &BTreeMap<Name, Vec<Edge>>,
    path: &mut Vec<(Name, Option<Edge>)>,
) -> Option<Vec<(Name, Edge)>> {
    let last = path.last()?.0.clone();
    for edge in waits_for.get(&last).into_iter().flatten() {
        path.push((edge.holder.clone(), Some(edge.clone())));
        if let Some(at) = path[..path.len() - 1]
            .iter()
            .position(|(robot, _)| *robot == edge.holder)
        {
            // Robot `at` waits on the edge that led to `at + 1`, and the last on this one.
            let robots = path[at..path.len() - 1]
                .iter()
                .map(|(robot, _)| robot.clone());
            let edges = path[at + 1..].iter().filter_map(|(_, edge)| edge.clone());
            return Some(robots.zip(edges).collect());
        }
        if let Some(cycle) = find_cycle(waits_for, path) {
            return Some(cycle);
        }
        path.pop();
    }
    None
}
