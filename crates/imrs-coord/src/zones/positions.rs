//! Where the robots are, as far as the coordinator was told: the seed's position
//! information, each robot's links where it last said they were. The coordinator checks a
//! robot's way ahead against them, and computes the alternative trajectory round the robots
//! in the way (the seed's geometric deadlock) from what it was told, never from where the
//! robots really are.

use std::collections::BTreeMap;

use imrs_ports::Name;

use super::detour::{Obstacle, detour};
use super::space::Space;
use super::sweep::{Sweep, space};
use super::table::ZoneError;

/// How much nearer than they are a way may take two robots already within the margin, down
/// to half the margin: a way along the other keeps its distance only to within a
/// millimetre.
pub const PARTING: f32 = 0.001;

/// An arm's pose in the working plane: its base, elbow and tool.
pub type Pose = [[f32; 2]; 3];

/// The robots' positions as they told them, and the checks made against them.
#[derive(Debug, Clone)]
pub struct Positions {
    radius: f32,
    margin: f32,
    robots: Vec<Name>,
    told: BTreeMap<Name, Space>,
    /// The poses as told, for alternatives: a robot in the way is an obstacle there.
    poses: BTreeMap<Name, Pose>,
}

impl Positions {
    /// Positions of `robots`, whose links are `radius` thick and kept `margin` apart.
    pub fn new<R: Into<Name>>(
        robots: impl IntoIterator<Item = R>,
        radius: f32,
        margin: f32,
    ) -> Self {
        Self {
            radius,
            margin,
            robots: robots.into_iter().map(Into::into).collect(),
            told: BTreeMap::new(),
            poses: BTreeMap::new(),
        }
    }

    fn known(&self, robot: &str) -> Result<(), ZoneError> {
        if self.robots.iter().any(|known| *known == robot) {
            Ok(())
        } else {
            Err(ZoneError::UnknownRobot(robot.into()))
        }
    }

    /// `robot` says where its links are now. A pose that is no place (not finite) is
    /// refused, and the last one told is kept.
    pub fn tell(&mut self, robot: &str, pose: Pose) -> Result<(), ZoneError> {
        self.known(robot)?;
        if pose.iter().flatten().any(|c| !c.is_finite()) {
            return Err(ZoneError::NoPlace(robot.into()));
        }
        self.told.insert(robot.into(), space(&[pose], self.radius));
        self.poses.insert(robot.into(), pose);
        Ok(())
    }

    /// Where `robot` last said it was, if it said.
    pub fn told(&self, robot: &str) -> Option<Pose> {
        self.poses.get(&Name::from(robot)).copied()
    }

    /// The other robots whose links, where they last said they were, come within the margin
    /// of `robot`'s links at any pose of `sweep`: none when its way is clear. Of two robots
    /// already nearer than the margin where they said they were, the way is blocked if it
    /// comes nearer than they are (less [`PARTING`], down to half the margin; below that,
    /// at all), so that they can part.
    pub fn blockers(&self, robot: &str, sweep: &Sweep) -> Result<Vec<Name>, ZoneError> {
        self.known(robot)?;
        if sweep.iter().flatten().flatten().any(|c| !c.is_finite()) {
            return Err(ZoneError::NoPlace(robot.into()));
        }
        let mine = space(sweep, self.radius);
        let here = self.told.get(&Name::from(robot));
        Ok(self
            .told
            .iter()
            .filter(|(other, _)| **other != robot)
            .filter(|(_, theirs)| {
                // Two robots already nearer than the margin may still part: the way is
                // blocked if it comes nearer than they are now (less a tolerance for a way
                // along the other, never down to touching).
                let margin = here.map_or(self.margin, |here| {
                    // Clear of each other by the margin (most robots, most of the time): no
                    // distance to measure.
                    if here.clear_of(theirs, self.margin) {
                        return self.margin;
                    }
                    let now = here.distance(theirs);
                    if now >= self.margin {
                        self.margin
                    } else if now >= self.margin / 2.0 {
                        // A way along the other may come a little nearer, but never below
                        // half the margin: step after step, the tolerance cannot ratchet.
                        (now - PARTING).max(self.margin / 2.0)
                    } else {
                        // Nearer than that, only a way that comes no nearer at all.
                        now
                    }
                });
                !mine.clear_of(theirs, margin)
            })
            .map(|(other, _)| other.clone())
            .collect())
    }

    /// An alternative for `robot`'s straight way from `from` to `to`, round the links of the
    /// robots `around` where they last said they were: the whole way, `from` first, or
    /// `None` if no side-step within `reach` keeps the margin (see [`detour`]), or if a
    /// robot in the way never said where it is. A point that is no place, or a robot the
    /// coordinator does not know, is refused by name.
    pub fn alternative(
        &self,
        robot: &str,
        from: [f32; 2],
        to: [f32; 2],
        around: &[Name],
        reach: f32,
    ) -> Result<Option<Vec<[f32; 2]>>, ZoneError> {
        self.known(robot)?;
        if from.iter().chain(&to).any(|c| !c.is_finite()) {
            return Err(ZoneError::NoPlace(robot.into()));
        }
        for other in around {
            self.known(other.as_str())?;
        }
        if around.iter().any(|other| !self.poses.contains_key(other)) {
            return Ok(None);
        }
        let obstacles: Vec<Obstacle> = around
            .iter()
            .filter_map(|other| self.poses.get(other))
            .map(|[base, elbow, tool]| {
                let p = |q: &[f32; 2]| [q[0], q[1], 0.0];
                Obstacle::links(&[(p(base), p(elbow)), (p(elbow), p(tool))], self.radius)
            })
            .collect();
        let path = [[from[0], from[1], 0.0], [to[0], to[1], 0.0]];
        Ok(detour(&path, self.radius, &obstacles, self.margin, reach)
            .map(|way| way.iter().map(|p| [p[0], p[1]]).collect()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An arm along the x axis at height `y`, 50 cm long.
    fn arm(y: f32) -> Pose {
        [[0.0, y], [0.25, y], [0.5, y]]
    }

    #[test]
    fn a_way_is_blocked_only_by_where_the_others_said_they_are() {
        let mut positions = Positions::new(["A", "B"], 0.035, 0.03);
        positions.tell("A", arm(0.0)).unwrap();
        // B's way crosses where A said it is.
        assert_eq!(positions.blockers("B", &vec![arm(0.05)]).unwrap(), ["A"]);
        // A says it moved away: the same way is clear.
        positions.tell("A", arm(0.5)).unwrap();
        assert!(
            positions
                .blockers("B", &vec![arm(0.05)])
                .unwrap()
                .is_empty()
        );
        // A robot is never in its own way.
        assert!(positions.blockers("A", &vec![arm(0.5)]).unwrap().is_empty());
    }

    #[test]
    fn unknown_robots_and_poses_that_are_no_place_are_refused_by_name() {
        let mut positions = Positions::new(["A"], 0.035, 0.03);
        assert_eq!(
            positions.tell("Z", arm(0.0)),
            Err(ZoneError::UnknownRobot("Z".into()))
        );
        positions.tell("A", arm(0.0)).unwrap();
        assert_eq!(
            positions.tell("A", [[f32::NAN, 0.0], [0.0, 0.0], [0.0, 0.0]]),
            Err(ZoneError::NoPlace("A".into()))
        );
        // The pose told before is kept.
        assert_eq!(positions.told("A"), Some(arm(0.0)));
    }

    #[test]
    fn an_alternative_round_a_robot_that_never_told_or_to_no_place_is_refused() {
        let positions = Positions::new(["A", "B"], 0.035, 0.03);
        // B never said where it is: no way round it is offered.
        assert_eq!(
            positions.alternative("A", [0.0, 0.0], [1.0, 0.0], &["B".into()], 0.5),
            Ok(None)
        );
        assert_eq!(
            positions.alternative("A", [f32::NAN, 0.0], [1.0, 0.0], &[], 0.5),
            Err(ZoneError::NoPlace("A".into()))
        );
        assert_eq!(
            positions.alternative("A", [0.0, 0.0], [1.0, 0.0], &["Z".into()], 0.5),
            Err(ZoneError::UnknownRobot("Z".into()))
        );
    }

    #[test]
    fn the_alternative_goes_round_the_robots_in_the_way() {
        let mut positions = Positions::new(["A", "B"], 0.035, 0.03);
        // A stands across B's straight way, its tool at (0.5, 0).
        positions
            .tell("A", [[0.5, -0.6], [0.5, -0.3], [0.5, 0.0]])
            .unwrap();
        let way = positions
            .alternative("B", [0.0, 0.05], [1.0, 0.05], &["A".into()], 0.5)
            .unwrap()
            .expect("a way round A");
        assert_eq!(way.first(), Some(&[0.0, 0.05]));
        assert_eq!(way.last(), Some(&[1.0, 0.05]));
        assert!(way.len() > 2, "the straight way is blocked: {way:?}");
    }
}
