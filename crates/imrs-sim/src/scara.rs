//! The kinematics of a two-link SCARA arm, on nalgebra: where its elbow is for a tool
//! position, its links as poses in space, and whether a point is within reach.

use nalgebra::{Isometry3, Point2, Point3, Translation3, UnitQuaternion, Vector3};

/// Which way the elbow bends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Elbow {
    /// Bent counter-clockwise of the line from base to tool.
    Left,
    /// Bent clockwise.
    Right,
}

/// A SCARA arm: its base in the working plane, its two links, and its elbow's side.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scara {
    /// The base (the shoulder's axis), in the working plane.
    pub base: Point2<f32>,
    /// The upper arm's length, shoulder to elbow.
    pub upper: f32,
    /// The forearm's length, elbow to tool.
    pub fore: f32,
    /// Which way the elbow bends.
    pub side: Elbow,
}

impl Scara {
    /// The elbow for the tool at `tool`; `None` out of reach (too far, or too near the
    /// base).
    pub fn elbow(&self, tool: &Point2<f32>) -> Option<Point2<f32>> {
        let (l1, l2) = (self.upper, self.fore);
        let to_tool = tool - self.base;
        let d2 = to_tool.norm_squared();
        let d = d2.sqrt();
        if d > l1 + l2 || d < (l1 - l2).abs() {
            return None;
        }
        let cos_q2 = ((d2 - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)).clamp(-1.0, 1.0);
        let q2 = match self.side {
            Elbow::Left => -cos_q2.acos(),
            Elbow::Right => cos_q2.acos(),
        };
        let q1 = to_tool.y.atan2(to_tool.x) - (l2 * q2.sin()).atan2(l1 + l2 * q2.cos());
        Some(self.base + l1 * nalgebra::Vector2::new(q1.cos(), q1.sin()))
    }

    /// The arm's joints with the tool at `tool`: base, elbow, tool; `None` out of reach.
    pub fn joints(&self, tool: &Point2<f32>) -> Option<[Point2<f32>; 3]> {
        self.elbow(tool).map(|elbow| [self.base, elbow, *tool])
    }

    /// Whether the tool can be at `tool`.
    pub fn reaches(&self, tool: &Point2<f32>) -> bool {
        self.elbow(tool).is_some()
    }
}

/// The pose of a link running from `from` to `to` in the working plane at height `z`: its
/// centre, its x axis along the link.
pub fn link_pose(from: &Point2<f32>, to: &Point2<f32>, z: f32) -> Isometry3<f32> {
    let middle = nalgebra::center(from, to);
    let along = to - from;
    Isometry3::from_parts(
        Translation3::from(Point3::new(middle.x, middle.y, z).coords),
        UnitQuaternion::from_axis_angle(&Vector3::z_axis(), along.y.atan2(along.x)),
    )
}

/// The elbow position for the tool at `tool`, with the base at `base` and links `l1`, `l2`;
/// `None` if the tool is out of reach. [`Scara::elbow`] on plain arrays.
pub fn elbow(base: [f32; 2], tool: [f32; 2], l1: f32, l2: f32, side: Elbow) -> Option<[f32; 2]> {
    let arm = Scara {
        base: base.into(),
        upper: l1,
        fore: l2,
        side,
    };
    arm.elbow(&tool.into()).map(|elbow| [elbow.x, elbow.y])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn distance(a: [f32; 2], b: [f32; 2]) -> f32 {
        ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)).sqrt()
    }

    #[test]
    fn the_elbow_is_one_link_from_the_base_and_the_other_from_the_tool() {
        for side in [Elbow::Left, Elbow::Right] {
            let (base, tool) = ([0.0, 0.0], [0.5, 0.3]);
            let elbow = elbow(base, tool, 0.4, 0.35, side).unwrap();
            assert!((distance(base, elbow) - 0.4).abs() < 1e-5);
            assert!((distance(elbow, tool) - 0.35).abs() < 1e-5);
        }
    }

    #[test]
    fn the_two_elbows_lie_on_either_side() {
        let left = elbow([0.0, 0.0], [0.6, 0.0], 0.4, 0.35, Elbow::Left).unwrap();
        let right = elbow([0.0, 0.0], [0.6, 0.0], 0.4, 0.35, Elbow::Right).unwrap();
        assert!(left[1] > 0.0 && right[1] < 0.0, "{left:?} {right:?}");
    }

    #[test]
    fn out_of_reach_is_none() {
        assert_eq!(elbow([0.0, 0.0], [0.8, 0.0], 0.4, 0.35, Elbow::Left), None);
        assert_eq!(elbow([0.0, 0.0], [0.01, 0.0], 0.4, 0.35, Elbow::Left), None);
    }

    #[test]
    fn a_link_pose_puts_its_x_axis_from_one_joint_to_the_other() {
        let (from, to) = (Point2::new(0.1, 0.2), Point2::new(0.4, 0.6));
        let pose = link_pose(&from, &to, 0.3);
        let end = pose * Point3::new(0.25, 0.0, 0.0);
        assert!((end - Point3::new(0.4, 0.6, 0.3)).norm() < 1e-5, "{end}");
        let start = pose * Point3::new(-0.25, 0.0, 0.0);
        assert!(
            (start - Point3::new(0.1, 0.2, 0.3)).norm() < 1e-5,
            "{start}"
        );
    }
}
