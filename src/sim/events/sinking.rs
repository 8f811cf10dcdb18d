//! The corner that sinks where a contact query's witness does not.
//!
//! When a body's face lies flush on an obstacle's face, the contact
//! query's witness points may be anywhere on the overlap, and their
//! relative velocity says nothing of the corners: a plate landing flat
//! while turning about one edge takes an impulse at its face's centre, and
//! after it the far corners still sink at 0.28 m/s while the witness, on
//! the near edge, rises. The search, trusting the witness, let the far
//! corners sink 4.6e-9 m (the skin is 1e-9 m) before another query's
//! witness moved to them. So a contact whose witness does not approach is
//! taken instead at the body part's deepest corner over the obstacle's
//! face that does approach, when there is one as deep as the witness: the
//! search then finds its impact at the skin, and the impulse is applied
//! where that corner touches (its contact point is the corner).

use super::bounds::FACE_COS;
use super::{Pair, World};
use crate::geometry::{Contact, PartKind, flat_faces};
use crate::sim::state::BodyState;
use crate::sim::trajectory::Party;

impl World<'_, '_> {
    /// `c` (with `rate`, its witness's relative normal speed) at its body
    /// part's deepest corner that approaches the obstacle's face there, if
    /// the witness does not approach and that corner lies over the face no
    /// more than `slack` m above the witness's distance. Against a body, or
    /// a part without a face along the normal, `c` itself.
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
        if !matches!(part_a.kind, PartKind::Convex { .. }) {
            return (c, rate);
        }
        let Some(face) = flat_faces(part_b, &ob.pose, &c.normal, FACE_COS)
            .into_iter()
            .max_by(|x, y| x.normal.dot(&c.normal).total_cmp(&y.normal.dot(&c.normal)))
        else {
            return (c, rate);
        };
        let m = face.normal;
        let deepest = part_a
            .vertices()
            .into_iter()
            .map(|v| s.point(&v))
            .map(|p| (m.dot(&p) - face.offset, p))
            .filter(|(h, p)| *h <= c.distance + slack && face.depth(p) >= 0.0)
            .map(|(h, p)| (h, p, m.dot(&s.velocity_at(&p))))
            .filter(|(.., r)| *r < 0.0)
            .min_by(|x, y| x.0.total_cmp(&y.0));
        match deepest {
            // Deeper than the witness, or the witness does not approach.
            Some((h, p, r)) if h < c.distance || rate >= 0.0 => (
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
