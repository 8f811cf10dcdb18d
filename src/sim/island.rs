//! Islands: bodies resting on bodies (static equilibrium of several bodies
//! under Coulomb friction).
//!
//! An *island* is a set of bodies `i = 1 … n` (centres of mass `xᵢ`,
//! masses `mᵢ`) touching one another and static obstacles at contacts `k`:
//! a point `p_k`, a unit normal `n_k` pointing from party `b_k` into party
//! `a_k` (`b_k` an obstacle or another body of the island) and a friction
//! coefficient `μ_k`. Contact `k` pushes `a_k` with a force `f_k` and, by
//! Newton's third law, `b_k` with `−f_k`. The island is *held* when forces
//! inside the friction cones balance every body's weight:
//!
//! ```text
//!   Σ_{k: a_k = i} f_k − Σ_{k: b_k = i} f_k                     = −mᵢ g
//!   Σ_{k: a_k = i} (p_k − xᵢ) × f_k − Σ_{k: b_k = i} (p_k − xᵢ) × f_k = 0
//! ```
//!
//! six rows per body. As in [`super::statics`], each cone is replaced by its
//! inscribed pyramid (edges `n_k ± μ_k t₁`, `n_k ± μ_k t₂`; the normal alone
//! without friction), so "held" is conservative, and each force is a
//! non-negative combination of its edges: the island is held exactly when
//! the non-negative least-squares residual of this `6n × Σ edges` system
//! vanishes (relative to the weights). The minimiser gives the contact
//! forces. Force rows are in units of the heaviest weight and torque rows
//! are divided by a common lever (the island's largest reach), so the
//! residual compares like with like. A single body on obstacles is exactly
//! [`super::statics::held`].
//!
//! Where the forces are statically indeterminate (a box on four corners)
//! the forces returned are one balancing set (the minimiser NNLS reaches),
//! not a prediction of the true distribution; where they are determinate
//! (a ball in a hollow) they are the forces.

use crate::math::nnls::{self, NotConverged};
use crate::math::{Vec3, plane_basis};
use nalgebra::{DMatrix, DVector};

/// A body of an island.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IslandBody {
    /// Centre of mass, world, m.
    pub com: Vec3,
    /// Mass, kg.
    pub mass: f64,
}

/// A contact of an island: it pushes body `a` along `normal` (and body `b`,
/// when it is one, the opposite way).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct IslandContact {
    /// Index (in the island's bodies) of the body the normal points into.
    pub a: usize,
    /// The other party: a body of the island, or `None` for an obstacle.
    pub b: Option<usize>,
    /// Contact point, world, m.
    pub point: Vec3,
    /// Unit normal from `b` into `a`.
    pub normal: Vec3,
    /// Coulomb coefficient (0: frictionless).
    pub friction: f64,
}

/// Relative residual below which the weights count as balanced (as for a
/// single body, [`super::statics`]).
const BALANCED: f64 = 1e-9;

/// The pyramid edges of a contact's friction cone (the normal alone
/// without friction).
fn edges(c: &IslandContact) -> Vec<Vec3> {
    let n = c.normal;
    if c.friction <= 0.0 {
        return vec![n];
    }
    let (t1, t2) = plane_basis(&n);
    [t1, -t1, t2, -t2]
        .iter()
        .map(|t| n + t * c.friction)
        .collect()
}

/// The contact forces that hold the island under gravity `gravity` (m/s²),
/// one per contact (the force on its body `a`, N), or `None` when no forces
/// inside the friction pyramids balance every body (or the solve did not
/// converge: [`solve`] tells that apart). `lever` (m) scales the torque
/// rows to the force rows (the island's largest reach).
pub fn contact_forces(
    bodies: &[IslandBody],
    contacts: &[IslandContact],
    gravity: &Vec3,
    lever: f64,
) -> Option<Vec<Vec3>> {
    solve(bodies, contacts, gravity, lever).ok().flatten()
}

/// [`contact_forces`], with an active-set solve that ran out of iterations
/// as an error rather than as "not held".
///
/// # Errors
/// [`NotConverged`] when the non-negative least-squares iterations ran out.
pub fn solve(
    bodies: &[IslandBody],
    contacts: &[IslandContact],
    gravity: &Vec3,
    lever: f64,
) -> Result<Option<Vec<Vec3>>, NotConverged> {
    let n = bodies.len();
    let g = gravity.norm();
    if n == 0 || !g.is_finite() {
        return Ok(None);
    }
    if contacts
        .iter()
        .any(|c| c.a >= n || c.b.is_some_and(|b| b >= n))
    {
        return Ok(None);
    }
    let weight = bodies.iter().map(|b| b.mass).fold(0.0, f64::max) * g;
    if g == 0.0 || weight <= 0.0 {
        // Nothing to balance: held by no force at all.
        return Ok(Some(vec![Vec3::zeros(); contacts.len()]));
    }
    let lever = lever.max(1e-12);
    let edge_sets: Vec<Vec<Vec3>> = contacts.iter().map(edges).collect();
    let cols: usize = edge_sets.iter().map(Vec::len).sum();
    if cols == 0 {
        return Ok(None);
    }
    let mut a = DMatrix::zeros(6 * n, cols);
    let mut col = 0;
    for (c, set) in contacts.iter().zip(&edge_sets) {
        for d in set {
            let mut put = |body: usize, sign: f64| {
                let r = (c.point - bodies[body].com) / lever;
                let m = r.cross(d);
                for k in 0..3 {
                    a[(6 * body + k, col)] += sign * d[k];
                    a[(6 * body + 3 + k, col)] += sign * m[k];
                }
            };
            put(c.a, 1.0);
            if let Some(b) = c.b {
                put(b, -1.0);
            }
            col += 1;
        }
    }
    let mut rhs = DVector::zeros(6 * n);
    for (i, b) in bodies.iter().enumerate() {
        let w = -gravity * (b.mass / weight);
        for k in 0..3 {
            rhs[6 * i + k] = w[k];
        }
    }
    let (x, residual) = nnls::checked(&a, &rhs)?;
    if residual > BALANCED * rhs.norm().max(1.0) || !residual.is_finite() {
        return Ok(None);
    }
    let mut out = Vec::with_capacity(contacts.len());
    let mut col = 0;
    for set in &edge_sets {
        let f = set
            .iter()
            .enumerate()
            .fold(Vec3::zeros(), |f, (j, d)| f + d * x[col + j]);
        col += set.len();
        out.push(f * weight);
    }
    Ok(Some(out))
}

/// Whether the island is held (see [`contact_forces`]).
pub fn held(bodies: &[IslandBody], contacts: &[IslandContact], gravity: &Vec3, lever: f64) -> bool {
    contact_forces(bodies, contacts, gravity, lever).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;

    const G: Vec3 = Vec3::new(0.0, 0.0, -9.81);

    fn on_floor(a: usize, x: f64, y: f64, mu: f64) -> IslandContact {
        IslandContact {
            a,
            b: None,
            point: Vec3::new(x, y, 0.0),
            normal: Vec3::z(),
            friction: mu,
        }
    }

    /// A unit cube (mass 2) on a unit cube (mass 1) on the floor: the top
    /// contact carries the top weight, the floor both.
    #[test]
    fn a_box_on_a_box_is_held_and_the_floor_carries_both_weights() {
        let bodies = [
            IslandBody {
                com: Vec3::new(0.0, 0.0, 0.5),
                mass: 1.0,
            },
            IslandBody {
                com: Vec3::new(0.1, 0.0, 1.5),
                mass: 2.0,
            },
        ];
        let mut contacts = Vec::new();
        for (x, y) in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
            contacts.push(on_floor(0, x, y, 0.0));
            contacts.push(IslandContact {
                a: 1,
                b: Some(0),
                point: Vec3::new(x, y, 1.0),
                normal: Vec3::z(),
                friction: 0.0,
            });
        }
        let f = contact_forces(&bodies, &contacts, &G, 1.0).unwrap_or_default();
        assert_eq!(f.len(), 8);
        let on = |b: Option<usize>| -> Vec3 {
            contacts
                .iter()
                .zip(&f)
                .filter(|(c, _)| c.b == b)
                .map(|(_, f)| *f)
                .sum()
        };
        assert!((on(Some(0)).z - 2.0 * 9.81).abs() < 1e-9);
        assert!((on(None).z - 3.0 * 9.81).abs() < 1e-9);
        // The top box overhanging the lower one's edge is not held.
        let mut over = bodies;
        over[1].com.x = 0.7;
        assert!(!held(&over, &contacts, &G, 1.0));
    }

    #[test]
    fn an_unsupported_island_or_a_bad_index_is_not_held() {
        let b = [IslandBody {
            com: Vec3::zeros(),
            mass: 1.0,
        }];
        assert!(!held(&b, &[], &G, 1.0));
        let bad = IslandContact {
            b: Some(3),
            ..on_floor(0, 0.0, 0.0, 0.0)
        };
        assert!(!held(&b, &[bad], &G, 1.0));
        assert!(held(&b, &[on_floor(0, 0.0, 0.0, 0.0)], &G, 1.0));
    }
}
