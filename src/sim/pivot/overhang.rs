//! Parts of a pivoting body that hang over the edge of the face it turns
//! on: a pair of scissors lying across the edge of a coatrack's base, one
//! blade on the top face, a handle beyond the edge and below the top
//! face's plane.
//!
//! The hinge finds its landing on the contact plane, which it takes as
//! unbounded (`sim::pivot`), so a point already below that plane would
//! land at once and the body stayed in micro-collisions at the edge. But
//! a part that hangs clear of the obstacle's part turned on, farther than
//! the support band (and [`CLEAR`] of the body's reach) from it, touches
//! it nowhere: its points are left out
//! of the plane's landing, and instead that part is searched against the
//! part turned on like any other part of the obstacle (the pair is
//! searched while the body pivots: [`super::Pivot::beside`]). A point
//! below the plane on a part that touches the face, within the band, is a
//! body reaching down over the edge from the face itself: no pivot.

use super::PivotStart;
use crate::geometry::part_contacts;
use crate::math::Vec3;

/// How far a hanging part must be from the part turned on, as a fraction
/// of the body's reach (and at least the support band). A part closer
/// than that hangs at the face's edge, where the search crawls in steps
/// the size of its gap: a scissors blade 0.1 mm below the coatrack base's
/// edge took 11,000 contact queries in one 19 ms hinge, four times the
/// micro-collisions it replaced.
const CLEAR: f64 = 1e-3;

/// A point off the line: its part, body offset, radius, and offset from
/// the line's point (world).
type Off<'a> = &'a (usize, Vec3, f64, Vec3);

/// The parts of the points `off` that hang clear of the part turned on
/// (none when no point is more than `tol` below the plane of normal `n`
/// at `level` from the line's point), taken out of `off`; `None` when a
/// point below the plane is on a part within the support band of it, or
/// the body leans (no pivot).
pub(super) fn take(
    p: &PivotStart<'_>,
    off: &mut Vec<Off<'_>>,
    n: &Vec3,
    level: f64,
    tol: f64,
) -> Option<Vec<usize>> {
    let mut parts: Vec<usize> = off
        .iter()
        .filter(|(.., radius, r)| n.dot(r) - level - radius < -tol)
        .map(|(k, ..)| *k)
        .collect();
    if parts.is_empty() {
        return Some(parts);
    }
    if p.lean.is_some() {
        return None;
    }
    parts.sort_unstable();
    parts.dedup();
    let o = &p.scene.obstacles[p.obstacle];
    let near = part_contacts(
        &p.scene.bodies[p.body].geometry,
        &p.post.pose(),
        &o.geometry,
        &o.pose,
        p.band.max(CLEAR * p.dynamics.reach),
    );
    let touches = |k: &usize| near.iter().any(|c| c.part_a == *k && c.part_b == p.part);
    if parts.iter().any(touches) {
        return None;
    }
    off.retain(|(k, ..)| !parts.contains(k));
    Some(parts)
}
