//! Whether a pivot's sweep is clear of its obstacle: the part it turns on
//! must stay below the contact plane (or the pivot is refused), and other
//! parts that come near the space the body sweeps are searched while it
//! turns (`sim::pivot`).

use super::turning::swept_box;
use super::{Pivot, PivotStart, STEP};
use crate::geometry::PartKind;
use crate::math::Vec3;

/// How an obstacle meets the space a pivoting body sweeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(in crate::sim) enum Clear {
    /// Nothing of it comes near: its pair needs no search while pivoting.
    Free,
    /// Parts other than the one turned on come near: searched, without it.
    Beside,
    /// The part turned on rises above the contact plane: no pivot.
    Blocked,
}

/// The box a pivoting body sweeps in its contact plane's frame, and,
/// leaning, in the far end's plane's frame (see [`Pivot::sweep`]).
pub(super) type Boxes = ([(f64, f64); 3], Option<[(f64, f64); 3]>);

/// A part a pivot turns on, for [`Pivot::clear_on`]: its index, the other
/// end's part (leaning), and the level of its plane along the normal from
/// the line's point, m.
struct On {
    part: usize,
    other: Option<usize>,
    level: f64,
}

impl Pivot {
    /// How the obstacle meets `swept`, a box that holds the body all
    /// through the pivot (intervals along the line, across it in the
    /// contact plane, and up from the plane, relative to `point`). The part
    /// turned on must stay below the plane ([`Clear::Blocked`] otherwise);
    /// a separating axis among the box's three proves another part clear,
    /// and a part that none separates (or an unbounded one) is
    /// [`Clear::Beside`].
    /// Leaning (`pivot::lean`), the far end's part must stay below its
    /// own plane in the second box (`swept.1`, of that plane's frame), and
    /// neither part counts as beside in the other's check.
    pub(super) fn clear(&self, p: &PivotStart<'_>, swept: &Boxes) -> Clear {
        let Some(lean) = self.lean else {
            return Self::clear_of(&self.point, &self.axis, &self.normal, p, &swept.0);
        };
        let levels = lean.levels(&self.normal, &self.point);
        let first = On {
            part: p.part,
            other: Some(lean.part),
            level: levels[0],
        };
        let far = On {
            part: lean.part,
            other: Some(p.part),
            level: levels[1],
        };
        let verdicts = [
            Self::clear_on(&self.point, &self.axis, &self.normal, p, &first, &swept.0),
            Self::clear_on(
                &self.point,
                &self.axis,
                &lean.normal,
                p,
                &far,
                swept.1.as_ref().unwrap_or(&swept.0),
            ),
        ];
        if verdicts.contains(&Clear::Blocked) {
            Clear::Blocked
        } else if verdicts.contains(&Clear::Beside) {
            Clear::Beside
        } else {
            Clear::Free
        }
    }

    /// [`Pivot::clear`] of a line through `point` along `axis` on the
    /// plane of normal `normal`, on the part `p.part`.
    pub(in crate::sim) fn clear_of(
        point: &Vec3,
        axis: &Vec3,
        normal: &Vec3,
        p: &PivotStart<'_>,
        swept: &[(f64, f64); 3],
    ) -> Clear {
        let on = On {
            part: p.part,
            other: None,
            level: 0.0,
        };
        Self::clear_on(point, axis, normal, p, &on, swept)
    }

    /// [`Pivot::clear_of`] with the part turned on, a part that is neither
    /// clear nor beside (the other end's, leaning), and the plane's level
    /// along `normal` from `point` given by `on`.
    fn clear_on(
        point: &Vec3,
        axis: &Vec3,
        normal: &Vec3,
        p: &PivotStart<'_>,
        on: &On,
        swept: &[(f64, f64); 3],
    ) -> Clear {
        let (a, n) = (*axis, *normal);
        let b = a.cross(&n);
        let tol = 1e-6 * p.dynamics.reach;
        let o = &p.scene.obstacles[p.obstacle];
        let mut verdict = Clear::Free;
        for (k, part) in o.geometry.parts.iter().enumerate() {
            let pose = o.pose * part.offset;
            let (pts, radius): (Vec<Vec3>, f64) = match &part.kind {
                PartKind::Ball { radius } => (vec![pose.translation.vector], *radius),
                PartKind::Convex { .. } => (
                    part.vertices()
                        .iter()
                        .map(|v| (o.pose * nalgebra::Point3::from(*v)).coords)
                        .collect(),
                    0.0,
                ),
                _ if k == on.part || Some(k) == on.other => continue,
                _ => {
                    verdict = Clear::Beside;
                    continue;
                }
            };
            if Some(k) == on.other {
                continue;
            }
            let span = |dir: &Vec3| {
                pts.iter()
                    .map(|q| dir.dot(&(q - point)))
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| {
                        (lo.min(x - radius), hi.max(x + radius))
                    })
            };
            let apart = |(lo, hi): (f64, f64), (s_lo, s_hi): (f64, f64)| hi < s_lo || lo > s_hi;
            let clear = apart(span(&a), swept[0])
                || apart(span(&b), swept[1])
                || span(&n).1 <= on.level + tol;
            if clear {
                continue;
            }
            if k == on.part {
                return Clear::Blocked;
            }
            verdict = Clear::Beside;
        }
        verdict
    }

    /// `swept` widened by how far the body's points move in one step at
    /// the pivot's top spin (the box is of the sampled angles).
    pub(super) fn padded(&self, swept: &Boxes, reach: f64, p: &PivotStart<'_>) -> Boxes {
        let pad = reach * self.w_max * STEP + 1e-6 * p.dynamics.reach;
        let grow = |b: &[(f64, f64); 3]| b.map(|(lo, hi)| (lo - pad, hi + pad));
        (grow(&swept.0), swept.1.as_ref().map(grow))
    }

    /// The box (intervals along the line, across it in the contact plane,
    /// and up from the plane, relative to `point`) of the points `pts`
    /// turned through every angle in `[lo, hi]` about the line. About a
    /// fixed axis each coordinate of a point is `c₀ + A cos(θ − φ)`, whose
    /// extremes over an interval are at its ends or at `φ` and `φ + π`
    /// (mod 2π): exact, and one pass over the points however long the
    /// pivot.
    /// Leaning, the second box is in the far end's plane's frame.
    pub(super) fn sweep(&self, pts: &[(usize, Vec3, f64, Vec3)], lo: f64, hi: f64) -> Boxes {
        (
            swept_box(&self.axis, &self.normal, pts, lo, hi),
            self.lean
                .map(|l| swept_box(&self.axis, &l.normal, pts, lo, hi)),
        )
    }
}
