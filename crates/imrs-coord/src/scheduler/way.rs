//! The way a robot takes to a task, worked out ahead as the seed's scheduler must: where it
//! enters each zone on the way (its entry points), and how much longer it is round a
//! working robot it would pass too near, as the coordinator's alternative trajectory would
//! take it. Coarse, as the seed says it must be to run in real time: a straight way, zones
//! as discs, and a working robot as a disc about its tool.

use super::cell::distance;

/// How far along the straight way from `from` to `to` it first comes within `radius` of
/// `centre`: its entry point, in metres from `from`; `None` if it never does. A way that
/// starts inside enters at 0.
pub(crate) fn entry(from: [f64; 2], to: [f64; 2], centre: [f64; 2], radius: f64) -> Option<f64> {
    let offset = [from[0] - centre[0], from[1] - centre[1]];
    let outside = offset[0] * offset[0] + offset[1] * offset[1] - radius * radius;
    if outside <= 0.0 {
        return Some(0.0);
    }
    let length = distance(from, to);
    if length == 0.0 {
        return None;
    }
    let u = [(to[0] - from[0]) / length, (to[1] - from[1]) / length];
    let b = u[0] * offset[0] + u[1] * offset[1];
    let discriminant = b * b - outside;
    if discriminant < 0.0 {
        return None;
    }
    let along = -b - discriminant.sqrt();
    (0.0..=length).contains(&along).then_some(along)
}

/// Where the way from `from` to `to` passes nearest `centre`, in metres along it, and how
/// much longer it is round a disc of `radius` about `centre` than straight through it: the
/// arc on the near side instead of the chord. `None` if the way keeps clear of the disc,
/// or if it starts or ends inside it (there is no way round then: a matter for the zone).
pub(crate) fn detour(
    from: [f64; 2],
    to: [f64; 2],
    centre: [f64; 2],
    radius: f64,
) -> Option<(f64, f64)> {
    let length = distance(from, to);
    if length == 0.0 || distance(from, centre) < radius || distance(to, centre) < radius {
        return None;
    }
    let u = [(to[0] - from[0]) / length, (to[1] - from[1]) / length];
    let offset = [centre[0] - from[0], centre[1] - from[1]];
    let along = (u[0] * offset[0] + u[1] * offset[1]).clamp(0.0, length);
    let nearest = [from[0] + u[0] * along, from[1] + u[1] * along];
    let gap = distance(nearest, centre);
    if gap >= radius {
        return None;
    }
    let chord = 2.0 * (radius * radius - gap * gap).sqrt();
    let arc = 2.0 * radius * (gap / radius).acos();
    Some((along, arc - chord))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_way_enters_a_zone_where_it_first_meets_it() {
        // Along the x axis through a disc of radius 0.1 about (0.5, 0).
        let along = entry([0.0, 0.0], [1.0, 0.0], [0.5, 0.0], 0.1).unwrap();
        assert!((along - 0.4).abs() < 1e-9, "{along}");
        // Starting inside: at once.
        assert_eq!(entry([0.5, 0.05], [1.0, 0.0], [0.5, 0.0], 0.1), Some(0.0));
        // Passing beside it, or stopping short of it: never.
        assert_eq!(entry([0.0, 0.2], [1.0, 0.2], [0.5, 0.0], 0.1), None);
        assert_eq!(entry([0.0, 0.0], [0.3, 0.0], [0.5, 0.0], 0.1), None);
    }

    #[test]
    fn a_way_through_a_disc_is_longer_round_it_and_one_beside_it_is_not() {
        // Through the centre: half the circumference instead of the diameter, passing
        // nearest half-way.
        let (along, through) = detour([0.0, 0.0], [1.0, 0.0], [0.5, 0.0], 0.1).unwrap();
        assert!((along - 0.5).abs() < 1e-9, "{along}");
        assert!(
            (through - (std::f64::consts::PI * 0.1 - 0.2)).abs() < 1e-9,
            "{through}"
        );
        // Grazing it: less.
        let (_, grazing) = detour([0.0, 0.09], [1.0, 0.09], [0.5, 0.0], 0.1).unwrap();
        assert!(grazing > 0.0 && grazing < through, "{grazing}");
        assert_eq!(detour([0.0, 0.2], [1.0, 0.2], [0.5, 0.0], 0.1), None);
        // Ending, or starting, inside it: no way round.
        assert_eq!(detour([0.0, 0.0], [0.45, 0.0], [0.5, 0.0], 0.1), None);
        assert_eq!(detour([0.55, 0.0], [1.0, 0.0], [0.5, 0.0], 0.1), None);
    }
}
