//! Rotations: the exponential and logarithm maps of SO(3) and their
//! derivatives, on nalgebra types.

use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use std::f64::consts::PI;

/// 3-vector of `f64`.
pub type Vec3 = Vector3<f64>;
/// 3×3 matrix of `f64`.
pub type Mat3 = Matrix3<f64>;

/// The skew-symmetric matrix `[v]×` with `[v]× w = v × w`.
pub fn skew(v: &Vec3) -> Mat3 {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// Below this angle (radians) the closed forms switch to Taylor series.
const SMALL_ANGLE: f64 = 1e-4;

/// `exp([r]×)` as a unit quaternion (Rodrigues, with the series form near zero).
pub fn exp_so3(r: &Vec3) -> UnitQuaternion<f64> {
    let angle = r.norm();
    let (s, c) = if angle < SMALL_ANGLE {
        let a2 = angle * angle;
        // sin(a/2)/a and cos(a/2), each to O(a^4).
        (0.5 - a2 / 48.0, 1.0 - a2 / 8.0)
    } else {
        ((0.5 * angle).sin() / angle, (0.5 * angle).cos())
    };
    UnitQuaternion::new_normalize(nalgebra::Quaternion::new(c, s * r.x, s * r.y, s * r.z))
}

/// The exponential-map vector of a rotation, with `|r| ≤ π`.
pub fn log_so3(q: &UnitQuaternion<f64>) -> Vec3 {
    // Choose the hemisphere with w ≥ 0 so the angle lies in [0, π].
    let q = if q.w < 0.0 {
        -q.into_inner()
    } else {
        q.into_inner()
    };
    let v = q.imag();
    let s = v.norm();
    if s < 1e-12 {
        // angle ≈ 2 s, direction v/s: r ≈ 2 v (1 + s²/6).
        return v * (2.0 / q.w.clamp(1e-300, 1.0));
    }
    let angle = 2.0 * s.atan2(q.w);
    v * (angle / s)
}

/// Grassia's reparameterisation: when `|r| > π` replace `r` by the equivalent
/// `r (1 − 2π/|r|)`, which describes the same rotation with `|r| ≤ π`.
/// Returns the new vector and whether it changed.
pub fn reparameterize(r: &Vec3) -> (Vec3, bool) {
    let angle = r.norm();
    if angle > PI {
        (r * (1.0 - 2.0 * PI / angle), true)
    } else {
        (*r, false)
    }
}

/// Coefficients `a = (1 − cos θ)/θ²`, `b = (θ − sin θ)/θ³` with series near 0.
fn jacobian_coefficients(angle: f64) -> (f64, f64) {
    if angle < 1e-3 {
        let t2 = angle * angle;
        (
            0.5 - t2 / 24.0 + t2 * t2 / 720.0,
            1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0,
        )
    } else {
        let t2 = angle * angle;
        (
            (1.0 - angle.cos()) / t2,
            (angle - angle.sin()) / (t2 * angle),
        )
    }
}

/// Left Jacobian `J_l(r)`: `exp([r + δr]×) ≈ exp([J_l δr]×) exp([r]×)`.
pub fn left_jacobian(r: &Vec3) -> Mat3 {
    let (a, b) = jacobian_coefficients(r.norm());
    let k = skew(r);
    Mat3::identity() + k * a + k * k * b
}

/// Right Jacobian `J_r(r) = J_l(−r)`: `exp([r + δr]×) ≈ exp([r]×) exp([J_r δr]×)`.
pub fn right_jacobian(r: &Vec3) -> Mat3 {
    left_jacobian(&-r)
}

/// Below this angle (rad) [`inverse_coefficient`] sums its series: the
/// closed form's two terms of about `1/θ²` cancel to `1/12`, losing
/// `12 ε/θ²` relative (3e-13 at 0.1 rad), while the series' first omitted
/// term, `|B₁₂|/12! · θ¹⁰`, is below 1e-18 relative there. Integration
/// steps turn bodies by less than this, and no sine or cosine is needed.
const SERIES_BELOW: f64 = 0.1;

/// Coefficient `(1/θ² − (1 + cos θ)/(2 θ sin θ))` of `[r]×²` in the inverse
/// Jacobians, with its series near 0 (valid for `θ < 2π`): the series is
/// `Σ_{n≥1} |B₂ₙ| θ^(2n−2) / (2n)!`.
fn inverse_coefficient(angle: f64) -> f64 {
    if angle < SERIES_BELOW {
        let t2 = angle * angle;
        1.0 / 12.0
            + t2 * (1.0 / 720.0
                + t2 * (1.0 / 30240.0 + t2 * (1.0 / 1209600.0 + t2 * (1.0 / 47900160.0))))
    } else {
        1.0 / (angle * angle) - (1.0 + angle.cos()) / (2.0 * angle * angle.sin())
    }
}

/// Inverse of the left Jacobian.
pub fn left_jacobian_inv(r: &Vec3) -> Mat3 {
    let c = inverse_coefficient(r.norm());
    let k = skew(r);
    Mat3::identity() - k * 0.5 + k * k * c
}

/// Inverse of the right Jacobian: `θ̇ = J_r⁻¹(θ) w` for `R = R₀ exp([θ]×)`, `Ṙ = R[w]×`.
pub fn right_jacobian_inv(r: &Vec3) -> Mat3 {
    left_jacobian_inv(&-r)
}

/// `J_r⁻¹(r) w = w + ½ r × w + c r × (r × w)` without forming the matrix
/// (the integrator's rotation rate, evaluated at every stage).
pub fn right_jacobian_inv_mul(r: &Vec3, w: &Vec3) -> Vec3 {
    let rw = r.cross(w);
    w + rw * 0.5 + r.cross(&rw) * inverse_coefficient(r.norm())
}

/// Convenience: rotation matrix of a unit quaternion.
pub fn rotation_matrix(q: &UnitQuaternion<f64>) -> Mat3 {
    *Rotation3::from(*q).matrix()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fd_left_jacobian(r: &Vec3, h: f64) -> Mat3 {
        // δθ such that exp(r + h e_i) = exp(δθ) exp(r): δθ = log(exp(r+he_i) exp(r)^-1).
        let base = exp_so3(r);
        let mut m = Mat3::zeros();
        for i in 0..3 {
            let mut rp = *r;
            rp[i] += h;
            let mut rm = *r;
            rm[i] -= h;
            let dp = log_so3(&(exp_so3(&rp) * base.inverse()));
            let dm = log_so3(&(exp_so3(&rm) * base.inverse()));
            m.set_column(i, &((dp - dm) / (2.0 * h)));
        }
        m
    }

    #[test]
    fn left_jacobian_matches_central_differences_small_and_large_angles() {
        for r in [
            Vec3::new(1e-7, -2e-7, 3e-8),
            Vec3::new(2e-4, 1e-4, -3e-4),
            Vec3::new(0.3, -0.2, 0.9),
            Vec3::new(2.0, 1.0, -1.5),
        ] {
            let analytic = left_jacobian(&r);
            let fd = fd_left_jacobian(&r, 1e-6);
            assert!(
                (analytic - fd).norm() < 1e-8,
                "r = {r:?}: {}",
                (analytic - fd).norm()
            );
            let inv = left_jacobian_inv(&r);
            assert!((analytic * inv - Mat3::identity()).norm() < 1e-12);
            let rinv = right_jacobian_inv(&r);
            assert!((right_jacobian(&r) * rinv - Mat3::identity()).norm() < 1e-12);
        }
    }

    /// The inverse coefficient's series and closed form meet at the switch
    /// (to the closed form's own round-off there), and the matrix-free
    /// product equals the matrix's.
    #[test]
    fn inverse_coefficient_is_continuous_at_the_series_switch() {
        let closed = |a: f64| 1.0 / (a * a) - (1.0 + a.cos()) / (2.0 * a * a.sin());
        for a in [SERIES_BELOW * (1.0 - 1e-12), 0.5 * SERIES_BELOW, 0.02] {
            let (series, exact) = (inverse_coefficient(a), closed(a));
            // The closed form loses 12 ε / a² relative to cancellation.
            let slack = 12.0 * f64::EPSILON / (a * a) * 4.0;
            assert!(
                ((series - exact) / exact).abs() < slack,
                "angle {a}: series {series:e}, closed form {exact:e}"
            );
        }
        let just_above = inverse_coefficient(SERIES_BELOW * (1.0 + 1e-12));
        let just_below = inverse_coefficient(SERIES_BELOW * (1.0 - 1e-12));
        assert!(((just_above - just_below) / just_below).abs() < 1e-12);
        let w = Vec3::new(0.7, -1.3, 2.1);
        for r in [
            Vec3::new(1e-7, -2e-7, 3e-8),
            Vec3::new(0.03, 0.05, -0.06),
            Vec3::new(0.3, -0.2, 0.9),
        ] {
            let m = right_jacobian_inv(&r) * w;
            assert!((right_jacobian_inv_mul(&r, &w) - m).norm() < 1e-15 * w.norm());
        }
    }

    #[test]
    fn exp_and_log_round_trip_across_the_whole_ball() {
        for r in [
            Vec3::zeros(),
            Vec3::new(1e-9, 0.0, 0.0),
            Vec3::new(0.5, -0.25, 1.0),
            Vec3::new(0.0, 3.0, 0.1),
        ] {
            let back = log_so3(&exp_so3(&r));
            assert!((back - r).norm() < 1e-12, "{r:?} -> {back:?}");
        }
    }

    #[test]
    fn reparameterisation_keeps_the_rotation_and_shrinks_the_vector() {
        let r = Vec3::new(2.5, 2.0, -1.0);
        let (s, changed) = reparameterize(&r);
        assert!(changed);
        assert!(s.norm() <= PI);
        let d = exp_so3(&r).angle_to(&exp_so3(&s));
        assert!(d < 1e-12);
    }
}
