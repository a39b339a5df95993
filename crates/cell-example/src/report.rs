//! The report of a run, readable at a glance, and the same byte for byte for the same seed
//! and flags (the last line, wall time, aside).

use std::collections::BTreeMap;
use std::fmt;

use imrs_sim::PalletId;

use crate::chip::{FeederPolicy, ZoneWaits};
use crate::run::RunRecord;

/// One line's figures.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LineFigures {
    /// Pallets the gate released.
    pub released: u32,
    /// Pallets that left the line done.
    pub completed: u32,
    /// Pallets still on the conveyor at the end.
    pub in_progress: u32,
    /// Pallets taken off the line (jams).
    pub scrapped: u32,
    /// Chips on the completed cards.
    pub chips: u32,
    /// Seconds between completed pallets: mean and worst.
    pub cycle: Option<(f64, f64)>,
}

/// One invariant, checked against what was measured.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Invariant {
    /// What must hold.
    pub rule: &'static str,
    /// Whether it held.
    pub held: bool,
    /// The evidence when it did not.
    pub detail: String,
}

/// A run's report.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// The feeder policy.
    pub policy: FeederPolicy,
    /// The seed.
    pub seed: u64,
    /// Simulated hours.
    pub hours: f64,
    /// Injected faults, as given.
    pub faults: Vec<String>,
    /// Per line, A then B.
    pub lines: [LineFigures; 2],
    /// Timeouts raised, per port.
    pub timeouts: BTreeMap<String, u32>,
    /// Tasks and modules restarted.
    pub restarts: u32,
    /// Alarms raised for the operator.
    pub alarms: u32,
    /// Deadlock cycles reported.
    pub deadlocks: u32,
    /// Whether both chip robots went on working after the last deadlock.
    pub deadlocks_broken: bool,
    /// Entries into the feeder zone per chip robot, measured by rapier.
    pub zone_entries: [u32; 2],
    /// Times a robot entered the zone while the other was inside.
    pub zone_conflicts: u32,
    /// Seconds both chip robots were inside together.
    pub zone_shared_seconds: f64,
    /// Contacts between robots, measured by rapier.
    pub collisions: u32,
    /// The chip robots' waits for the zone.
    pub waits: [ZoneWaits; 2],
    /// The invariants.
    pub invariants: Vec<Invariant>,
    /// Simulated seconds.
    pub simulated: f64,
    /// Wall seconds.
    pub wall: f64,
}

impl Report {
    /// The report of `record`.
    pub fn of(record: &RunRecord) -> Self {
        let tally = &record.tally;
        let mut lines = tally.lines.clone();
        for (line, figures) in lines.iter_mut().enumerate() {
            figures.in_progress = record
                .pallets_left
                .iter()
                .filter(|(l, _, _)| l.index() == line)
                .count() as u32;
            figures.cycle = tally.cycles[line].mean_and_worst();
        }
        let deadlocks_broken = tally.last_deadlock.is_none_or(|last| {
            tally
                .chips_inserted_after
                .iter()
                .all(|after| after.is_some_and(|at| at > last))
        });
        let (early_screw, early_chip) = (&tally.early_screw, &tally.early_chip);
        let (zone_conflicts, zone_shared) = (tally.zone_conflicts, tally.zone_shared);

        let mut invariants = Vec::new();
        let lost: Vec<String> = lines
            .iter()
            .zip(["A", "B"])
            .filter(|(f, _)| f.released != f.completed + f.in_progress + f.scrapped)
            .map(|(f, line)| {
                format!(
                    "line {line}: {} released, {} completed, {} in progress, {} scrapped",
                    f.released, f.completed, f.in_progress, f.scrapped
                )
            })
            .collect();
        invariants.push(Invariant {
            rule: "no pallet lost (released = completed + in progress + scrapped)",
            held: lost.is_empty(),
            detail: lost.join("; "),
        });
        invariants.push(Invariant {
            rule: "no card screwed before it was loaded",
            held: early_screw.is_empty(),
            detail: pallets(early_screw),
        });
        invariants.push(Invariant {
            rule: "no chip inserted before its card was screwed",
            held: early_chip.is_empty(),
            detail: pallets(early_chip),
        });
        if record.config.feeder == FeederPolicy::Arbiter {
            invariants.push(Invariant {
                rule: "no two robots in the feeder zone together",
                held: zone_conflicts == 0,
                detail: format!("{zone_conflicts} conflicts, {zone_shared:.1} s shared"),
            });
        }

        Self {
            policy: record.config.feeder,
            seed: record.config.seed,
            hours: record.config.hours,
            faults: record
                .config
                .faults
                .iter()
                .map(ToString::to_string)
                .collect(),
            lines,
            timeouts: tally.timeouts.clone(),
            restarts: tally.restarts,
            alarms: tally.alarms,
            deadlocks: tally.deadlocks,
            deadlocks_broken,
            zone_entries: tally.zone_entries,
            zone_conflicts,
            zone_shared_seconds: zone_shared,
            collisions: tally.collisions,
            waits: record.waits,
            invariants,
            simulated: record.simulated.as_secs_f64(),
            wall: record.wall.as_secs_f64(),
        }
    }

    /// Cards completed per hour on `line`.
    pub fn cards_per_hour(&self, line: usize) -> f64 {
        f64::from(self.lines[line].completed) / self.hours.max(1e-9)
    }

    /// Whether every invariant held.
    pub fn all_held(&self) -> bool {
        self.invariants.iter().all(|invariant| invariant.held)
    }

    /// The two policies side by side.
    pub fn side_by_side(appendix: &Report, arbiter: &Report) -> String {
        let mut out = String::new();
        let row = |out: &mut String, what: &str, a: String, b: String| {
            out.push_str(&format!("  {what:<34}{a:>12}{b:>12}\n"));
        };
        out.push_str(&format!(
            "  {:<34}{:>12}{:>12}\n",
            "", "appendix", "arbiter"
        ));
        for (line, name) in [(0, "A"), (1, "B")] {
            row(
                &mut out,
                &format!("cards per hour, line {name}"),
                format!("{:.1}", appendix.cards_per_hour(line)),
                format!("{:.1}", arbiter.cards_per_hour(line)),
            );
        }
        let waited = |r: &Report| format!("{:.1}", r.waits[0].waited + r.waits[1].waited);
        row(
            &mut out,
            "seconds waiting for the zone",
            waited(appendix),
            waited(arbiter),
        );
        let refused = |r: &Report| format!("{}", r.waits[0].refused + r.waits[1].refused);
        row(
            &mut out,
            "zone requests refused",
            refused(appendix),
            refused(arbiter),
        );
        row(
            &mut out,
            "deadlocks",
            appendix.deadlocks.to_string(),
            arbiter.deadlocks.to_string(),
        );
        row(
            &mut out,
            "zone conflicts (rapier)",
            appendix.zone_conflicts.to_string(),
            arbiter.zone_conflicts.to_string(),
        );
        row(
            &mut out,
            "collisions (rapier)",
            appendix.collisions.to_string(),
            arbiter.collisions.to_string(),
        );
        out
    }
}

fn pallets(pallets: &[PalletId]) -> String {
    pallets
        .iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join(", ")
}

fn policy_name(policy: FeederPolicy) -> &'static str {
    match policy {
        FeederPolicy::Appendix => "appendix",
        FeederPolicy::Arbiter => "arbiter",
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "IMRS chip-insertion cell: seed {}, {:.2} h simulated, feeder policy {}",
            self.seed,
            self.hours,
            policy_name(self.policy)
        )?;
        if self.faults.is_empty() {
            writeln!(f, "faults injected: none")?;
        } else {
            writeln!(f, "faults injected: {}", self.faults.join(", "))?;
        }
        writeln!(f)?;
        writeln!(f, "  {:<34}{:>12}{:>12}", "", "line A", "line B")?;
        let row = |f: &mut fmt::Formatter<'_>, what: &str, value: &dyn Fn(usize) -> String| {
            writeln!(f, "  {what:<34}{:>12}{:>12}", value(0), value(1))
        };
        row(f, "pallets released", &|l| {
            self.lines[l].released.to_string()
        })?;
        row(f, "pallets completed", &|l| {
            self.lines[l].completed.to_string()
        })?;
        row(f, "pallets in progress", &|l| {
            self.lines[l].in_progress.to_string()
        })?;
        row(f, "pallets scrapped (jammed)", &|l| {
            self.lines[l].scrapped.to_string()
        })?;
        row(f, "cards per hour", &|l| {
            format!("{:.1}", self.cards_per_hour(l))
        })?;
        row(f, "cycle time mean (s)", &|l| {
            self.lines[l]
                .cycle
                .map_or("-".into(), |(mean, _)| format!("{mean:.1}"))
        })?;
        row(f, "cycle time worst (s)", &|l| {
            self.lines[l]
                .cycle
                .map_or("-".into(), |(_, worst)| format!("{worst:.1}"))
        })?;
        row(f, "chips per completed card", &|l| {
            let figures = &self.lines[l];
            if figures.completed == 0 {
                "-".into()
            } else {
                format!(
                    "{:.2}",
                    f64::from(figures.chips) / f64::from(figures.completed)
                )
            }
        })?;
        row(f, "feeder zone entries (rapier)", &|l| {
            self.zone_entries[l].to_string()
        })?;
        row(f, "zone requests / refused", &|l| {
            format!("{}/{}", self.waits[l].asks, self.waits[l].refused)
        })?;
        row(f, "seconds waiting for the zone", &|l| {
            format!("{:.1}", self.waits[l].waited)
        })?;
        writeln!(f)?;
        if self.timeouts.is_empty() {
            writeln!(f, "timeouts: none")?;
        } else {
            let timeouts: Vec<String> = self
                .timeouts
                .iter()
                .map(|(port, n)| format!("{port} {n}"))
                .collect();
            writeln!(f, "timeouts: {}", timeouts.join(", "))?;
        }
        writeln!(f, "restarts: {}   alarms: {}", self.restarts, self.alarms)?;
        let broken = if self.deadlocks == 0 {
            ""
        } else if self.deadlocks_broken {
            " (all broken: both robots went on)"
        } else {
            " (NOT broken: a robot stayed stuck)"
        };
        writeln!(f, "deadlocks met: {}{broken}", self.deadlocks)?;
        writeln!(
            f,
            "feeder zone, measured by rapier: {} conflicts ({:.1} s shared), {} collisions",
            self.zone_conflicts, self.zone_shared_seconds, self.collisions
        )?;
        writeln!(f)?;
        writeln!(f, "invariants:")?;
        for invariant in &self.invariants {
            let mark = if invariant.held { "ok" } else { "VIOLATED" };
            write!(f, "  [{mark}] {}", invariant.rule)?;
            if !invariant.held {
                write!(f, ": {}", invariant.detail)?;
            }
            writeln!(f)?;
        }
        Ok(())
    }
}

/// The last line of a report: how fast the simulation ran. It differs from run to run.
pub fn speed_line(report: &Report) -> String {
    let ratio = report.simulated / report.wall.max(1e-9);
    format!(
        "simulated {:.0} s in {:.2} s of wall time ({ratio:.0}x real time)",
        report.simulated, report.wall
    )
}
