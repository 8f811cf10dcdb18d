//! Contacts with a parabola obstacle `z = −κ x²`: the closest point by a
//! safeguarded Newton iteration, and the signed distance and normal.

use super::to_point;
use crate::geometry::shapes::{Part, PartKind};
use crate::math::Vec3;
use nalgebra::Isometry3;

/// Closest point on the parabola `z = −κ x²` (parabola frame) to `(x, z)`:
/// returns the foot parameter `s` (the foot is `(s, −κ s²)`).
/// Solves `2κ² s³ + (1 + 2κ z) s − x = 0` by safeguarded Newton iteration.
pub fn point_parabola(curvature: f64, x: f64, z: f64) -> f64 {
    let k = curvature;
    if !(k.is_finite() && x.is_finite() && z.is_finite()) {
        // No foot for a point that is not a point: the caller's finiteness
        // check turns the NaN distance into a typed error.
        return f64::NAN;
    }
    let g = |s: f64| 2.0 * k * k * s * s * s + (1.0 + 2.0 * k * z) * s - x;
    let dg = |s: f64| 6.0 * k * k * s * s + 1.0 + 2.0 * k * z;
    // The foot lies between 0 and x (|s| ≤ |x|) for points above the vertex
    // region; bracket and use Newton with bisection fallback.
    let (mut lo, mut hi) = if x >= 0.0 {
        (0.0, x.max(1e-300))
    } else {
        (x, 0.0)
    };
    // Widen the bracket if needed (points far below the surface).
    let mut width = 1.0_f64.max(x.abs());
    while g(lo) > 0.0 {
        lo -= width;
        width *= 2.0;
    }
    while g(hi) < 0.0 {
        hi += width;
        width *= 2.0;
    }
    let mut s = x.clamp(lo, hi);
    for _ in 0..200 {
        let gs = g(s);
        if gs == 0.0 {
            break;
        }
        if gs < 0.0 {
            lo = s;
        } else {
            hi = s;
        }
        let d = dg(s);
        let mut next = s - gs / d;
        if next <= lo || next >= hi || !next.is_finite() {
            next = 0.5 * (lo + hi);
        }
        if (next - s).abs() <= 1e-15 * (1.0 + s.abs()) {
            s = next;
            break;
        }
        s = next;
    }
    s
}

/// Signed distance from a world point to a parabola part placed at `pose`.
pub(super) fn parabola_point(pose: &Isometry3<f64>, curvature: f64, p: &Vec3) -> (f64, Vec3, Vec3) {
    let local = pose.inverse_transform_point(&to_point(p)).coords;
    let s = point_parabola(curvature, local.x, local.z);
    let foot = Vec3::new(s, local.y, -curvature * s * s);
    let d = local - foot;
    let above = local.z >= -curvature * local.x * local.x;
    let dist = d.norm();
    let n_local = if dist > 1e-300 {
        d / dist * if above { 1.0 } else { -1.0 }
    } else {
        Vec3::new(2.0 * curvature * s, 0.0, 1.0).normalize()
    };
    let sign = if above { 1.0 } else { -1.0 };
    (
        sign * dist,
        pose.rotation * n_local,
        (pose * to_point(&foot)).coords,
    )
}

/// Contact between a bounded part `pa` (at `pose_a`) and a parabola part.
pub(super) fn against_parabola(
    pa: &Part,
    pose_a: &Isometry3<f64>,
    pose_b: &Isometry3<f64>,
    curvature: f64,
) -> Option<(f64, Vec3, Vec3, Vec3)> {
    match &pa.kind {
        PartKind::Ball { radius } => {
            let c = (pose_a * to_point(&Vec3::zeros())).coords;
            let (d, n, foot) = parabola_point(pose_b, curvature, &c);
            Some((d - radius, n, c - n * *radius, foot))
        }
        PartKind::Convex { vertices, .. } => vertices
            .iter()
            .map(|v| {
                let p = (pose_a * to_point(v)).coords;
                let (d, n, foot) = parabola_point(pose_b, curvature, &p);
                (d, n, p, foot)
            })
            .min_by(|x, y| x.0.total_cmp(&y.0)),
        _ => None,
    }
}
