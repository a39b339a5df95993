//! The two-link geometry of a SCARA arm: where its elbow is for a tool position.

/// Which way the elbow bends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Elbow {
    /// Bent counter-clockwise of the line from base to tool.
    Left,
    /// Bent clockwise.
    Right,
}

/// The elbow position for the tool at `tool`, with the base at `base` and links `l1`, `l2`;
/// `None` if the tool is out of reach.
pub fn elbow(base: [f32; 2], tool: [f32; 2], l1: f32, l2: f32, side: Elbow) -> Option<[f32; 2]> {
    let (dx, dy) = (tool[0] - base[0], tool[1] - base[1]);
    let d2 = dx * dx + dy * dy;
    let d = d2.sqrt();
    if d > l1 + l2 || d < (l1 - l2).abs() {
        return None;
    }
    let cos_q2 = ((d2 - l1 * l1 - l2 * l2) / (2.0 * l1 * l2)).clamp(-1.0, 1.0);
    let q2 = match side {
        Elbow::Left => -cos_q2.acos(),
        Elbow::Right => cos_q2.acos(),
    };
    let q1 = dy.atan2(dx) - (l2 * q2.sin()).atan2(l1 + l2 * q2.cos());
    Some([base[0] + l1 * q1.cos(), base[1] + l1 * q1.sin()])
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
}
