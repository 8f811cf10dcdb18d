//! Leaning: a hinge whose two ends touch surfaces with different normals
//! (`sim::pivot`) — a pair of scissors with a handle on a coatrack's base
//! and a blade against its pole, or lying across the edge of the base with
//! one corner on its top face.
//!
//! The body turns about the line through its two supports `p₁`, `p₂`
//! (`p₂ = p₁ + L a`) exactly as on one face: both ends stay put, so both
//! stay in contact, and the angle follows the same pendulum. What differs
//! is which contact forces hold the line. The hinge needs a force `F` and a
//! moment `M` about `p₁` (the force and moment balance of
//! `Pivot::forces`); the moment about the line itself is zero, as forces
//! at points of the line make none. Forces `f₁`, `f₂` at the ends supply
//! them when `f₁ + f₂ = F` and `L a × f₂ = M`, which fixes `f₂` up to a
//! squeeze along the line:
//!
//! ```text
//! f₂(β) = (M / L) × a + β a,   f₁(β) = F − f₂(β).
//! ```
//!
//! The line holds while some `β` puts each `fᵢ` inside its friction cone
//! (`|fᵢ − (nᵢ·fᵢ) nᵢ| ≤ μ nᵢ·fᵢ`). Along the affine `fᵢ(β)` each cone
//! is an interval of `β`, in closed form (the roots of a quadratic); the
//! line holds where the two intervals meet. When they do not, it *lifts
//! off* if no `β` even keeps both normal forces non-negative, and *slips*
//! otherwise.
//!
//! The body lands when a point off the line reaches either surface's
//! plane, and on a face that point must be over the face, as for a hinge on
//! one face. While it leans, the obstacle's pair is searched without the
//! two parts it leans on (or not at all when nothing else comes near).

use super::PivotEnd;
use crate::math::Vec3;

/// The second end of a hinge whose ends touch surfaces with different
/// normals: the obstacle part it touches and the unit contact normal
/// there (out of the obstacle); and both surfaces' planes, `nᵢ · x =
/// planes[i]` (a face's own plane where the end lies on a face, else the
/// plane through the surface point closest to the end).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Lean {
    pub part: usize,
    pub normal: Vec3,
    pub planes: [f64; 2],
}

impl Lean {
    /// Where both surfaces' planes are along their normals from `point`
    /// (`first`: the first surface's normal), m.
    pub(super) fn levels(&self, first: &Vec3, point: &Vec3) -> [f64; 2] {
        [
            self.planes[0] - first.dot(point),
            self.planes[1] - self.normal.dot(point),
        ]
    }
}

/// The interval of `β` (possibly empty: `lo > hi`) for which `c + β e`
/// lies in the friction cone of normal `n` and coefficient `mu`, within
/// `tol` (N) of its boundary.
fn cone_interval(c: &Vec3, e: &Vec3, n: &Vec3, mu: f64, tol: f64) -> (f64, f64) {
    // q(β) = (1 + μ²)(n·f)² − |f|² ≥ 0 and n·f ≥ 0, for f = c + β e.
    let k = 1.0 + mu * mu;
    let (cn, en) = (n.dot(c), n.dot(e));
    let a = k * en * en - e.norm_squared();
    let b = 2.0 * (k * cn * en - c.dot(e));
    let cc = k * cn * cn - c.norm_squared() + tol * tol;
    let all = (f64::NEG_INFINITY, f64::INFINITY);
    let empty = (f64::INFINITY, f64::NEG_INFINITY);
    // The half-line where the normal force is not negative.
    let normal = if en.abs() <= f64::EPSILON {
        if cn >= -tol { all } else { empty }
    } else if en > 0.0 {
        ((-tol - cn) / en, f64::INFINITY)
    } else {
        (f64::NEG_INFINITY, (-tol - cn) / en)
    };
    let quad = if a.abs() <= 1e-12 * (1.0 + e.norm_squared()) {
        // Linear: b β + c ≥ 0.
        if b.abs() <= f64::EPSILON * (1.0 + cc.abs()) {
            if cc >= 0.0 { all } else { empty }
        } else if b > 0.0 {
            (-cc / b, f64::INFINITY)
        } else {
            (f64::NEG_INFINITY, -cc / b)
        }
    } else {
        let disc = b * b - 4.0 * a * cc;
        if disc < 0.0 {
            if a > 0.0 { all } else { empty }
        } else {
            let s = disc.sqrt();
            let (r1, r2) = {
                let x = (-b - s) / (2.0 * a);
                let y = (-b + s) / (2.0 * a);
                (x.min(y), x.max(y))
            };
            if a < 0.0 {
                (r1, r2)
            } else if en > 0.0 {
                // Outside the roots; the nappe where n·f grows with β.
                (r2, f64::INFINITY)
            } else {
                (f64::NEG_INFINITY, r1)
            }
        }
    };
    (quad.0.max(normal.0), quad.1.min(normal.1))
}

/// Why a leaning hinge stops holding, if it does: `None` while forces at
/// the ends inside their cones supply `force` and `moment` (about the
/// first end; see the module notes), [`PivotEnd::LiftsOff`] when no
/// squeeze keeps both normal forces non-negative, [`PivotEnd::Slips`]
/// otherwise.
pub(super) fn fails(
    force: &Vec3,
    moment: &Vec3,
    axis: &Vec3,
    length: f64,
    normals: [&Vec3; 2],
    mu: f64,
    tol: f64,
) -> Option<PivotEnd> {
    let a = *axis;
    let m_perp = moment - a * a.dot(moment);
    let f2 = (m_perp / length).cross(&a);
    let f1 = force - f2;
    let (lo1, hi1) = cone_interval(&f1, &(-a), normals[0], mu, tol);
    let (lo2, hi2) = cone_interval(&f2, &a, normals[1], mu, tol);
    if lo1.max(lo2) <= hi1.min(hi2) {
        return None;
    }
    // Without the cones' sides: only the normal forces' signs.
    let (lo1, hi1) = cone_interval(&f1, &(-a), normals[0], 1e12, tol);
    let (lo2, hi2) = cone_interval(&f2, &a, normals[1], 1e12, tol);
    Some(if lo1.max(lo2) > hi1.min(hi2) {
        PivotEnd::LiftsOff
    } else {
        PivotEnd::Slips
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// In the cone, by direct evaluation.
    fn inside(f: &Vec3, n: &Vec3, mu: f64) -> bool {
        let fn_ = n.dot(f);
        fn_ >= -1e-12 && (f - n * fn_).norm() <= mu * fn_ + 1e-12
    }

    #[test]
    fn the_cone_interval_is_where_the_force_is_in_the_cone() {
        let cases = [
            (
                Vec3::new(0.3, -0.2, 1.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::z(),
                0.5,
            ),
            (
                Vec3::new(0.3, -0.2, -1.0),
                Vec3::new(0.0, 0.6, 0.8),
                Vec3::z(),
                0.8,
            ),
            (
                Vec3::new(2.0, 0.1, 0.4),
                Vec3::new(0.0, 0.0, -1.0),
                Vec3::new(0.6, 0.0, 0.8),
                1.0,
            ),
            (
                Vec3::new(0.0, 1.0, 0.0),
                Vec3::new(0.0, -0.6, 0.8),
                Vec3::new(0.0, 0.6, 0.8),
                0.3,
            ),
        ];
        for (c, e, n, mu) in cases {
            let e = e.normalize();
            let n = n.normalize();
            let (lo, hi) = cone_interval(&c, &e, &n, mu, 0.0);
            for k in -4000..=4000 {
                let beta = k as f64 * 1e-3;
                let f = c + e * beta;
                let within = beta >= lo - 1e-9 && beta <= hi + 1e-9;
                let near_end = (beta - lo).abs() < 2e-3 || (beta - hi).abs() < 2e-3;
                if !near_end {
                    assert_eq!(
                        within,
                        inside(&f, &n, mu),
                        "β {beta}: [{lo}, {hi}] {c:?} {e:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_line_between_a_floor_and_a_wall_holds_slips_or_lifts_off() {
        // The line along y from a floor point (normal +z) at the origin to
        // a wall point (normal −x) at y = 1.
        let axis = Vec3::y();
        let normals = [&Vec3::z(), &(-Vec3::x())];
        // Straight up, no moment: the floor takes it all.
        assert_eq!(
            fails(&Vec3::z(), &Vec3::zeros(), &axis, 1.0, normals, 0.5, 1e-12),
            None
        );
        // The wall end pushes off the wall and carries half the weight,
        // f₂ = (−1, 0, ½), f₁ = (0, 0, ½): its friction must hold ½ against
        // a normal force of 1.
        let force = Vec3::new(-1.0, 0.0, 1.0);
        let moment = Vec3::y().cross(&Vec3::new(-1.0, 0.0, 0.5));
        assert_eq!(
            fails(&force, &moment, &axis, 1.0, normals, 1.0, 1e-12),
            None
        );
        assert_eq!(
            fails(&force, &moment, &axis, 1.0, normals, 0.2, 1e-12),
            Some(PivotEnd::Slips)
        );
        // Pulled off the floor: it lifts off.
        let pull = Vec3::new(1.0, 0.0, -1.0);
        assert_eq!(
            fails(&pull, &Vec3::zeros(), &axis, 1.0, normals, 1.0, 1e-12),
            Some(PivotEnd::LiftsOff)
        );
    }
}
