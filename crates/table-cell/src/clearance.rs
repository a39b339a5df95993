//! The arm's look at the others before it moves: its links along the next points of its
//! trajectory, against where the other arms' links are now (as the table senses them), by
//! parry3d distances. A stopped arm in the way is the seed's geometric deadlock.

use imrs_ports::Name;
use imrs_sim::scara::Scara;
use imrs_sim::table::LINK_RADIUS;
use nalgebra::Point2;
use parry3d::math::{Pose, Vector};
use parry3d::query;
use parry3d::shape::Capsule;

use imrs_coord::zones::Obstacle;

fn capsules(joints: &[Point2<f32>; 3]) -> [Capsule; 2] {
    let v = |p: &Point2<f32>| Vector::new(p.x, p.y, 0.0);
    [
        Capsule::new(v(&joints[0]), v(&joints[1]), LINK_RADIUS),
        Capsule::new(v(&joints[1]), v(&joints[2]), LINK_RADIUS),
    ]
}

/// The arms whose links, where they are now, come within `margin` of `arm`'s links with its
/// tool at any of `points`.
pub(crate) fn blockers(
    me: &Name,
    arm: &Scara,
    points: &[Point2<f32>],
    others: &[(Name, [Point2<f32>; 3])],
    margin: f32,
) -> Vec<Name> {
    let mine: Vec<[Capsule; 2]> = points
        .iter()
        .filter_map(|point| arm.joints(point))
        .map(|joints| capsules(&joints))
        .collect();
    others
        .iter()
        .filter(|(name, _)| name != me)
        .filter(|(_, joints)| {
            let theirs = capsules(joints);
            mine.iter().flatten().any(|a| {
                theirs.iter().any(|b| {
                    query::distance(&Pose::IDENTITY, a, &Pose::IDENTITY, b)
                        .is_ok_and(|d| d.distance < margin)
                })
            })
        })
        .map(|(name, _)| name.clone())
        .collect()
}

/// The arms in the way as obstacles for [`imrs_coord::zones::detour`]: their links, a link's
/// radius thick.
pub(crate) fn obstacles(names: &[Name], others: &[(Name, [Point2<f32>; 3])]) -> Vec<Obstacle> {
    others
        .iter()
        .filter(|(name, _)| names.contains(name))
        .map(|(_, j)| {
            let p = |q: &Point2<f32>| [q.x, q.y, 0.0];
            Obstacle::links(&[(p(&j[0]), p(&j[1])), (p(&j[1]), p(&j[2]))], LINK_RADIUS)
        })
        .collect()
}
