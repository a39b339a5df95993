//! The table's state: where each arm is going, who holds the tool, and what rapier measured.

use std::collections::BTreeSet;
use std::time::Duration;

use imrs_ports::{Instant, Name};
use nalgebra::Point2;
use rapier3d::prelude::ColliderHandle;

use super::drive::Drive;
use super::physics::TablePhysics;
use super::{ArmSpec, Measured, TableLayout, ZoneUse};
use crate::scara::Scara;

pub(crate) struct TableArmState {
    pub(crate) spec: ArmSpec,
    /// Where the tool rests when it drives no leg.
    tool: Point2<f32>,
    pub(crate) drive: Option<Drive>,
    /// Whether it moved during the last step.
    moved: bool,
    links: [ColliderHandle; 2],
    gripper: ColliderHandle,
}

impl TableArmState {
    pub(crate) fn scara(&self) -> Scara {
        self.spec.arm
    }

    pub(crate) fn tool(&self) -> Point2<f32> {
        self.drive.map_or(self.tool, |drive| drive.tool())
    }

    fn can_move(&self) -> bool {
        self.drive.is_some_and(|drive| drive.can_move())
    }

    /// One step of its controller; whether it moved. A leg driven to its end stays its
    /// leg, at rest, until the next starts: its progress says where it ended.
    fn step(&mut self, dt: f32) -> bool {
        self.drive
            .as_mut()
            .is_some_and(|drive| drive.step(dt, self.spec.speed, self.spec.acceleration))
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
                drive: None,
                moved: false,
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
        self.dirty || self.arms.iter().any(TableArmState::can_move)
    }

    /// Starts arm `arm` on a leg to `to`, from where it stands; refused while it moves.
    pub(crate) fn start_leg(&mut self, arm: usize, to: Point2<f32>) -> Result<(), f32> {
        let state = &mut self.arms[arm];
        if let Some(drive) = state.drive.filter(|drive| !drive.progress().at_rest()) {
            return Err(drive.progress().speed);
        }
        state.tool = state.tool();
        state.drive = Some(Drive::new(state.tool, to));
        self.dirty = true;
        Ok(())
    }

    /// Places arm `arm`'s links and gripper where its drive has them, and the tool with
    /// them if it holds it.
    pub(crate) fn place_arm(&mut self, arm: usize) {
        let state = &self.arms[arm];
        let tool = state.tool();
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

    /// Steps every arm's controller by `elapsed`, places the arms, runs rapier's detection,
    /// and measures: links of two arms touching, the closest they came, and zones in
    /// conflict.
    pub(crate) fn step(&mut self, now: Instant, elapsed: Duration) {
        let dt = elapsed.as_secs_f32();
        for arm in 0..self.arms.len() {
            let moved = self.arms[arm].step(dt);
            self.arms[arm].moved = moved;
            self.place_arm(arm);
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
                // Two that moved in the same step. (One that stops as the other starts is
                // seen moving in different steps: no conflict.)
                ZoneUse::Shared => inside.iter().filter(|arm| arm.moved).count() > 1,
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
