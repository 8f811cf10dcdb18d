//! What bounds an obstacle for the broad phase of the event search.

use crate::geometry::PartKind;
use crate::math::Vec3;
use crate::scene::Obstacle;

/// The region an obstacle occupies, as the broad phase tests it against
/// a body's swept box (`World::sweep_box`): only a pair whose body may
/// meet it in the window is searched.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum ObstacleBound {
    /// The box around a bounded obstacle (world, corners).
    Box(Vec3, Vec3),
    /// A lone half-space, `n · x ≤ c` with `n` its outward unit normal: a
    /// floor's box would be unbounded, and its pair searched in every
    /// window of a body's flight however high it is.
    Plane(Vec3, f64),
    /// An unbounded compound: every window is searched.
    Unbounded,
}

impl ObstacleBound {
    pub(super) fn of(o: &Obstacle) -> ObstacleBound {
        if let [part] = o.geometry.parts.as_slice()
            && let PartKind::HalfSpace { normal } = part.kind
        {
            let frame = o.pose * part.offset;
            let n = frame.rotation * normal;
            return ObstacleBound::Plane(n, n.dot(&frame.translation.vector));
        }
        if !o.geometry.reach().is_finite() {
            return ObstacleBound::Unbounded;
        }
        let (mut lo, mut hi) = (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY));
        for (a, b) in o.geometry.outline(1.0) {
            for p in [a, b] {
                let p = (o.pose * nalgebra::Point3::from(p)).coords;
                lo = lo.inf(&p);
                hi = hi.sup(&p);
            }
        }
        ObstacleBound::Box(lo, hi)
    }

    /// Whether a body inside the box `(lo, hi)` may touch the obstacle:
    /// the boxes overlap, or the box's lowest corner along the plane's
    /// normal is not above it.
    pub(super) fn may_meet(&self, (lo, hi): &(Vec3, Vec3)) -> bool {
        match self {
            ObstacleBound::Box(a, b) => overlap(&(*lo, *hi), &(*a, *b)),
            ObstacleBound::Plane(n, level) => {
                let (centre, half) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
                n.dot(&centre) - n.abs().dot(&half) <= *level
            }
            ObstacleBound::Unbounded => true,
        }
    }
}

/// Whether two boxes (corners) overlap.
pub(super) fn overlap(a: &(Vec3, Vec3), b: &(Vec3, Vec3)) -> bool {
    (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(centre: Vec3, half: f64) -> (Vec3, Vec3) {
        (centre.add_scalar(-half), centre.add_scalar(half))
    }

    /// A tilted plane through (0, 0, 1): a box is searched exactly when
    /// its lowest corner along the normal reaches the plane, whatever the
    /// box's position along the plane.
    #[test]
    fn a_box_wholly_above_a_plane_is_not_searched() {
        let n = Vec3::new(1.0, 0.0, 1.0).normalize();
        let plane = ObstacleBound::Plane(n, n.dot(&Vec3::z()));
        // The lowest corner is (−h, ·, −h) from the centre: `h √2` below it
        // along the normal.
        let h = 0.1;
        for along in [-5.0, 0.0, 5.0] {
            let on = Vec3::new(along, 3.0 * along, 1.0 - along);
            for (height, meets) in [
                (h * 2f64.sqrt() + 1e-9, false),
                (h * 2f64.sqrt() - 1e-9, true),
            ] {
                let b = cube(on + n * height, h);
                assert_eq!(plane.may_meet(&b), meets, "{along} {height}");
            }
            // Below the plane, or through it: searched.
            assert!(plane.may_meet(&cube(on - n, h)));
            assert!(plane.may_meet(&cube(on, 10.0)));
        }
    }

    #[test]
    fn boxes_are_searched_when_they_overlap() {
        let b = ObstacleBound::Box(Vec3::zeros(), Vec3::repeat(1.0));
        assert!(b.may_meet(&cube(Vec3::repeat(1.05), 0.1)));
        assert!(!b.may_meet(&cube(Vec3::new(0.5, 0.5, 1.2), 0.1)));
        assert!(ObstacleBound::Unbounded.may_meet(&cube(Vec3::repeat(1e9), 1.0)));
    }
}
