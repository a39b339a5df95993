//! Geometric deadlock: a robot with permission to move cannot take its trajectory because a
//! stopped robot is in the way. The coordinator checks the trajectory against the stopped
//! robots' links with parry3d and, where it is blocked, computes an alternative that goes
//! round them ("continue with alternative trajectory").

use parry3d::math::{Pose, Vector};
use parry3d::query;
use parry3d::shape::Capsule;

/// A stopped robot, as the space its links take: one capsule per link.
#[derive(Debug, Clone)]
pub struct Obstacle {
    links: Vec<Capsule>,
}

fn v(p: [f32; 3]) -> Vector {
    Vector::new(p[0], p[1], p[2])
}

impl Obstacle {
    /// A robot whose links run between these points, each `radius` thick.
    pub fn links(links: &[([f32; 3], [f32; 3])], radius: f32) -> Self {
        Self {
            links: links
                .iter()
                .map(|&(a, b)| Capsule::new(v(a), v(b), radius))
                .collect(),
        }
    }

    /// How far the tool, a ball of `radius` swept from `a` to `b`, passes from this robot
    /// (0 when it touches).
    pub fn distance(&self, a: [f32; 3], b: [f32; 3], radius: f32) -> f32 {
        let swept = Capsule::new(v(a), v(b), radius);
        self.links
            .iter()
            .map(|link| {
                query::distance(&Pose::IDENTITY, &swept, &Pose::IDENTITY, link)
                    .map_or(0.0, |d| d.distance)
            })
            .fold(f32::INFINITY, f32::min)
    }
}

/// The first segment of `path` along which the tool (a ball of `radius`) comes within
/// `margin` of an obstacle: its index (the segment from point `i` to `i + 1`).
pub fn first_blocked(
    path: &[[f32; 3]],
    radius: f32,
    obstacles: &[Obstacle],
    margin: f32,
) -> Option<usize> {
    path.windows(2).position(|segment| {
        obstacles
            .iter()
            .any(|o| o.distance(segment[0], segment[1], radius) < margin)
    })
}

/// A trajectory from the same start to the same end that keeps `margin` from every
/// obstacle: `path` itself if it does, else `path` with its blocked stretch replaced by a
/// side-step in the plane — the nearest one, tried 5 cm further out at a time, either side,
/// up to `reach` — or `None` if none is free (or the end itself is taken: only the stopped
/// robot moving can free it).
pub fn detour(
    path: &[[f32; 3]],
    radius: f32,
    obstacles: &[Obstacle],
    margin: f32,
    reach: f32,
) -> Option<Vec<[f32; 3]>> {
    let Some(first) = first_blocked(path, radius, obstacles, margin) else {
        return Some(path.to_vec());
    };
    let last = path.windows(2).rposition(|s| {
        obstacles
            .iter()
            .any(|o| o.distance(s[0], s[1], radius) < margin)
    })?;
    // Segment `last + 1` is clear, so point `last + 1` is; past the end there is none.
    let (entry, exit) = (path[first], *path.get(last + 1)?);
    if last + 1 == path.len() - 1
        && obstacles
            .iter()
            .any(|o| o.distance(exit, exit, radius) < margin)
    {
        return None;
    }
    let along = [exit[0] - entry[0], exit[1] - entry[1]];
    let length = (along[0] * along[0] + along[1] * along[1])
        .sqrt()
        .max(f32::EPSILON);
    let normal = [-along[1] / length, along[0] / length];
    let steps = (reach / 0.05).floor() as usize;
    (1..=steps)
        .flat_map(|k| [k as f32 * 0.05, -(k as f32) * 0.05])
        .map(|offset| {
            let side = |p: [f32; 3]| [p[0] + normal[0] * offset, p[1] + normal[1] * offset, p[2]];
            let mut candidate = path[..=first].to_vec();
            candidate.extend([side(entry), side(exit)]);
            candidate.extend_from_slice(&path[last + 1..]);
            candidate
        })
        .find(|candidate| first_blocked(candidate, radius, obstacles, margin).is_none())
}
