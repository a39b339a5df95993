//! Which of the seed's mechanisms buys what: the cell run over the same arrivals with the
//! mechanisms added one at a time, each row summing what rapier and the coordinator saw
//! over every seed.

use super::{Assignment, CellConfig, CellError, Coordination, Report, run_all};
use std::fmt;
use std::ops::RangeInclusive;

/// One row: a set of mechanisms over every seed.
#[derive(Debug, Clone, PartialEq)]
pub struct AblationRow {
    /// What keeps the arms apart.
    pub coordination: Coordination,
    /// Who decides which arm does what.
    pub assignment: Assignment,
    /// Each seed's report, in the seeds' order.
    pub reports: Vec<Report>,
}

impl AblationRow {
    /// Collisions between arms, over every seed.
    pub fn collisions(&self) -> usize {
        self.reports
            .iter()
            .map(|r| r.measured.collisions.len())
            .sum()
    }

    /// Zone conflicts (intrusions), over every seed.
    pub fn zone_conflicts(&self) -> usize {
        self.reports
            .iter()
            .map(|r| r.measured.zone_conflicts.len())
            .sum()
    }

    /// The closest two arms came, over every seed, in metres.
    pub fn closest(&self) -> Option<f32> {
        self.reports
            .iter()
            .filter_map(|r| r.measured.closest)
            .min_by(f32::total_cmp)
    }

    /// Deadlocks the coordinator found and resolved, over every seed: of zones and the
    /// tool, and of space and zones (an arm asleep at a border in the way of one it waits
    /// for).
    pub fn deadlocks(&self) -> usize {
        self.reports.iter().map(|r| r.coordinator.resolved()).sum()
    }

    /// Requests answered with sleep, over every seed.
    pub fn slept(&self) -> u32 {
        self.reports.iter().map(|r| r.coordinator.slept).sum()
    }

    /// Units per hour, the mean over the seeds.
    pub fn per_hour(&self) -> f64 {
        let sum: f64 = self.reports.iter().map(Report::per_hour).sum();
        sum / self.reports.len().max(1) as f64
    }

    /// Arms that stopped working, over every seed.
    pub fn failures(&self) -> usize {
        self.reports.iter().map(|r| r.stats.failures.len()).sum()
    }

    /// Whether every seed's run was clean ([`Report::is_clean`]): rapier saw neither a
    /// collision nor a zone or tool conflict, and no arm failed.
    pub fn is_safe(&self) -> bool {
        self.reports.iter().all(Report::is_clean)
    }
}

/// The rows, as `cargo run --release --example ablation` prints them.
#[derive(Debug, Clone, PartialEq)]
pub struct Ablation {
    /// How many seeds each row ran, and for how long each.
    pub seeds: usize,
    /// Simulated hours per seed.
    pub hours: f64,
    /// The rows, in the order asked.
    pub rows: Vec<AblationRow>,
}

/// Runs each of `rows` on every seed of `seeds` for `hours`, on as many threads as the
/// machine has cores; the same seed gives each row the same arrivals.
pub fn ablation(
    rows: &[(Coordination, Assignment)],
    seeds: RangeInclusive<u64>,
    hours: f64,
) -> Result<Ablation, CellError> {
    let seeds: Vec<u64> = seeds.collect();
    let configs: Vec<CellConfig> = rows
        .iter()
        .flat_map(|&(coordination, assignment)| {
            seeds.iter().map(move |&seed| CellConfig {
                assignment,
                coordination,
                ..CellConfig::new(seed, hours)
            })
        })
        .collect();
    let reports = run_all(&configs)?;
    let mut reports = reports.into_iter();
    Ok(Ablation {
        seeds: seeds.len(),
        hours,
        rows: rows
            .iter()
            .map(|&(coordination, assignment)| AblationRow {
                coordination,
                assignment,
                reports: reports.by_ref().take(seeds.len()).collect(),
            })
            .collect(),
    })
}

impl fmt::Display for Ablation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{} seeds × {} h each, the same arrivals in every row; rapier measures collisions, \
             the closest approach and zone conflicts",
            self.seeds, self.hours
        )?;
        writeln!(f)?;
        writeln!(
            f,
            "| mechanisms | assignment | collisions | closest | zone conflicts | sleeps | deadlocks | units / h | |"
        )?;
        writeln!(f, "|---|---|---:|---:|---:|---:|---:|---:|---|")?;
        for row in &self.rows {
            let closest = row
                .closest()
                .map_or("—".to_string(), |c| format!("{:.0} mm", c * 1000.0));
            let verdict = if row.is_safe() {
                String::new()
            } else if row.failures() > 0 {
                format!("UNSAFE ({} arms failed)", row.failures())
            } else {
                "UNSAFE".to_string()
            };
            writeln!(
                f,
                "| {} | {} | {} | {} | {} | {} | {} | {:.1} | {} |",
                row.coordination,
                row.assignment,
                row.collisions(),
                closest,
                row.zone_conflicts(),
                row.slept(),
                row.deadlocks(),
                row.per_hour(),
                verdict
            )?;
        }
        Ok(())
    }
}
