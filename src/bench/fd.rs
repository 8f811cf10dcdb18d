//! Whole-scene Jacobians (all bodies stacked, `12n × m`) from tangents and
//! from finite differences, and their relative errors.
//!
//! The difference runs follow [`crate::tangent::FiniteDifference`] (same
//! steps, controls written without reparameterising the orientation, the
//! nominal run included in the cost), but a column counts as *comparable*
//! when its perturbed runs keep the nominal collision sequence up to the
//! evaluation time only: the state at `t` does not depend on later events,
//! and in a rattling scene almost every perturbation changes some late one.

use super::cases::signature_until;
use crate::controls::Controls;
use crate::scene::Scene;
use crate::sim::{Side, SimError, SimOptions, TangentError, Trajectory, simulate};
use crate::tangent::{Scheme, max_relative_error, state_difference};
use nalgebra::{DMatrix, DVector};

/// The Jacobian of every body's state at `t`, stacked (`12n × m`).
pub(crate) fn stacked(traj: &Trajectory, t: f64) -> Result<DMatrix<f64>, TangentError> {
    let n = traj.tracks.len();
    let mut j = DMatrix::zeros(12 * n, traj.m);
    for b in 0..n {
        j.rows_mut(12 * b, 12)
            .copy_from(&traj.jacobian(b, t, Side::Post)?);
    }
    Ok(j)
}

/// The perturbed runs of a finite-difference Jacobian.
pub(crate) struct FdRuns {
    nominal: Trajectory,
    /// `(step, plus, minus)` per column; no `minus` for forward differences.
    cols: Vec<(f64, Trajectory, Option<Trajectory>)>,
}

fn perturbed(
    scene: &Scene,
    controls: &Controls,
    u: &DVector<f64>,
    col: usize,
    h: f64,
) -> Result<Trajectory, SimError> {
    let mut s = scene.clone();
    for (c, &i) in controls.free.iter().enumerate() {
        controls.set(&mut s, i, if c == col { u[c] + h } else { u[c] });
    }
    simulate(&s, controls, &SimOptions::without_tangents())
}

impl FdRuns {
    /// The nominal run and `m` (forward) or `2m` (central) perturbed runs.
    pub(crate) fn new(
        scene: &Scene,
        controls: &Controls,
        scheme: Scheme,
    ) -> Result<FdRuns, SimError> {
        let u = controls.values(scene);
        let nominal = simulate(scene, controls, &SimOptions::without_tangents())?;
        let mut cols = Vec::with_capacity(controls.m());
        for col in 0..controls.m() {
            let h = scheme.step(u[col]);
            let plus = perturbed(scene, controls, &u, col, h)?;
            let minus = match scheme {
                Scheme::Central => Some(perturbed(scene, controls, &u, col, -h)?),
                Scheme::Forward => None,
            };
            cols.push((h, plus, minus));
        }
        Ok(FdRuns { nominal, cols })
    }

    /// Number of simulations run.
    pub(crate) fn simulations(&self) -> usize {
        1 + self
            .cols
            .iter()
            .map(|c| 1 + usize::from(c.2.is_some()))
            .sum::<usize>()
    }

    /// The difference-quotient Jacobian at `t` (stacked) and, per column,
    /// whether its runs keep the nominal events up to `t`.
    pub(crate) fn jacobian(&self, t: f64) -> (DMatrix<f64>, Vec<bool>) {
        let n = self.nominal.tracks.len();
        let sig = signature_until(&self.nominal, t);
        let mut j = DMatrix::zeros(12 * n, self.cols.len());
        let mut comparable = Vec::with_capacity(self.cols.len());
        for (c, (h, plus, minus)) in self.cols.iter().enumerate() {
            for b in 0..n {
                let sp = plus.state(b, t, Side::Post);
                let col = match minus {
                    Some(m) => state_difference(&m.state(b, t, Side::Post), &sp) / (2.0 * h),
                    None => state_difference(&self.nominal.state(b, t, Side::Post), &sp) / *h,
                };
                j.view_mut((12 * b, c), (12, 1)).copy_from(&col);
            }
            comparable.push(
                signature_until(plus, t) == sig
                    && minus.as_ref().is_none_or(|m| signature_until(m, t) == sig),
            );
        }
        (j, comparable)
    }
}

/// Largest column-wise relative error of `a` against `b` over the masked
/// columns (a column's norm is floored at 1e-8 of `b`'s largest, so a
/// control that barely acts does not divide by zero). `None` when no
/// column is compared or a number is not finite.
pub(crate) fn relative_error(a: &DMatrix<f64>, b: &DMatrix<f64>, mask: &[bool]) -> Option<f64> {
    if a.shape() != b.shape() || !mask.iter().any(|m| *m) {
        return None;
    }
    let scale = (0..b.ncols())
        .map(|c| b.column(c).norm())
        .fold(0.0, f64::max);
    let e = max_relative_error(a, b, mask, (1e-8 * scale).max(f64::MIN_POSITIVE));
    e.is_finite().then_some(e)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;
    use crate::scene::Block;
    use crate::testkit;

    /// A ball thrown in gravity: every scheme agrees with the tangents, and
    /// the columns stay comparable.
    #[test]
    fn differences_match_tangents_in_free_flight() {
        let mut s = testkit::scene(1.0);
        s.effects.collisions = false;
        let mut b = testkit::body(
            "ball",
            crate::geometry::Geometry::sphere(0.1).unwrap_or_else(|e| panic!("{e}")),
            Vec3::new(0.0, 0.0, 1.0),
        );
        b.velocity = Vec3::new(1.0, 0.0, 2.0);
        b.free = vec![Block::Position, Block::Velocity];
        s.bodies.push(b);
        let controls = Controls::new(&s);
        let tr = simulate(&s, &controls, &SimOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        let jt = stacked(&tr, 1.0).unwrap_or_else(|e| panic!("{e}"));
        for scheme in [Scheme::Central, Scheme::Forward] {
            let fd = FdRuns::new(&s, &controls, scheme).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(
                fd.simulations(),
                1 + if scheme == Scheme::Central { 12 } else { 6 }
            );
            let (j, ok) = fd.jacobian(1.0);
            assert!(ok.iter().all(|c| *c));
            let e = relative_error(&j, &jt, &ok).unwrap_or(f64::INFINITY);
            assert!(e < 1e-6, "{scheme:?}: {e}");
        }
        assert_eq!(relative_error(&jt, &jt, &[false; 6]), None);
    }
}
