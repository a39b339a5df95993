//! An arm's dynamic controller on one straight leg: it speeds up and brakes at the arm's
//! limit, stops at the leg's end as planned, and goes towards the points it is allowed
//! without knowing what lies beyond them.
//!
//! The controller is told the leg (the trajectory) when it starts, but may go only as far as
//! the last point allowed (the seed's TRAJECTORY_POINT). It does not plan to stop there:
//! from the step in which it reaches that point with no other allowed, or is halted
//! (STOP_C), it brakes, and goes on along the leg by its stopping distance, `v² / 2a`, and
//! by up to a step's travel more, since it looks at the start of each step. That is why an arm
//! is allowed points only `offset` ahead of a point checked: the offset covers what it needs
//! to stop.

use nalgebra::{Point2, Vector2};

/// Where a leg ends, to within this: a controller at rest this close has arrived.
const ARRIVED: f32 = 1e-5;

/// An arm's progress along its leg.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// How far along the leg the tool is, in metres.
    pub along: f32,
    /// The leg's length, in metres.
    pub length: f32,
    /// The tool's speed, in m/s.
    pub speed: f32,
    /// How far it is allowed to go, in metres along the leg.
    pub allowed: f32,
    /// Whether it was halted, and not allowed further since.
    pub halted: bool,
}

impl Progress {
    /// Whether the tool stands still.
    pub fn at_rest(&self) -> bool {
        self.speed == 0.0
    }

    /// Whether it is at the leg's end, at rest.
    pub fn arrived(&self) -> bool {
        self.at_rest() && self.along >= self.length - ARRIVED
    }

    /// The distance it needs to stop from its speed, braking at `deceleration`.
    pub fn stopping(&self, deceleration: f32) -> f32 {
        self.speed * self.speed / (2.0 * deceleration)
    }
}

/// A leg being driven.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Drive {
    from: Point2<f32>,
    direction: Vector2<f32>,
    length: f32,
    along: f32,
    speed: f32,
    allowed: f32,
    halted: bool,
}

impl Drive {
    /// A leg from `from` to `to`, at rest, allowed nowhere yet.
    pub(crate) fn new(from: Point2<f32>, to: Point2<f32>) -> Self {
        let length = (to - from).norm();
        let direction = if length > 0.0 {
            (to - from) / length
        } else {
            Vector2::zeros()
        };
        Self {
            from,
            direction,
            length,
            along: 0.0,
            speed: 0.0,
            allowed: 0.0,
            halted: false,
        }
    }

    pub(crate) fn tool(&self) -> Point2<f32> {
        self.from + self.direction * self.along
    }

    pub(crate) fn progress(&self) -> Progress {
        Progress {
            along: self.along,
            length: self.length,
            speed: self.speed,
            allowed: self.allowed,
            halted: self.halted,
        }
    }

    /// Allows it as far as `point`, taken where it lies along the leg; a point behind one
    /// allowed before allows nothing new. Lifts a halt (CONTINUE).
    pub(crate) fn allow(&mut self, point: Point2<f32>) {
        let along = (point - self.from)
            .dot(&self.direction)
            .clamp(0.0, self.length);
        self.allowed = self.allowed.max(along);
        self.halted = false;
    }

    /// STOP_C: brake now, whatever is allowed.
    pub(crate) fn halt(&mut self) {
        self.halted = true;
    }

    /// Whether a step could move it: it moves, or may.
    pub(crate) fn can_move(&self) -> bool {
        self.speed > 0.0 || (!self.halted && self.along < self.allowed.min(self.length) - ARRIVED)
    }

    /// One step of `dt` seconds at `top` speed and `acceleration` (both ways); whether it
    /// moved.
    pub(crate) fn step(&mut self, dt: f32, top: f32, acceleration: f32) -> bool {
        let before = self.along;
        // Halted, or at the last point allowed: brake, and go on by what stopping takes.
        let brake = self.halted || self.along >= self.allowed - ARRIVED;
        let speed = if brake {
            (self.speed - acceleration * dt).max(0.0)
        } else {
            // The leg's end is planned: never faster than it can stop there.
            let to_end = (self.length - self.along).max(0.0);
            (self.speed + acceleration * dt)
                .min(top)
                .min((2.0 * acceleration * to_end).sqrt())
        };
        self.along = (self.along + (self.speed + speed) / 2.0 * dt).min(self.length);
        self.speed = speed;
        if self.along >= self.length - ARRIVED {
            self.along = self.length;
            self.speed = 0.0;
        }
        self.along > before
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DT: f32 = 0.02;

    fn run(drive: &mut Drive, steps: usize) {
        for _ in 0..steps {
            drive.step(DT, 0.5, 2.5);
        }
    }

    #[test]
    fn a_leg_allowed_to_its_end_stops_there() {
        let mut drive = Drive::new(Point2::new(0.0, 0.0), Point2::new(0.3, 0.0));
        drive.allow(Point2::new(0.3, 0.0));
        run(&mut drive, 200);
        assert!(drive.progress().arrived(), "{:?}", drive.progress());
        assert_eq!(drive.tool(), Point2::new(0.3, 0.0));
    }

    #[test]
    fn at_the_last_point_allowed_it_brakes_and_goes_on_by_its_stopping_distance() {
        let mut drive = Drive::new(Point2::new(0.0, 0.0), Point2::new(1.0, 0.0));
        drive.allow(Point2::new(0.4, 0.0));
        // Up to speed, then to the point allowed.
        while drive.progress().along < 0.4 - ARRIVED {
            drive.step(DT, 0.5, 2.5);
        }
        let at = drive.progress();
        run(&mut drive, 100);
        let overshoot = drive.progress().along - at.along;
        // v² / 2a = 5 cm, within a step's travel.
        assert!(drive.progress().at_rest());
        assert!(
            (overshoot - at.stopping(2.5)).abs() < 0.5 * DT,
            "{overshoot}"
        );
        assert!(overshoot > 0.04, "{overshoot}");
    }

    #[test]
    fn halted_it_brakes_and_allowed_again_it_goes_on() {
        let mut drive = Drive::new(Point2::new(0.0, 0.0), Point2::new(1.0, 0.0));
        drive.allow(Point2::new(1.0, 0.0));
        run(&mut drive, 30);
        drive.halt();
        run(&mut drive, 20);
        assert!(drive.progress().at_rest() && !drive.can_move());
        drive.allow(Point2::new(1.0, 0.0));
        assert!(drive.can_move());
        run(&mut drive, 200);
        assert!(drive.progress().arrived());
    }
}
