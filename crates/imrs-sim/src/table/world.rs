//! The table's state: where each arm is going, who holds the tool, and what rapier measured.

use std::collections::BTreeSet;
use std::time::Duration;

use imrs_ports::{Instant, Name};
use nalgebra::Point2;
use rapier3d::prelude::ColliderHandle;

use super::physics::TablePhysics;
use super::{ArmSpec, Measured, TableLayout, ZoneUse};
use crate::scara::Scara;

/// A straight move of the tool at the arm's speed.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Motion {
    from: Point2<f32>,
    to: Point2<f32>,
    start: Instant,
    end: Instant,
}

impl Motion {
    fn at(&self, now: Instant) -> Point2<f32> {
        let total = self.end.saturating_duration_since(self.start).as_secs_f32();
        if total <= 0.0 {
            return self.to;
        }
        let share = (now.saturating_duration_since(self.start).as_secs_f32() / total).min(1.0);
        self.from + (self.to - self.from) * share
    }
}

pub(crate) struct TableArmState {
    pub(crate) spec: ArmSpec,
    tool: Point2<f32>,
    motion: Option<Motion>,
    /// Its moves that ended since the last step: (start, end).
    ended: Vec<(Instant, Instant)>,
    /// When it moved during the last step: its moves, cut to the step.
    moving: Vec<(Instant, Instant)>,
    links: [ColliderHandle; 2],
    gripper: ColliderHandle,
}

impl TableArmState {
    pub(crate) fn scara(&self) -> Scara {
        self.spec.arm
    }

    pub(crate) fn tool_at(&self, now: Instant) -> Point2<f32> {
        self.motion.map_or(self.tool, |motion| motion.at(now))
    }
}

struct Zone {
    name: Name,
    usage: ZoneUse,
    sensor: ColliderHandle,
    /// Whether it is in conflict at the last step (an episode is counted once).
    in_conflict: bool,
}

pub(crate) struct TableWorld {
    physics: TablePhysics,
    pub(crate) arms: Vec<TableArmState>,
    zones: Vec<Zone>,
    tool: ColliderHandle,
    /// The arm holding the tool.
    pub(crate) holder: Option<usize>,
    touching: BTreeSet<(usize, usize)>,
    pub(crate) measured: Measured,
    /// Whether something changed since the last step: a move started or ended.
    dirty: bool,
}

impl TableWorld {
    pub(crate) fn new(layout: &TableLayout) -> Self {
        let mut physics = TablePhysics::new();
        let arms = layout
            .arms
            .iter()
            .map(|spec| TableArmState {
                spec: spec.clone(),
                tool: spec.home,
                motion: None,
                ended: Vec::new(),
                moving: Vec::new(),
                links: [
                    physics.add_link(spec.arm.upper),
                    physics.add_link(spec.arm.fore),
                ],
                gripper: physics.add_gripper(),
            })
            .collect();
        let zones = layout
            .zones
            .iter()
            .map(|zone| Zone {
                name: zone.name.clone(),
                usage: zone.usage,
                sensor: physics.add_zone(zone.centre, zone.half),
                in_conflict: false,
            })
            .collect();
        let tool = physics.add_tool(layout.tool);
        let mut world = Self {
            physics,
            arms,
            zones,
            tool,
            holder: None,
            touching: BTreeSet::new(),
            measured: Measured::default(),
            dirty: true,
        };
        world.measured.zone_time = layout
            .zones
            .iter()
            .map(|zone| (zone.name.clone(), Duration::ZERO))
            .collect();
        world
    }

    pub(crate) fn is_active(&self) -> bool {
        self.dirty || self.arms.iter().any(|arm| arm.motion.is_some())
    }

    pub(crate) fn start_move(&mut self, arm: usize, to: Point2<f32>, now: Instant) -> Instant {
        let state = &mut self.arms[arm];
        let from = state.tool_at(now);
        let seconds = (to - from).norm() / state.spec.speed;
        let end = now + Duration::from_secs_f32(seconds);
        state.motion = Some(Motion {
            from,
            to,
            start: now,
            end,
        });
        self.dirty = true;
        end
    }

    /// Ends arm `arm`'s move if its time is up.
    pub(crate) fn settle(&mut self, arm: usize, now: Instant) {
        let state = &mut self.arms[arm];
        if let Some(motion) = state.motion.filter(|motion| motion.end <= now) {
            state.tool = motion.to;
            state.motion = None;
            state.ended.push((motion.start, motion.end));
            self.dirty = true;
        }
    }

    /// Places arm `arm`'s links and gripper as they are at `now`, and the tool with them if
    /// it holds it.
    pub(crate) fn place_arm(&mut self, arm: usize, now: Instant) {
        let state = &self.arms[arm];
        let tool = state.tool_at(now);
        // A straight path that grazes the dead zone round the base keeps the last
        // placement for that step; both its ends are within reach.
        if let Some([base, elbow, tool]) = state.spec.arm.joints(&tool) {
            self.physics.place_link(state.links[0], &base, &elbow);
            self.physics.place_link(state.links[1], &elbow, &tool);
            self.physics.place_ball(state.gripper, &tool);
        }
        if self.holder == Some(arm) {
            self.physics.place_ball(self.tool, &tool);
        }
    }

    /// Where the tool lies, as rapier has it.
    pub(crate) fn tool_position(&self) -> Point2<f32> {
        self.physics.position(self.tool)
    }

    /// How far arm `arm`'s gripper is from the tool, by parry3d.
    pub(crate) fn gripper_to_tool(&self, arm: usize) -> f32 {
        self.physics.distance(self.arms[arm].gripper, self.tool)
    }

    /// Places every arm as it is at `now`, runs rapier's detection, and measures: links of
    /// two arms touching, the closest they came, and zones in conflict.
    pub(crate) fn step(&mut self, now: Instant, elapsed: Duration) {
        for arm in 0..self.arms.len() {
            self.settle(arm, now);
        }
        let since = Instant::from_start(now.since_start().saturating_sub(elapsed));
        for arm in 0..self.arms.len() {
            self.place_arm(arm, now);
            let state = &mut self.arms[arm];
            let current = state.motion.map(|motion| (motion.start, now));
            state.moving = state
                .ended
                .drain(..)
                .chain(current)
                .map(|(start, end)| (start.max(since), end.min(now)))
                .filter(|(start, end)| start < end)
                .collect();
        }
        self.physics.detect();
        self.measured.steps += 1;
        self.measure_links(now);
        self.measure_zones(now, elapsed);
        self.dirty = false;
    }

    fn measure_links(&mut self, now: Instant) {
        for a in 0..self.arms.len() {
            for b in a + 1..self.arms.len() {
                let pairs = self.arms[a]
                    .links
                    .iter()
                    .flat_map(|&la| self.arms[b].links.iter().map(move |&lb| (la, lb)));
                let mut touching = false;
                let mut closest = f32::INFINITY;
                for (la, lb) in pairs {
                    touching |= self.physics.touching(la, lb);
                    closest = closest.min(self.physics.distance(la, lb));
                }
                self.measured.closest =
                    Some(self.measured.closest.map_or(closest, |c| c.min(closest)));
                if touching && self.touching.insert((a, b)) {
                    let names = (
                        self.arms[a].spec.name.clone(),
                        self.arms[b].spec.name.clone(),
                    );
                    self.measured.collisions.push((names.0, names.1, now));
                } else if !touching {
                    self.touching.remove(&(a, b));
                }
            }
        }
    }

    fn measure_zones(&mut self, now: Instant, elapsed: Duration) {
        for (index, zone) in self.zones.iter_mut().enumerate() {
            let inside: Vec<&TableArmState> = self
                .arms
                .iter()
                .filter(|arm| self.physics.inside(zone.sensor, arm.gripper))
                .collect();
            if !inside.is_empty() {
                self.measured.zone_time[index].1 += elapsed;
            }
            let conflict = match zone.usage {
                ZoneUse::Exclusive => inside.len() > 1,
                // Two moving at the same time: their moves in the step overlap. (One that
                // stops as the other starts, within a step, is not a conflict.)
                ZoneUse::Shared => inside.iter().enumerate().any(|(i, a)| {
                    inside[i + 1..]
                        .iter()
                        .any(|b| overlap(&a.moving, &b.moving))
                }),
            };
            if conflict && !zone.in_conflict {
                self.measured.zone_conflicts.push((
                    zone.name.clone(),
                    now,
                    inside.iter().map(|a| a.spec.name.clone()).collect(),
                ));
            }
            zone.in_conflict = conflict;
        }
    }
}

/// Whether two sets of intervals overlap for a positive time.
fn overlap(a: &[(Instant, Instant)], b: &[(Instant, Instant)]) -> bool {
    a.iter()
        .any(|&(s1, e1)| b.iter().any(|&(s2, e2)| s1.max(s2) < e1.min(e2)))
}
