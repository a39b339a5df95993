//! The space a sweep takes, as capsules with their boxes: two spaces are compared link by
//! link with parry3d, and the boxes spare that query for every pair of links too far apart
//! for it to matter.

use parry3d::math::{Pose, Vector};
use parry3d::query;
use parry3d::shape::Capsule;

/// Added to the margin before a gap between boxes answers for the links inside: the boxes
/// are computed in `f32`, a few ulps from the capsules they bound, and a tenth of a
/// millimetre is thousands of those at a cell's size. A pair closer than that is measured.
const BOX_SLACK: f32 = 1e-4;

/// An axis-aligned box of the working plane: its lowest corner and its highest.
#[derive(Debug, Clone, Copy)]
struct Bounds {
    min: [f32; 2],
    max: [f32; 2],
}

impl Bounds {
    const EMPTY: Self = Self {
        min: [f32::INFINITY; 2],
        max: [f32::NEG_INFINITY; 2],
    };

    /// Everywhere: apart from nothing.
    const EVERYWHERE: Self = Self {
        min: [f32::NEG_INFINITY; 2],
        max: [f32::INFINITY; 2],
    };

    /// The box of a link from `a` to `b`, `radius` thick. A link with a point that is no
    /// point is boxed everywhere, so that parry3d measures it, whatever it makes of it.
    fn link(a: [f32; 2], b: [f32; 2], radius: f32) -> Self {
        if !a.iter().chain(&b).all(|c| c.is_finite()) {
            return Self::EVERYWHERE;
        }
        Self {
            min: [a[0].min(b[0]) - radius, a[1].min(b[1]) - radius],
            max: [a[0].max(b[0]) + radius, a[1].max(b[1]) + radius],
        }
    }

    fn merged(self, other: Self) -> Self {
        Self {
            min: [self.min[0].min(other.min[0]), self.min[1].min(other.min[1])],
            max: [self.max[0].max(other.max[0]), self.max[1].max(other.max[1])],
        }
    }

    /// Whether everything in `self` is at least `apart` from everything in `other`. The
    /// gap between two boxes is never more than the distance between what they hold, so a
    /// `true` is certain; a `false` says only that the boxes cannot tell.
    fn apart(&self, other: &Self, apart: f32) -> bool {
        let gap = |axis: usize| {
            (other.min[axis] - self.max[axis])
                .max(self.min[axis] - other.max[axis])
                .max(0.0)
        };
        let (x, y) = (gap(0), gap(1));
        x * x + y * y >= apart * apart
    }
}

/// The links of a sweep, each a capsule in the plane z = 0 with its box, and the box of
/// them all.
#[derive(Debug, Clone)]
pub(super) struct Space {
    links: Vec<(Capsule, Bounds)>,
    whole: Bounds,
}

impl Space {
    /// The space of links between these points of the plane, each `radius` thick.
    pub(super) fn new(links: impl IntoIterator<Item = ([f32; 2], [f32; 2])>, radius: f32) -> Self {
        let v = |p: [f32; 2]| Vector::new(p[0], p[1], 0.0);
        let links: Vec<_> = links
            .into_iter()
            .map(|(a, b)| (Capsule::new(v(a), v(b), radius), Bounds::link(a, b, radius)))
            .collect();
        let whole = links
            .iter()
            .fold(Bounds::EMPTY, |whole, (_, bounds)| whole.merged(*bounds));
        Self { links, whole }
    }

    /// Whether every link of `self` is at least `margin` from every link of `other`, as
    /// parry3d measures them: pairs whose boxes are that far apart are not measured, since
    /// their distance cannot be less.
    pub(super) fn clear_of(&self, other: &Self, margin: f32) -> bool {
        let far = margin + BOX_SLACK;
        if self.whole.apart(&other.whole, far) {
            return true;
        }
        self.links.iter().all(|(a, a_box)| {
            a_box.apart(&other.whole, far)
                || other.links.iter().all(|(b, b_box)| {
                    a_box.apart(b_box, far)
                        || query::distance(&Pose::IDENTITY, a, &Pose::IDENTITY, b)
                            .is_ok_and(|d| d.distance >= margin)
                })
        })
    }

    /// The least distance between a link of `self` and one of `other`, as parry3d measures
    /// it: 0 where they touch.
    pub(super) fn distance(&self, other: &Self) -> f32 {
        self.links
            .iter()
            .flat_map(|(a, _)| {
                other.links.iter().map(move |(b, _)| {
                    query::distance(&Pose::IDENTITY, a, &Pose::IDENTITY, b)
                        .map_or(0.0, |d| d.distance)
                })
            })
            .fold(f32::INFINITY, f32::min)
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;

    /// Every pair measured, as the boxes would have it without them.
    fn measured(a: &Space, b: &Space, margin: f32) -> bool {
        a.links.iter().all(|(a, _)| {
            b.links.iter().all(|(b, _)| {
                query::distance(&Pose::IDENTITY, a, &Pose::IDENTITY, b)
                    .is_ok_and(|d| d.distance >= margin)
            })
        })
    }

    fn link() -> impl Strategy<Value = ([f32; 2], [f32; 2])> {
        let point = || [-0.3f32..0.3, -0.3f32..0.3];
        (point(), point())
    }

    proptest! {
        #[test]
        fn the_boxes_never_change_the_answer(
            a in proptest::collection::vec(link(), 1..8),
            b in proptest::collection::vec(link(), 1..8),
            // Far enough to part the two now and then, near enough to mostly not.
            shift in [-0.8f32..0.8, -0.8f32..0.8],
            margin in 0.0f32..0.1,
        ) {
            let b = b.into_iter().map(|(p, q)| {
                let moved = |p: [f32; 2]| [p[0] + shift[0], p[1] + shift[1]];
                (moved(p), moved(q))
            });
            let (a, b) = (Space::new(a, 0.035), Space::new(b, 0.035));
            prop_assert_eq!(a.clear_of(&b, margin), measured(&a, &b, margin));
        }
    }

    #[test]
    fn links_just_beyond_the_margin_are_clear_and_just_within_it_are_not() {
        let arm = |y: f32| Space::new([([0.0, y], [0.5, y])], 0.035);
        // Centre lines 10 cm apart: 3 cm between the surfaces.
        assert!(arm(0.0).clear_of(&arm(0.1001), 0.03));
        assert!(!arm(0.0).clear_of(&arm(0.0999), 0.03));
        let lost = Space::new([([0.0, f32::NAN], [0.5, 10.0])], 0.035);
        // Whatever parry3d makes of a point that is no point, the boxes leave it to it.
        for (a, b) in [(&arm(0.0), &lost), (&lost, &arm(0.0))] {
            assert_eq!(a.clear_of(b, 0.03), measured(a, b, 0.03));
        }
    }
}
