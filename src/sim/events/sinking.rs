//! The corner that sinks where a contact query's witness does not.
//!
//! When a body's face lies flush on an obstacle's face, the contact
//! query's witness points may be anywhere on the overlap, and their
//! relative velocity says nothing of the corners: a plate landing flat
//! while turning about one edge takes an impulse at its face's centre, and
//! after it the far corners still sink at 0.28 m/s while the witness, on
//! the near edge, rises. The search, trusting the witness, let the far
//! corners sink 5.4e-9 m (the skin is 1e-9 m; `tests/flush.rs`) before
//! another query's witness moved to them. And where an edge lies nearly
//! flush, the query's gap itself can be off: 5e-10 m reported while one
//! end is 1.7e-9 m inside. So a contact is taken instead at the body part's deepest
//! corner over the obstacle's face that approaches, when that corner is
//! deeper than the witness, or as deep (within a slack) while the witness
//! does not approach: the search then finds its impact at the skin, and
//! the impulse is applied where that corner touches (its contact point is
//! the corner).

use super::bounds::FACE_COS;
use super::{Pair, World};
use crate::geometry::{Contact, Part, PartKind, flat_faces};
use crate::math::Vec3;
use crate::sim::state::BodyState;
use crate::sim::trajectory::Party;
use nalgebra::Isometry3;
use smallvec::SmallVec;

/// How much deeper than an approaching witness a corner must lie to take
/// its place, m: a vertex witness's own height differs by round-off.
const DEEPER: f64 = 1e-12;

/// The plane (unit normal, world, and offset: `m · p = offset`) of the face
/// of `part` at `pose` nearest to `n`, within `FACE_COS`.
fn plane(part: &Part, pose: &Isometry3<f64>, n: &Vec3) -> Option<(Vec3, f64)> {
    let w = pose * part.offset;
    match &part.kind {
        PartKind::HalfSpace { normal } => {
            let m = w.rotation * normal;
            (m.dot(n) >= FACE_COS).then(|| (m, m.dot(&w.translation.vector)))
        }
        PartKind::Convex {
            vertices, faces, ..
        } => faces
            .iter()
            .map(|(f, corners)| (w.rotation * f, corners))
            .filter(|(m, _)| m.dot(n) >= FACE_COS)
            .max_by(|x, y| x.0.dot(n).total_cmp(&y.0.dot(n)))
            .and_then(|(m, corners)| {
                let v = vertices.get(*corners.first()?)?;
                Some((m, m.dot(&(w * nalgebra::Point3::from(*v)).coords)))
            }),
        _ => None,
    }
}

impl World<'_, '_> {
    /// `c` (with `rate`, its witness's relative normal speed) at its body
    /// part's deepest corner over the obstacle's face there that
    /// approaches it, no more than `slack` m above the witness's distance,
    /// if that corner is deeper than the witness or the witness does not
    /// approach. Against a body, or a part without a face along the
    /// normal, `c` itself.
    pub(super) fn sinking(
        &self,
        pair: &Pair,
        sa: &Option<BodyState>,
        (c, rate): (Contact, f64),
        slack: f64,
    ) -> (Contact, f64) {
        let (Party::Obstacle(o), Some(s)) = (pair.b, sa) else {
            return (c, rate);
        };
        let ob = &self.scene.obstacles[o];
        let body = &self.scene.bodies[pair.a].geometry;
        let (Some(part_a), Some(part_b)) =
            (body.parts.get(c.part_a), ob.geometry.parts.get(c.part_b))
        else {
            return (c, rate);
        };
        let PartKind::Convex { vertices, .. } = &part_a.kind else {
            return (c, rate);
        };
        // Most queries end below, before the face's polygon is built: no
        // corner approaches as deep as the witness on the face's plane, or
        // the witness approaches and none is deeper.
        let Some((m, offset)) = plane(part_b, &ob.pose, &c.normal) else {
            return (c, rate);
        };
        let world = s.pose() * part_a.offset;
        let sinking: SmallVec<[(f64, Vec3, f64); 16]> = vertices
            .iter()
            .map(|v| (world * nalgebra::Point3::from(*v)).coords)
            .map(|p| (m.dot(&p) - offset, p))
            .filter(|(h, _)| *h <= c.distance + slack)
            .map(|(h, p)| (h, p, m.dot(&s.velocity_at(&p))))
            .filter(|(.., r)| *r < 0.0)
            .collect();
        // Deeper than the witness, or the witness does not approach.
        let takes = |h: f64| h < c.distance - DEEPER || rate >= 0.0;
        if !sinking.iter().any(|(h, ..)| takes(*h)) {
            return (c, rate);
        }
        // Only a corner over the face touches it (the polygon, built here
        // only, is of the same face as the plane).
        let Some(face) = flat_faces(part_b, &ob.pose, &c.normal, FACE_COS)
            .into_iter()
            .max_by(|x, y| x.normal.dot(&c.normal).total_cmp(&y.normal.dot(&c.normal)))
        else {
            return (c, rate);
        };
        let deepest = sinking
            .into_iter()
            .filter(|(_, p, _)| face.depth(p) >= 0.0)
            .min_by(|x, y| x.0.total_cmp(&y.0));
        match deepest {
            Some((h, p, r)) if takes(h) => (
                Contact {
                    distance: h,
                    normal: m,
                    point_a: p,
                    point_b: p - m * h,
                    ..c
                },
                r,
            ),
            _ => (c, rate),
        }
    }
}
