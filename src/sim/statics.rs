//! Whether contacts can hold a body still against gravity (static
//! equilibrium under Coulomb friction).
//!
//! A body touching obstacles at points `pᵢ` with inward normals `nᵢ` and
//! friction coefficients `μᵢ` is *held* when some contact forces `fᵢ` inside
//! the friction cones (`|fᵢ − (fᵢ·nᵢ)nᵢ| ≤ μᵢ fᵢ·nᵢ`) balance its weight:
//! `Σ fᵢ = −m g` and `Σ (pᵢ − x) × fᵢ = 0`. Each cone is replaced by the
//! inscribed pyramid with four edges `nᵢ ± μᵢ t₁`, `nᵢ ± μᵢ t₂` (so "held"
//! is conservative) and the forces by non-negative combinations of the
//! edges: held exactly when the non-negative least-squares residual of that
//! 6 × 4k system vanishes. Without friction this is "the centre of mass is
//! over the support polygon"; with it, a body wedged between a peg and a
//! pole, or leaning on a wall, is held as it would be.

use crate::math::{Vec3, nnls::nnls, plane_basis};
use nalgebra::{DMatrix, DVector};

/// One supporting contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Support {
    /// Contact point, world.
    pub point: Vec3,
    /// Unit normal pointing from the obstacle into the body.
    pub normal: Vec3,
    /// Coulomb coefficient (0: frictionless).
    pub friction: f64,
}

/// Relative residual below which the weight counts as balanced.
const BALANCED: f64 = 1e-9;

/// Whether the supports can balance the weight of a body with centre of
/// mass `com` under gravity along `down` (unit). `reach` (m) scales the
/// torque rows to the force rows.
pub(crate) fn held(supports: &[Support], com: &Vec3, down: &Vec3, reach: f64) -> bool {
    if supports.is_empty() {
        return false;
    }
    let lever = reach.max(1e-12);
    let mut cols: Vec<[f64; 6]> = Vec::new();
    for s in supports {
        let n = s.normal;
        let (t1, t2) = plane_basis(&n);
        let r = (s.point - com) / lever;
        let edges: Vec<Vec3> = if s.friction > 0.0 {
            [t1, -t1, t2, -t2]
                .iter()
                .map(|t| n + t * s.friction)
                .collect()
        } else {
            vec![n]
        };
        for d in edges {
            let m = r.cross(&d);
            cols.push([d.x, d.y, d.z, m.x, m.y, m.z]);
        }
    }
    let a = DMatrix::from_fn(6, cols.len(), |i, j| cols[j][i]);
    let b = DVector::from_vec(vec![-down.x, -down.y, -down.z, 0.0, 0.0, 0.0]);
    let (_, residual) = nnls(&a, &b);
    residual <= BALANCED
}

#[cfg(test)]
mod tests {
    use super::*;

    fn floor(x: f64, y: f64, friction: f64) -> Support {
        Support {
            point: Vec3::new(x, y, 0.0),
            normal: Vec3::z(),
            friction,
        }
    }

    const DOWN: Vec3 = Vec3::new(0.0, 0.0, -1.0);

    #[test]
    fn a_frictionless_body_is_held_only_with_its_centre_over_the_support_polygon() {
        let square = [
            floor(-1.0, -1.0, 0.0),
            floor(1.0, -1.0, 0.0),
            floor(1.0, 1.0, 0.0),
            floor(-1.0, 1.0, 0.0),
        ];
        assert!(held(&square, &Vec3::new(0.3, -0.5, 1.0), &DOWN, 1.0));
        assert!(!held(&square, &Vec3::new(1.2, 0.0, 1.0), &DOWN, 1.0));
        // On an edge's line but not over it; on one point only directly above.
        assert!(!held(&square[..2], &Vec3::new(0.0, 0.0, 1.0), &DOWN, 1.0));
        assert!(held(&square[..1], &Vec3::new(-1.0, -1.0, 2.0), &DOWN, 1.0));
    }

    #[test]
    fn friction_does_not_hold_a_body_whose_centre_overhangs_a_level_support() {
        // Level supports: friction only acts sideways and cannot make a
        // torque about the support edge that balances an overhang.
        let edge = [floor(0.0, -1.0, 1.0), floor(0.0, 1.0, 1.0)];
        assert!(!held(&edge, &Vec3::new(0.2, 0.0, 0.5), &DOWN, 1.0));
        assert!(held(&edge, &Vec3::new(0.0, 0.3, 0.5), &DOWN, 1.0));
    }

    #[test]
    fn a_rod_leaning_on_a_wall_is_held_only_with_enough_friction() {
        // A rod from the floor at (0, 0, 0) to the wall at (1, 0, h): wall
        // normal −x, floor normal +z. With friction μ on both, the classic
        // ladder holds when tan(angle from vertical) ≤ 2μ/(1 − μ²) ... here
        // the centre is at (0.5, 0, h/2); test a steep and a shallow lean.
        let lean = |h: f64, mu: f64| {
            let s = [
                Support {
                    point: Vec3::zeros(),
                    normal: Vec3::z(),
                    friction: mu,
                },
                Support {
                    point: Vec3::new(1.0, 0.0, h),
                    normal: -Vec3::x(),
                    friction: mu,
                },
            ];
            held(&s, &Vec3::new(0.5, 0.0, 0.5 * h), &DOWN, h.max(1.0))
        };
        // Ladder with friction μ at both ends holds when (1/h) ≤ 2μ/(1 − μ²)
        // for the rod's horizontal run 1 and height h (μ < 1). The pyramid
        // is inscribed in the cone along these axes, so the bound is exact
        // in this plane.
        let mu: f64 = 0.5;
        let h_min = (1.0 - mu * mu) / (2.0 * mu);
        assert!(lean(h_min * 1.05, mu));
        assert!(!lean(h_min * 0.95, mu));
        assert!(!lean(10.0, 0.0), "a frictionless lean always slides");
    }

    #[test]
    fn a_body_touching_only_a_wall_falls() {
        let wall = [
            Support {
                point: Vec3::new(1.0, 0.0, 0.0),
                normal: -Vec3::x(),
                friction: 1.0,
            },
            Support {
                point: Vec3::new(1.0, 0.0, 1.0),
                normal: -Vec3::x(),
                friction: 1.0,
            },
        ];
        assert!(!held(&wall, &Vec3::new(0.5, 0.0, 0.5), &DOWN, 1.0));
        assert!(!held(&[], &Vec3::zeros(), &DOWN, 1.0));
    }
}
