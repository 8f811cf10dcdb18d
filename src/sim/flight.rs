//! Closed-form translation under gravity and linear drag, with exact tangents.

use crate::math::Vec3;

/// Translation after `τ` seconds from `(x₀, v₀)` under `v̇ = g − k v`, and
/// the coefficients of its tangent:
/// `δx = δx₀ + dx_dv δv₀ + dx_dk δk`, `δv = dv_dv δv₀ + dv_dk δk`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Translation {
    pub x: Vec3,
    pub v: Vec3,
    pub dx_dv: f64,
    pub dv_dv: f64,
    pub dx_dk: Vec3,
    pub dv_dk: Vec3,
}

/// `φ₁ = (1 − e^{−kτ})/k`, `φ₂ = (τ − φ₁)/k` and their k-derivatives.
/// Series for small `kτ` avoid cancellation.
fn drag_coefficients(k: f64, tau: f64) -> (f64, f64, f64, f64, f64) {
    let kt = k * tau;
    let e = (-kt).exp();
    if kt.abs() < 0.5 {
        // φ₁ = τ Σ (−kτ)ⁿ/(n+1)!, φ₂ = τ² Σ (−kτ)ⁿ/(n+2)!, differentiated termwise.
        let (mut p1, mut p2, mut d1, mut d2) = (0.0, 0.0, 0.0, 0.0);
        let (mut pow, mut prev) = (1.0, 0.0); // (kτ)ⁿ and (kτ)ⁿ⁻¹
        let (mut f1, mut f2) = (1.0, 2.0); // (n+1)! and (n+2)!
        for n in 0..20 {
            let sign = if n % 2 == 0 { 1.0 } else { -1.0 };
            p1 += sign * pow / f1;
            p2 += sign * pow / f2;
            if n >= 1 {
                d1 += sign * n as f64 * prev / f1;
                d2 += sign * n as f64 * prev / f2;
            }
            prev = pow;
            pow *= kt;
            f1 *= (n + 2) as f64;
            f2 *= (n + 3) as f64;
        }
        (
            e,
            tau * p1,
            tau * tau * p2,
            tau * tau * d1,
            tau * tau * tau * d2,
        )
    } else {
        let p1 = -(-kt).exp_m1() / k;
        let p2 = (tau - p1) / k;
        let d1 = (tau * e - p1) / k;
        let d2 = -(d1 + p2) / k;
        (e, p1, p2, d1, d2)
    }
}

/// Closed-form translation. `k = None` means no drag term at all (not
/// evaluated); `Some(k)` uses `v̇ = g − k v` with `k = c/m`.
pub fn translation(x0: &Vec3, v0: &Vec3, g: &Vec3, k: Option<f64>, tau: f64) -> Translation {
    match k {
        None => Translation {
            x: x0 + v0 * tau + g * (0.5 * tau * tau),
            v: v0 + g * tau,
            dx_dv: tau,
            dv_dv: 1.0,
            dx_dk: Vec3::zeros(),
            dv_dk: Vec3::zeros(),
        },
        Some(k) => {
            let (e, p1, p2, d1, d2) = drag_coefficients(k, tau);
            Translation {
                x: x0 + v0 * p1 + g * p2,
                v: v0 * e + g * p1,
                dx_dv: p1,
                dv_dv: e,
                dx_dk: v0 * d1 + g * d2,
                dv_dk: v0 * (-tau * e) + g * d1,
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ballistic_flight_matches_the_closed_form() {
        let g = Vec3::new(0.0, 0.0, -9.81);
        let t = translation(
            &Vec3::new(1.0, 2.0, 3.0),
            &Vec3::new(0.5, -1.0, 4.0),
            &g,
            None,
            0.7,
        );
        assert_eq!(
            t.x,
            Vec3::new(1.0 + 0.35, 2.0 - 0.7, 3.0 + 2.8 - 0.5 * 9.81 * 0.49)
        );
        assert_eq!(t.v, Vec3::new(0.5, -1.0, 4.0 - 9.81 * 0.7));
    }

    #[test]
    fn drag_solution_satisfies_the_ode_and_its_k_derivative_matches_fd() {
        let g = Vec3::new(0.0, 0.0, -9.81);
        let x0 = Vec3::new(0.1, 0.2, 0.3);
        let v0 = Vec3::new(3.0, -1.0, 2.0);
        for k in [1e-6, 0.05, 0.4, 2.0, 7.0] {
            for tau in [0.01, 0.3, 1.7] {
                let h = 1e-6;
                let a = translation(&x0, &v0, &g, Some(k), tau);
                let b = translation(&x0, &v0, &g, Some(k), tau + h);
                let c = translation(&x0, &v0, &g, Some(k), tau - h);
                // ẋ = v and v̇ = g − k v
                assert!(((b.x - c.x) / (2.0 * h) - a.v).norm() < 1e-6 * (1.0 + a.v.norm()));
                assert!(((b.v - c.v) / (2.0 * h) - (g - a.v * k)).norm() < 1e-5 * (1.0 + g.norm()));
                let hk = 1e-6 * k.max(1e-3);
                let p = translation(&x0, &v0, &g, Some(k + hk), tau);
                let m = translation(&x0, &v0, &g, Some(k - hk), tau);
                let fdx = (p.x - m.x) / (2.0 * hk);
                let fdv = (p.v - m.v) / (2.0 * hk);
                assert!(
                    (fdx - a.dx_dk).norm() < 1e-6 * (1.0 + fdx.norm()),
                    "k={k} τ={tau}: {fdx:?} vs {:?}",
                    a.dx_dk
                );
                assert!(
                    (fdv - a.dv_dk).norm() < 1e-6 * (1.0 + fdv.norm()),
                    "k={k} τ={tau}"
                );
            }
        }
    }

    #[test]
    fn tiny_drag_tends_to_ballistic() {
        let g = Vec3::new(0.0, 0.0, -9.81);
        let a = translation(
            &Vec3::zeros(),
            &Vec3::new(1.0, 0.0, 5.0),
            &g,
            Some(1e-12),
            1.0,
        );
        let b = translation(&Vec3::zeros(), &Vec3::new(1.0, 0.0, 5.0), &g, None, 1.0);
        assert!((a.x - b.x).norm() < 1e-10);
    }
}
