//! Trapezoidal velocity profiles: how long a move takes, and where the tool is meanwhile.

use std::time::Duration;

/// A straight move of `distance`, accelerating at `accel` to at most `speed`, cruising, and
/// braking to a stop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trapezoid {
    distance: f32,
    speed: f32,
    accel: f32,
}

impl Trapezoid {
    /// The profile of a move of `distance` with top `speed` and acceleration `accel`.
    pub fn new(distance: f32, speed: f32, accel: f32) -> Self {
        Self {
            distance: distance.max(0.0),
            speed,
            accel,
        }
    }

    /// The speed actually reached: the top speed, or less on a short (triangular) move.
    fn peak(&self) -> f32 {
        self.speed.min((self.distance * self.accel).sqrt())
    }

    /// How long the move takes.
    pub fn duration(&self) -> Duration {
        if self.distance == 0.0 {
            return Duration::ZERO;
        }
        let peak = self.peak();
        let ramps = peak / self.accel;
        let cruise = (self.distance - peak * ramps) / peak;
        Duration::from_secs_f32(2.0 * ramps + cruise.max(0.0))
    }

    /// The distance covered `elapsed` into the move.
    pub fn covered(&self, elapsed: Duration) -> f32 {
        let total = self.duration().as_secs_f32();
        let t = elapsed.as_secs_f32().min(total);
        if self.distance == 0.0 {
            return 0.0;
        }
        let peak = self.peak();
        let ramp = peak / self.accel;
        let braking_from = total - ramp;
        let covered = if t < ramp {
            0.5 * self.accel * t * t
        } else if t < braking_from {
            0.5 * peak * ramp + peak * (t - ramp)
        } else {
            let left = total - t;
            self.distance - 0.5 * self.accel * left * left
        };
        covered.clamp(0.0, self.distance)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_move_cruises() {
        // 1 m at 1 m/s, 4 m/s²: 0.25 s up, 0.75 s cruising, 0.25 s down.
        let move_ = Trapezoid::new(1.0, 1.0, 4.0);
        assert!((move_.duration().as_secs_f32() - 1.25).abs() < 1e-6);
        assert!((move_.covered(Duration::from_millis(250)) - 0.125).abs() < 1e-6);
        assert!((move_.covered(Duration::from_millis(625)) - 0.5).abs() < 1e-6);
        assert_eq!(move_.covered(Duration::from_secs(5)), 1.0);
    }

    #[test]
    fn a_short_move_never_reaches_top_speed() {
        // 0.04 m at 4 m/s²: peak 0.4 m/s after 0.1 s; 0.2 s in all.
        let move_ = Trapezoid::new(0.04, 1.0, 4.0);
        assert!((move_.duration().as_secs_f32() - 0.2).abs() < 1e-6);
        assert!((move_.covered(Duration::from_millis(100)) - 0.02).abs() < 1e-6);
    }

    #[test]
    fn no_distance_takes_no_time() {
        let move_ = Trapezoid::new(0.0, 1.0, 4.0);
        assert_eq!(move_.duration(), Duration::ZERO);
        assert_eq!(move_.covered(Duration::from_secs(1)), 0.0);
    }
}
