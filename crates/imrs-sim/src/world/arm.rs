//! One SCARA arm: where its tool is at any moment, and its links in the rapier world.

use std::time::Duration;

use imrs_ports::Instant;
use rapier3d::prelude::ColliderHandle;

use super::physics::Physics;
use crate::ids::RobotId;
use crate::layout::{LINK_1, LINK_2, TOOL_ACCEL, TOOL_SPEED};
use crate::profile::Trapezoid;
use crate::scara::{Elbow, elbow};

/// What a tool holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Held {
    /// A chip of this number.
    Chip(u32),
    /// A blank card.
    Card,
}

/// A straight move of the tool under a trapezoidal profile.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Motion {
    from: [f32; 2],
    to: [f32; 2],
    start: Instant,
    profile: Trapezoid,
}

impl Motion {
    pub(crate) fn end(&self) -> Instant {
        self.start + self.profile.duration()
    }

    fn at(&self, now: Instant) -> [f32; 2] {
        let length = distance(self.from, self.to);
        if length == 0.0 {
            return self.to;
        }
        let share = self
            .profile
            .covered(now.saturating_duration_since(self.start))
            / length;
        [
            self.from[0] + (self.to[0] - self.from[0]) * share,
            self.from[1] + (self.to[1] - self.from[1]) * share,
        ]
    }
}

pub(crate) struct Arm {
    pub(crate) id: RobotId,
    pub(crate) base: [f32; 2],
    pub(crate) home: [f32; 2],
    side: Elbow,
    tool: [f32; 2],
    motion: Option<Motion>,
    pub(crate) holding: Option<Held>,
    pub(crate) colliders: [ColliderHandle; 2],
    /// Whether the links were placed since the world last measured them: an arm that has not
    /// moved cannot have entered the zone or touched another unmoved arm.
    pub(crate) moved: bool,
}

impl Arm {
    pub(crate) fn new(
        id: RobotId,
        base: [f32; 2],
        home: [f32; 2],
        side: Elbow,
        physics: &mut Physics,
    ) -> Self {
        let (collider1, collider2) = (physics.add_link(LINK_1), physics.add_link(LINK_2));
        let mut arm = Self {
            id,
            base,
            home,
            side,
            tool: home,
            motion: None,
            holding: None,
            colliders: [collider1, collider2],
            moved: true,
        };
        arm.place(physics, home);
        arm
    }

    /// The arm's links with its tool at `tool`: base, elbow, tool; `None` out of reach.
    pub(crate) fn links_at(&self, tool: [f32; 2]) -> Option<[[f32; 2]; 3]> {
        elbow(self.base, tool, LINK_1, LINK_2, self.side).map(|elbow| [self.base, elbow, tool])
    }

    pub(crate) fn reaches(&self, target: [f32; 2]) -> bool {
        elbow(self.base, target, LINK_1, LINK_2, self.side).is_some()
    }

    /// Where the tool is at `now`.
    pub(crate) fn tool_at(&self, now: Instant) -> [f32; 2] {
        self.motion.map_or(self.tool, |motion| motion.at(now))
    }

    pub(crate) fn is_moving(&self) -> bool {
        self.motion.is_some()
    }

    /// Ends a move whose time is up (also one whose operation was abandoned).
    pub(crate) fn settle(&mut self, now: Instant, physics: &mut Physics) {
        if self.motion.is_some_and(|motion| motion.end() <= now) {
            self.stop(now, physics);
        }
    }

    /// Starts a move to `to` at `now`; returns how long it takes.
    pub(crate) fn start_move(&mut self, now: Instant, to: [f32; 2]) -> Duration {
        let from = self.tool_at(now);
        let profile = Trapezoid::new(distance(from, to), TOOL_SPEED, TOOL_ACCEL);
        self.motion = Some(Motion {
            from,
            to,
            start: now,
            profile,
        });
        profile.duration()
    }

    /// Ends the move at `now`: where it got to (the target, unless it was cut short).
    pub(crate) fn stop(&mut self, now: Instant, physics: &mut Physics) {
        self.tool = self.tool_at(now);
        self.motion = None;
        self.place(physics, self.tool);
    }

    /// Places the links for the tool where it is at `now`.
    pub(crate) fn update(&mut self, now: Instant, physics: &mut Physics) {
        if let Some(motion) = self.motion {
            let tool = motion.at(now);
            self.place(physics, tool);
        }
        self.settle(now, physics);
    }

    fn place(&mut self, physics: &mut Physics, tool: [f32; 2]) {
        self.moved = true;
        // Both ends of a move are within reach; a straight path between them that grazes
        // the dead zone around the base keeps the last placement for that step.
        if let Some(elbow) = elbow(self.base, tool, LINK_1, LINK_2, self.side) {
            physics.place_link(self.colliders[0], self.base, elbow);
            physics.place_link(self.colliders[1], elbow, tool);
        }
    }
}

pub(crate) fn distance(a: [f32; 2], b: [f32; 2]) -> f32 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
}
