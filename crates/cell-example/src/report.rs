//! The report of a run, readable at a glance, and the same byte for byte for the same seed
//! and flags (the last lines, on wall time, aside).

use std::collections::BTreeMap;
use std::fmt;

use imrs_sim::{FeederId, PalletId, RobotId, Role};

use crate::alarms::AlarmKind;
use crate::chip::ZoneWaits;
use crate::feeder_policy::FeederPolicy;
use crate::gate::CycleTimeHistory;
use crate::outage::Outage;
use crate::run_record::RunRecord;
use crate::tally::{Cycles, LineFigures};

/// One invariant, checked against what was measured.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Invariant {
    /// What must hold.
    pub rule: &'static str,
    /// Whether it held.
    pub held: bool,
    /// The evidence when it did not.
    pub detail: String,
    /// Whether the run fails when it does not hold. An invariant the policy is known not to
    /// keep (the feeder zone under the Appendix's scheme, note 6) is checked and reported
    /// all the same, as a finding.
    pub required: bool,
}

/// One feeder at the end of the run.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct FeederFigures {
    /// The feeder.
    pub feeder: FeederId,
    /// The chip number it holds.
    pub chip: u32,
    /// The chips it has left.
    pub stock: u32,
    /// How often a robot found it empty.
    pub empties: u32,
    /// How often the operator refilled it.
    pub refills: u32,
}

/// How one robot spent the run, in seconds, as the simulation measured it.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotFigures {
    /// The robot.
    pub robot: RobotId,
    /// Moving its tool.
    pub moving: f64,
    /// Grasping, inserting, picking, placing or screwing.
    pub working: f64,
    /// Waiting for the feeder zone (chip robots).
    pub waiting: f64,
    /// The rest.
    pub idle: f64,
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
    /// Alarms per kind.
    pub alarm_kinds: Vec<(String, u32)>,
    /// Deadlock cycles reported.
    pub deadlocks: u32,
    /// Whether both chip robots went on working after the last deadlock.
    pub deadlocks_broken: bool,
    /// Seconds the members of deadlocks spent blocked in them, added over the robots.
    pub deadlock_lost: f64,
    /// Per line, per station (load, chip): seconds between pallets held in place, mean and
    /// worst.
    pub stations: [[Option<(f64, f64)>; 2]; 2],
    /// Per line, GATE's CYCLE_TIME over the run.
    pub cycle_times: [CycleTimeHistory; 2],
    /// Chips whose place on the card was measured, and the worst distance from the work
    /// schedule's place, in millimetres.
    pub chip_places: (u32, f64),
    /// The feeders at the end.
    pub feeders: Vec<FeederFigures>,
    /// How each robot spent the run.
    pub robots: Vec<RobotFigures>,
    /// Entries into the feeder zone per chip robot, measured by rapier.
    pub zone_entries: [u32; 2],
    /// Times a robot entered the zone while the other was inside.
    pub zone_conflicts: u32,
    /// Seconds both chip robots were inside together.
    pub zone_shared_seconds: f64,
    /// Contacts between robots, measured by rapier.
    pub collisions: u32,
    /// The closest two arms came while both were in the feeder zone (rapier), in metres.
    pub closest_in_zone: Option<f32>,
    /// The chip robots' waits for the zone.
    pub waits: [ZoneWaits; 2],
    /// The invariants.
    pub invariants: Vec<Invariant>,
    /// Simulated seconds.
    pub simulated: f64,
    /// Wall seconds.
    pub wall: f64,
    /// Across processes: how many times as fast as the wall clock the cell ran.
    pub processes: Option<f64>,
    /// Across processes: how late each process's timer woke at worst, in wall seconds.
    pub lateness: Vec<(String, f64)>,
    /// Across processes: each line's process that died, and its return.
    pub outages: Vec<Outage>,
    /// Across processes over zenoh: where the lines' hosts were; `None` over iceoryx2.
    pub hosts: Option<String>,
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
            required: true,
        });
        invariants.push(Invariant {
            rule: "no card screwed before it was loaded",
            held: early_screw.is_empty(),
            detail: pallets(early_screw),
            required: true,
        });
        invariants.push(Invariant {
            rule: "no chip inserted before its card was screwed",
            held: early_chip.is_empty(),
            detail: pallets(early_chip),
            required: true,
        });
        // Under every policy; the Appendix's scheme is not expected to keep it (note 6), so
        // a violation there is a finding, not a failure of the run. The coordinator lets both
        // arms into the zone by design, where their trajectories do not meet: what it must
        // keep is the next rule.
        invariants.push(Invariant {
            rule: "no two robots in the feeder zone together (rapier)",
            held: zone_conflicts == 0,
            detail: format!("{zone_conflicts} conflicts, {zone_shared:.1} s shared"),
            required: record.config.feeder == FeederPolicy::Arbiter,
        });
        invariants.push(Invariant {
            rule: "no two arms touching (rapier)",
            held: tally.collisions == 0,
            detail: format!("{} collisions", tally.collisions),
            required: record.config.feeder != FeederPolicy::Appendix,
        });
        invariants.push(Invariant {
            rule: "every chip lies at its work-schedule place on the card (within 1 mm, rapier)",
            held: tally.misplaced == 0,
            detail: format!(
                "{} of {} chips misplaced, worst by {:.1} mm, on {}",
                tally.misplaced,
                tally.chips_checked,
                tally.worst_place * 1000.0,
                pallets(&tally.misplaced_on)
            ),
            required: true,
        });

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
            alarm_kinds: tally
                .alarm_kinds
                .iter()
                .map(|(kind, n)| (kind.map_or("other", AlarmKind::label).to_string(), *n))
                .collect(),
            deadlocks: tally.deadlocks,
            deadlocks_broken,
            deadlock_lost: tally.deadlock_lost,
            stations: tally
                .stations
                .each_ref()
                .map(|line| line.each_ref().map(Cycles::mean_and_worst)),
            cycle_times: record.cycle_times.clone(),
            chip_places: (tally.chips_checked, f64::from(tally.worst_place) * 1000.0),
            feeders: record
                .feeders
                .iter()
                .map(|&(feeder, chip, stock)| FeederFigures {
                    feeder,
                    chip,
                    stock,
                    empties: tally.feeder_empties[usize::from(feeder.0)],
                    refills: tally.feeder_refills[usize::from(feeder.0)],
                })
                .collect(),
            robots: record
                .robot_times
                .iter()
                .map(|(robot, times)| {
                    let waiting = if robot.role == Role::ChipIt {
                        record.waits[robot.line.index()].waited
                    } else {
                        0.0
                    };
                    let (moving, working) =
                        (times.moving.as_secs_f64(), times.working.as_secs_f64());
                    let total = record.simulated.as_secs_f64();
                    RobotFigures {
                        robot: *robot,
                        moving,
                        working,
                        waiting,
                        idle: (total - moving - working - waiting).max(0.0),
                    }
                })
                .collect(),
            zone_entries: tally.zone_entries,
            zone_conflicts,
            zone_shared_seconds: zone_shared,
            collisions: tally.collisions,
            closest_in_zone: record.closest_in_zone,
            waits: record.waits,
            invariants,
            simulated: record.simulated.as_secs_f64(),
            wall: record.wall.as_secs_f64(),
            processes: record.config.processes.then_some(record.config.speed),
            outages: record.outages.clone(),
            hosts: record.hosts.clone(),
            lateness: record
                .lateness
                .iter()
                .map(|(process, late)| (process.clone(), late.as_secs_f64()))
                .collect(),
        }
    }

    /// Cards completed per hour on `line`.
    pub fn cards_per_hour(&self, line: usize) -> f64 {
        f64::from(self.lines[line].completed) / self.hours.max(1e-9)
    }

    /// Whether every required invariant held (findings aside).
    pub fn all_held(&self) -> bool {
        self.invariants
            .iter()
            .all(|invariant| invariant.held || !invariant.required)
    }

    /// The policies side by side, in the order given.
    pub fn side_by_side(reports: &[Report]) -> String {
        let mut out = String::new();
        let row = |out: &mut String, what: &str, cells: Vec<String>| {
            out.push_str(&format!("  {what:<34}"));
            for cell in cells {
                out.push_str(&format!("{cell:>13}"));
            }
            out.push('\n');
        };
        let each = |f: &dyn Fn(&Report) -> String| reports.iter().map(f).collect::<Vec<_>>();
        row(&mut out, "", each(&|r| r.policy.name().to_string()));
        for (line, name) in [(0, "A"), (1, "B")] {
            row(
                &mut out,
                &format!("cards per hour, line {name}"),
                each(&|r| format!("{:.1}", r.cards_per_hour(line))),
            );
        }
        row(
            &mut out,
            "seconds waiting for the zone",
            each(&|r| format!("{:.1}", r.waits[0].waited + r.waits[1].waited)),
        );
        row(
            &mut out,
            "zone requests refused",
            each(&|r| format!("{}", r.waits[0].refused + r.waits[1].refused)),
        );
        row(
            &mut out,
            "cards short",
            each(&|r| format!("{}", r.lines[0].short + r.lines[1].short)),
        );
        row(&mut out, "deadlocks", each(&|r| r.deadlocks.to_string()));
        row(
            &mut out,
            "robot-seconds lost to deadlocks",
            each(&|r| format!("{:.1}", r.deadlock_lost)),
        );
        row(
            &mut out,
            "zone conflicts (rapier)",
            each(&|r| r.zone_conflicts.to_string()),
        );
        row(
            &mut out,
            "seconds both arms in the zone",
            each(&|r| format!("{:.1}", r.zone_shared_seconds)),
        );
        row(
            &mut out,
            "closest arms in zone (rapier, mm)",
            each(&|r| {
                r.closest_in_zone
                    .map_or("-".into(), |m| format!("{:.0}", m * 1000.0))
            }),
        );
        row(
            &mut out,
            "collisions (rapier)",
            each(&|r| r.collisions.to_string()),
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

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "IMRS chip-insertion cell: seed {}, {:.2} h simulated, feeder policy {}",
            self.seed,
            self.hours,
            self.policy.name()
        )?;
        if self.faults.is_empty() {
            writeln!(f, "faults injected: none")?;
        } else {
            writeln!(f, "faults injected: {}", self.faults.join(", "))?;
        }
        if let Some(speed) = self.processes {
            // The feeder zone's keeper, if the policy has one, runs in the world.
            let keeper = match self.policy {
                FeederPolicy::Arbiter => ", FEEDER_MONITOR",
                FeederPolicy::Coordinator => ", FEEDER_COORDINATOR",
                FeederPolicy::Appendix => "",
            };
            let carried = match &self.hosts {
                Some(hosts) => format!("over zenoh, {hosts}"),
                None => "over iceoryx2".into(),
            };
            writeln!(
                f,
                "processes: world (simulation, WORLD{keeper}), line A, line B {carried}, on \
                 the wall clock x {speed}"
            )?;
            if self.outages.is_empty() {
                writeln!(f, "outages: none")?;
            }
            for outage in &self.outages {
                writeln!(f, "outage: {outage}")?;
            }
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
        row(f, "  cards good (every chip)", &|l| {
            self.lines[l].good.to_string()
        })?;
        row(f, "  cards short (a chip missing)", &|l| {
            self.lines[l].short.to_string()
        })?;
        row(f, "pallets in progress", &|l| {
            self.lines[l].in_progress.to_string()
        })?;
        row(f, "pallets scrapped", &|l| {
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
        let station = |l: usize, s: usize, worst: bool| {
            self.stations[l][s].map_or("-".into(), |(mean, most)| {
                format!("{:.1}", if worst { most } else { mean })
            })
        };
        row(f, "load station cycle mean/worst (s)", &|l| {
            format!("{}/{}", station(l, 0, false), station(l, 0, true))
        })?;
        row(f, "chip station cycle mean/worst (s)", &|l| {
            format!("{}/{}", station(l, 1, false), station(l, 1, true))
        })?;
        row(f, "GATE CYCLE_TIME first/now (s)", &|l| {
            let history = &self.cycle_times[l];
            let value = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.1}"));
            format!("{}/{}", value(history.first), value(history.now))
        })?;
        row(f, "GATE CYCLE_TIME min/max (s)", &|l| {
            self.cycle_times[l]
                .range
                .map_or("-".into(), |(low, high)| format!("{low:.1}/{high:.1}"))
        })?;
        row(f, "GATE CYCLE_TIME changes", &|l| {
            self.cycle_times[l].changes.to_string()
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
        for (history, line) in self.cycle_times.iter().zip(["A", "B"]) {
            if history.recent.is_empty() {
                continue;
            }
            let changes: Vec<String> = history
                .recent
                .iter()
                .map(|(at, value)| format!("{value:.1} s at {at:.0} s"))
                .collect();
            writeln!(
                f,
                "  GATE CYCLE_TIME, line {line}, last changes: {}",
                changes.join(", ")
            )?;
        }
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
        let kinds: Vec<String> = self
            .alarm_kinds
            .iter()
            .map(|(kind, n)| format!("{kind} {n}"))
            .collect();
        let kinds = if kinds.is_empty() {
            String::new()
        } else {
            format!(" ({})", kinds.join(", "))
        };
        writeln!(
            f,
            "restarts: {}   alarms: {}{kinds}",
            self.restarts, self.alarms
        )?;
        let broken = if self.deadlocks == 0 {
            String::new()
        } else if self.deadlocks_broken {
            format!(
                " (all broken: both robots went on; {:.1} robot-seconds lost in them)",
                self.deadlock_lost
            )
        } else {
            format!(
                " (NOT broken: a robot stayed stuck; {:.1} robot-seconds lost so far)",
                self.deadlock_lost
            )
        };
        writeln!(f, "deadlocks met: {}{broken}", self.deadlocks)?;
        writeln!(
            f,
            "feeder zone, measured by rapier: {} conflicts ({:.1} s shared), {} collisions",
            self.zone_conflicts, self.zone_shared_seconds, self.collisions
        )?;
        let (checked, worst) = self.chip_places;
        writeln!(
            f,
            "chip places, measured against the pallets in rapier: {checked} chips, worst {worst:.2} mm from the work schedule"
        )?;
        writeln!(f)?;
        writeln!(f, "feeders:")?;
        for feeder in &self.feeders {
            writeln!(
                f,
                "  {} (chip {:>2}): {:>4} left, found empty {}, refilled {}",
                feeder.feeder, feeder.chip, feeder.stock, feeder.empties, feeder.refills
            )?;
        }
        writeln!(f)?;
        writeln!(
            f,
            "robots, share of the run:  {:>8}{:>9}{:>9}{:>8}",
            "moving", "working", "waiting", "idle"
        )?;
        let total = self.simulated.max(1e-9);
        for robot in &self.robots {
            let share = |seconds: f64| format!("{:.1}%", 100.0 * seconds / total);
            writeln!(
                f,
                "  {:<24}{:>8}{:>9}{:>9}{:>8}",
                robot.robot.to_string(),
                share(robot.moving),
                share(robot.working),
                share(robot.waiting),
                share(robot.idle)
            )?;
        }
        writeln!(f)?;
        writeln!(f, "invariants:")?;
        for invariant in &self.invariants {
            let mark = match (invariant.held, invariant.required) {
                (true, _) => "ok",
                (false, true) => "VIOLATED",
                (false, false) => "FINDING",
            };
            write!(f, "  [{mark}] {}", invariant.rule)?;
            if !invariant.held {
                write!(f, ": {}", invariant.detail)?;
                if !invariant.required {
                    write!(f, " (this policy is not expected to keep it)")?;
                }
            }
            writeln!(f)?;
        }
        Ok(())
    }
}

/// How fast one run ran: the last line of a run across processes. (The example's other runs
/// end with every feeder policy's, [`crate::compare::speed_line`].) It differs from run to run.
pub fn speed_line(report: &Report) -> String {
    let ratio = report.simulated / report.wall.max(1e-9);
    format!(
        "simulated {:.0} s in {:.2} s of wall time ({ratio:.0}x real time)",
        report.simulated, report.wall
    )
}
