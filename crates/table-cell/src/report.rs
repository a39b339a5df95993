//! What a run of the table cell made, and what rapier and the coordinator saw.

use std::fmt;
use std::time::Duration;

use imrs_ports::Name;
use imrs_sim::table::Measured;

use super::{CellConfig, CellStats};
use imrs_coord::coordinator::CoordinatorLog;
use imrs_coord::network::PortBound;
use imrs_coord::zones::DeadlockKind;

/// A run's report.
#[derive(Debug, Clone, PartialEq)]
pub struct Report {
    /// The run.
    pub config: CellConfig,
    /// The arms, in the scheduler's order.
    pub arms: Vec<Name>,
    /// Units completed.
    pub units: usize,
    /// What rapier measured.
    pub measured: Measured,
    /// What the coordinator did.
    pub coordinator: CoordinatorLog,
    /// What the arms did.
    pub stats: CellStats,
    /// Each port's worst case on the paper's bus (802.3, 100 m), the coordinator and the
    /// scheduler on one station and each arm on its own: a port whose `TIMEOUT` is below
    /// its worst round trip is a wiring warning.
    pub network: Vec<PortBound>,
    /// How long the run took on the wall clock.
    pub wall: Duration,
}

impl Report {
    /// Units per simulated hour.
    pub fn per_hour(&self) -> f64 {
        self.units as f64 / self.config.hours
    }

    /// The deadlocks of `kind` the coordinator found and resolved.
    pub fn deadlocks(&self, kind: DeadlockKind) -> usize {
        let found = self.coordinator.deadlocks.iter();
        found.filter(|deadlock| deadlock.kind == kind).count()
    }

    /// The deadlocks of space and `kind` the coordinator found and resolved: an arm asleep
    /// at a border, waiting on a resource of `kind` (through other sleepers), in the way of
    /// the arm that holds it.
    pub fn in_the_way(&self, kind: DeadlockKind) -> usize {
        let found = self.coordinator.in_the_way.iter();
        found.filter(|(_, of)| *of == kind).count()
    }

    /// Whether rapier saw neither a collision nor a zone or tool conflict, and every arm
    /// kept working.
    pub fn is_clean(&self) -> bool {
        self.measured.collisions.is_empty()
            && self.measured.zone_conflicts.is_empty()
            && self.measured.tool_conflicts.is_empty()
            && self.stats.failures.is_empty()
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (config, measured, log, stats) =
            (&self.config, &self.measured, &self.coordinator, &self.stats);
        writeln!(
            f,
            "coord_cell: seed {}, {} h simulated, {}, {}, {}",
            config.seed, config.hours, config.assignment, config.travel, config.variant
        )?;
        writeln!(
            f,
            "  units made              {} ({:.1} per hour)",
            self.units,
            self.per_hour()
        )?;
        for (index, arm) in self.arms.iter().enumerate() {
            let busy = stats.busy.get(index).copied().unwrap_or_default();
            writeln!(
                f,
                "  {arm:<6} jobs {:>5}, on jobs {:>5.1} % of the time (travel and waits included)",
                stats.jobs.get(index).copied().unwrap_or_default(),
                100.0 * busy.as_secs_f64() / (config.hours * 3600.0)
            )?;
        }
        writeln!(f, "measured by rapier")?;
        writeln!(f, "  collisions between arms {}", measured.collisions.len())?;
        if let Some(closest) = measured.closest {
            writeln!(f, "  closest two arms came   {:.0} mm", closest * 1000.0)?;
        }
        writeln!(
            f,
            "  zone conflicts          {}",
            measured.zone_conflicts.len()
        )?;
        writeln!(
            f,
            "  tool conflicts          {}",
            measured.tool_conflicts.len()
        )?;
        for (zone, time) in &measured.zone_time {
            writeln!(
                f,
                "  {zone:<8} occupied        {:>5.1} %",
                100.0 * time.as_secs_f64() / (config.hours * 3600.0)
            )?;
        }
        writeln!(f, "coordination")?;
        writeln!(
            f,
            "  requests granted / slept {} / {}",
            log.granted, log.slept
        )?;
        writeln!(
            f,
            "  deadlocks over zones, the tool and rights to move, found and resolved  {} \
             (zone {}, tool {}, mixed {})",
            log.deadlocks.len(),
            self.deadlocks(DeadlockKind::Zone),
            self.deadlocks(DeadlockKind::Tool),
            self.deadlocks(DeadlockKind::Mixed)
        )?;
        writeln!(
            f,
            "  deadlocks of space and zones (an arm asleep at a border in the way of one it \
             waits for), found and resolved  {} (zone {}, tool {}, mixed {}); \
             victims that backed off  {}",
            log.in_the_way.len(),
            self.in_the_way(DeadlockKind::Zone),
            self.in_the_way(DeadlockKind::Tool),
            self.in_the_way(DeadlockKind::Mixed),
            stats.victims
        )?;
        writeln!(
            f,
            "  an arm in another's way: stopped {}, went round {}, \
             two in each other's way parted by a back-off {}",
            stats.geometric_blocks, stats.detours, stats.back_offs
        )?;
        writeln!(
            f,
            "  ways ahead checked by the coordinator against the arms' told positions {}, \
             blocked {}; alternative trajectories computed {} of {} asked",
            log.checked, log.blocked, log.alternatives.1, log.alternatives.0
        )?;
        writeln!(
            f,
            "  rights to move in a shared zone given up by an arm stopped at a border  {}",
            stats.rights_given_up
        )?;
        let crossing: Vec<&PortBound> = self
            .network
            .iter()
            .filter(|bound| bound.stations.len() > 1)
            .collect();
        if let Some(worst) = crossing.iter().map(|bound| bound.round_trip).max() {
            writeln!(
                f,
                "on the cell bus  {} ports cross stations, worst round trip {:.1} µs",
                crossing.len(),
                worst.as_secs_f64() * 1e6
            )?;
        }
        for bound in crossing.iter().filter(|bound| bound.timeout_too_short()) {
            writeln!(f, "  WIRING {bound}")?;
        }
        for (a, b, at) in measured.collisions.iter().take(5) {
            writeln!(f, "  COLLISION {a} and {b} at {at}")?;
        }
        for (zone, at, arms) in measured.zone_conflicts.iter().take(5) {
            let arms: Vec<&str> = arms.iter().map(Name::as_str).collect();
            writeln!(f, "  ZONE CONFLICT in {zone} at {at}: {}", arms.join(", "))?;
        }
        for failure in &stats.failures {
            writeln!(f, "  FAILED {failure}")?;
        }
        Ok(())
    }
}
