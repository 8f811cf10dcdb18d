//! One differential update: the KKT solve, successive step reduction and
//! sampling across a change of the collision sequence.

use super::constraint::{Constraint, ConstraintError};
use crate::controls::Controls;
use crate::math::Rng;
use crate::scene::Scene;
use crate::sim::{SimError, SimOptions, Trajectory, simulate};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// A condition worth telling the user about; the update still returns
/// the best step it found.
#[derive(Debug, Clone, PartialEq)]
pub enum Diagnostic {
    /// The constraints cannot all hold: the step is the least-squares one
    /// and this much of `C δu = r` remains.
    Conflicting { residual: f64 },
    /// A drag with no other constraint that the free controls can follow
    /// only in part (the editor's reading of `Conflicting` then).
    PartialDrag { residual: f64 },
    /// `C M⁻¹ Cᵀ` is ill-conditioned (condition number shown): directions
    /// below the rank threshold were dropped.
    IllConditioned { condition: f64 },
    /// The step crossed into another smooth component (new collision
    /// signature) and the sampled jump lowered the residual.
    Pop { from: usize, to: usize },
    /// No step, smooth or sampled, lowered the residual: the edit is blocked
    /// in that direction.
    Blocked,
    /// The Jacobian is unavailable (grazing contact); sampling was used.
    Grazing(String),
}

impl std::fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Diagnostic::Conflicting { residual } => write!(
                f,
                "conflicting constraints: least-squares step, residual {residual:.2e} remains"
            ),
            Diagnostic::PartialDrag { residual } => write!(
                f,
                "the free controls follow this drag only in part ({residual:.2e} short): free another block to follow it fully"
            ),
            Diagnostic::IllConditioned { condition } => write!(
                f,
                "ill-conditioned constraints (cond {condition:.1e}): damped step"
            ),
            Diagnostic::Pop { from, to } => {
                write!(f, "pop: collision sequence changed ({from} → {to} events)")
            }
            Diagnostic::Blocked => write!(
                f,
                "blocked: no nearby motion lowers the residual in this direction"
            ),
            Diagnostic::Grazing(m) => write!(f, "{m}"),
        }
    }
}

/// Why an update could not be computed. Nothing changes.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SolveError {
    #[error(transparent)]
    Sim(#[from] SimError),
    #[error(transparent)]
    Constraint(#[from] ConstraintError),
    /// Nothing to solve for.
    #[error(
        "no free controls: free a block of {body} (e.g. `:free {body} velocity`) so the edit has something to change"
    )]
    NoFreeControls { body: String },
    /// The constraint rows do not involve any free control.
    #[error(
        "the free controls cannot move this: free a block of {body} that acts before this time (position, orientation, velocity or angular_velocity)"
    )]
    Unreachable { body: String },
    /// A NaN or infinity appeared.
    #[error("the update produced a non-finite number; the edit was not applied")]
    NonFinite,
}

/// Candidates simulated together when sampling across a pop.
const SAMPLE_BATCH: usize = 8;

/// Options of one differential update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct UpdateOptions {
    /// First step fraction ε₀.
    pub step: f64,
    /// Halvings tried after ε₀.
    pub halvings: usize,
    /// Candidates sampled at a signature change.
    pub samples: usize,
    /// Relative eigenvalue threshold of the rank-revealing solve.
    pub rank_tol: f64,
    /// Seed of the sampler (deterministic results).
    pub seed: u64,
    /// Sampling may jump to another collision sequence (a pop). `false`
    /// keeps every step in the current one: after the user chose a
    /// sequence (an explored alternative), a nudge that cannot go further
    /// in it is blocked rather than popped out of it.
    pub pop: bool,
}

impl Default for UpdateOptions {
    fn default() -> Self {
        UpdateOptions {
            step: 1.0,
            halvings: 4,
            samples: 24,
            rank_tol: 1e-12,
            seed: 0x5eed,
            pop: true,
        }
    }
}

/// The outcome of one update.
#[derive(Debug, Clone)]
pub struct UpdateResult {
    /// The new control values (equal to the old ones when blocked).
    pub u: DVector<f64>,
    /// Weighted residual norm before and after.
    pub before: f64,
    pub after: f64,
    /// Step fraction accepted (0 when blocked).
    pub step: f64,
    /// Condition number of `C M⁻¹ Cᵀ`.
    pub condition: f64,
    pub diagnostics: Vec<Diagnostic>,
    /// The trajectory at the new `u` (with tangents when it came from the
    /// smooth step, without when it came from sampling), simulated up to
    /// just past the last constrained time only (its `duration` says how
    /// far) when that is before the end of the motion.
    pub trajectory: Option<Trajectory>,
}

/// Stack every constraint's residual (and rows).
pub(super) fn assemble(
    traj: &Trajectory,
    constraints: &[Constraint],
    with_jac: bool,
) -> Result<(DVector<f64>, Option<DMatrix<f64>>), ConstraintError> {
    let rows: usize = constraints.iter().map(Constraint::rows).sum();
    let mut r = DVector::zeros(rows);
    let mut c = with_jac.then(|| DMatrix::zeros(rows, traj.m));
    let mut at = 0;
    for k in constraints {
        let (rk, ck) = k.evaluate(traj, with_jac)?;
        r.rows_mut(at, rk.len()).copy_from(&rk);
        if let (Some(c), Some(ck)) = (c.as_mut(), ck) {
            c.rows_mut(at, rk.len()).copy_from(&ck);
        }
        at += rk.len();
    }
    Ok((r, c))
}

/// The residual norm of the constraints on a trajectory (`∞` if one cannot
/// be evaluated, e.g. a floating constraint whose collision vanished).
pub fn residual_norm(traj: &Trajectory, constraints: &[Constraint]) -> f64 {
    match assemble(traj, constraints, false) {
        Ok((r, _)) if r.iter().all(|v| v.is_finite()) => r.norm(),
        _ => f64::INFINITY,
    }
}

/// Solve `min ½ δuᵀMδu + dᵀδu s.t. Cδu = r` via the rank-revealing
/// eigendecomposition of `A = C M⁻¹ Cᵀ`. Returns `δu`, the condition number
/// of `A` (over all its directions, `∞` when singular), and the
/// unsatisfiable part of `r`.
pub fn kkt(
    c: &DMatrix<f64>,
    r: &DVector<f64>,
    scales: &DVector<f64>,
    d: &DVector<f64>,
    rank_tol: f64,
) -> (DVector<f64>, f64, f64) {
    let k = c.nrows();
    let minv = scales.map(|s| 1.0 / s);
    let cm = c * DMatrix::from_diagonal(&minv); // C M⁻¹
    let a = &cm * c.transpose();
    let b = r + &cm * d;
    // Rows are equilibrated (each scaled to unit norm in the M⁻¹ metric)
    // before the rank-revealing solve: otherwise a row whose derivatives
    // are 1e7 times larger (the spin after a chain of bounces, beside the
    // spin about the vertical) sets the rank threshold and the small but
    // well-determined row is dropped as rank-deficient. The minimum-norm
    // step of a consistent system does not change. Rows far below the
    // largest (1e-10 of it: round-off, such as the height of a ball at its
    // own bounce) are not blown up to unit size.
    let norms: Vec<f64> = (0..k).map(|i| a[(i, i)].max(0.0).sqrt()).collect();
    let largest = norms.iter().cloned().fold(0.0, f64::max);
    let w: Vec<f64> = norms
        .iter()
        .map(|&n| {
            let n = n.max(1e-10 * largest);
            if n.is_finite() && n > 0.0 {
                1.0 / n
            } else {
                1.0
            }
        })
        .collect();
    let condition = unscaled_condition(&a);
    let fa = faer::Mat::<f64>::from_fn(k, k, |i, j| w[i] * a[(i, j)] * w[j]);
    let b = DVector::from_iterator(k, (0..k).map(|i| w[i] * b[i]));
    let lambda = match fa.self_adjoint_eigen(faer::Side::Lower) {
        Ok(evd) => {
            let s = evd.S().column_vector();
            let u = evd.U();
            let max = (0..k).map(|i| s[i].abs()).fold(0.0, f64::max);
            let cut = max * rank_tol.max(f64::EPSILON * k as f64);
            let mut lambda = DVector::zeros(k);
            for i in 0..k {
                if s[i] > cut {
                    let coef: f64 = (0..k).map(|j| u[(j, i)] * b[j]).sum::<f64>() / s[i];
                    for j in 0..k {
                        lambda[j] += coef * u[(j, i)] * w[j];
                    }
                }
            }
            lambda
        }
        Err(_) => DVector::zeros(k),
    };
    let du = DVector::from_iterator(
        scales.len(),
        (c.transpose() * &lambda - d)
            .iter()
            .zip(minv.iter())
            .map(|(x, m)| x * m),
    );
    let unmet = (c * &du - r).norm();
    (du, condition, unmet)
}

/// The condition number of `A = C M⁻¹ Cᵀ` over all its directions, dropped
/// ones included: that is what tells the user the constraints are (nearly)
/// dependent or the horizon chaotic. Eigenvalues below round-off (or
/// slightly negative from it) count as ε·max, so a singular system reports
/// ~1/ε; `∞` when `A` is zero or the decomposition fails.
fn unscaled_condition(a: &DMatrix<f64>) -> f64 {
    let k = a.nrows();
    let fa = faer::Mat::<f64>::from_fn(k, k, |i, j| a[(i, j)]);
    match fa.self_adjoint_eigen(faer::Side::Lower) {
        Ok(evd) => {
            let s = evd.S().column_vector();
            let max = (0..k).map(|i| s[i].abs()).fold(0.0, f64::max);
            let min_all = (0..k)
                .map(|i| s[i])
                .fold(f64::INFINITY, f64::min)
                .max(max * f64::EPSILON);
            if max > 0.0 {
                max / min_all
            } else {
                f64::INFINITY
            }
        }
        Err(_) => f64::INFINITY,
    }
}

/// [`kkt`] within the controls' bounds: controls that the step would push
/// out of their range are held at the bound they would cross (their
/// columns leave the system and the rest of the residual is re-solved), a
/// few rounds of this active-set strategy. Every step `u0 + ε δu` with
/// `0 < ε ≤ 1` then stays in range.
fn bounded_kkt(
    c: &DMatrix<f64>,
    r: &DVector<f64>,
    scales: &DVector<f64>,
    d: &DVector<f64>,
    u0: &DVector<f64>,
    controls: &Controls,
    opts: &UpdateOptions,
) -> (DVector<f64>, f64, f64) {
    let (lo, hi) = controls.bounds();
    let m = u0.len();
    let mut held: Vec<Option<f64>> = vec![None; m];
    let (mut du, mut condition, mut unmet) = kkt(c, r, scales, d, opts.rank_tol);
    for _ in 0..m.min(8) {
        let out: Vec<usize> = (0..m)
            .filter(|&k| held[k].is_none() && !(lo[k]..=hi[k]).contains(&(u0[k] + du[k])))
            .collect();
        if out.is_empty() {
            break;
        }
        for k in out {
            held[k] = Some((u0[k] + du[k]).clamp(lo[k], hi[k]) - u0[k]);
        }
        let mut c2 = c.clone();
        let mut r2 = r.clone();
        let mut d2 = d.clone();
        for (k, h) in held.iter().enumerate() {
            if let Some(step) = h {
                r2 -= c.column(k) * *step;
                c2.column_mut(k).fill(0.0);
                d2[k] = 0.0;
            }
        }
        (du, condition, _) = kkt(&c2, &r2, scales, &d2, opts.rank_tol);
        for (k, h) in held.iter().enumerate() {
            if let Some(step) = h {
                du[k] = *step;
            }
        }
        unmet = (c * &du - r).norm();
    }
    (du, condition, unmet)
}

/// The signature of the events that can influence the constrained states:
/// each constrained body's events up to its latest constrained time (an
/// event that moves across that time appears in or leaves the list) and,
/// through every body–body event kept, the other body's earlier events,
/// transitively. A bounce of a body the constrained one never touched, or
/// one after its constrained time, is not a discontinuity of the edit.
fn causal_signature(tr: &Trajectory, constraints: &[Constraint]) -> Vec<String> {
    tr.signature()
        .into_iter()
        .zip(causal_events(tr, constraints))
        .filter_map(|(s, k)| k.then_some(s))
        .collect()
}

/// Which of `tr`'s events are in the causal past of the constrained
/// states (see [`causal_signature`]), one flag per event.
pub(crate) fn causal_events(tr: &Trajectory, constraints: &[Constraint]) -> Vec<bool> {
    let bodies = tr.tracks.len();
    let mut until = vec![f64::NEG_INFINITY; bodies];
    for c in constraints {
        if let Some(t) = c.time(tr) {
            for b in c.bodies() {
                if let Some(u) = until.get_mut(b) {
                    *u = u.max(t);
                }
            }
        }
    }
    let mut keep = vec![false; tr.events.len()];
    for (k, e) in tr.events.iter().enumerate().rev() {
        let other = match e.b {
            crate::sim::Party::Body(j) if j < bodies => Some(j),
            _ => None,
        };
        let reaches = |b: usize| until.get(b).is_some_and(|u| e.t <= *u);
        if reaches(e.a) || other.is_some_and(reaches) {
            keep[k] = true;
            for b in std::iter::once(e.a).chain(other) {
                if let Some(u) = until.get_mut(b) {
                    *u = u.max(e.t);
                }
            }
        }
    }
    keep
}

/// Simulate `u` up to `until` (the whole motion for `None`) and evaluate
/// the constraints there.
fn trial(
    scene: &Scene,
    controls: &Controls,
    u: &DVector<f64>,
    constraints: &[Constraint],
    tangent: bool,
    until: Option<f64>,
) -> Option<(f64, Trajectory)> {
    if !u.iter().all(|v| v.is_finite()) {
        return None;
    }
    let mut s = scene.clone();
    controls.write(&mut s, u);
    let tr = simulate(
        &s,
        controls,
        &SimOptions {
            tangent,
            until,
            ..SimOptions::default()
        },
    )
    .ok()?;
    let res = residual_norm(&tr, constraints);
    res.is_finite().then_some((res, tr))
}

/// One differential update of `scene`'s free controls towards satisfying
/// `constraints` (paper Eq. 15 with successive step reduction and sampling
/// across discontinuities). `traj` is the current motion with tangents.
pub fn update(
    scene: &Scene,
    controls: &Controls,
    traj: &Trajectory,
    constraints: &[Constraint],
    opts: &UpdateOptions,
) -> Result<UpdateResult, SolveError> {
    let u0 = controls.values(scene);
    let body_name = |c: &Constraint| {
        scene
            .bodies
            .get(c.body)
            .map(|b| b.name.clone())
            .unwrap_or_default()
    };
    if controls.m() == 0 {
        return Err(SolveError::NoFreeControls {
            body: constraints.first().map(body_name).unwrap_or_default(),
        });
    }
    let before = residual_norm(traj, constraints);
    let mut diagnostics = Vec::new();
    // Only the collisions in the causal past of the constrained states
    // shape the residual: later events, and events of bodies that never
    // touched a constrained body before its constrained time, may come and
    // go without a discontinuity in what the edit asks for.
    let last = constraints
        .iter()
        .filter_map(|c| c.time(traj))
        .fold(0.0, f64::max);
    // Trials stop a little past the last constrained time (a floating
    // constraint's collision may come later in a trial): later events
    // cannot change the residual.
    let horizon = last + 0.02 * scene.duration;
    let until = (horizon < scene.duration).then_some(horizon);
    let prefix = |tr: &Trajectory| causal_signature(tr, constraints);
    let signature = prefix(traj);
    // Desired values pull surface parameters back towards the geometric normal.
    let scales = controls.scales();
    let d = DVector::from_iterator(
        controls.m(),
        controls
            .free
            .iter()
            .enumerate()
            .map(|(col, &i)| match controls.entries[i].desired {
                Some(want) => -scales[col] * (want - u0[col]),
                None => 0.0,
            }),
    );
    let linearise = crate::profile::span(crate::profile::Part::Linearise);
    let step = match assemble(traj, constraints, true) {
        Ok((r, Some(c))) => {
            if c.iter().all(|v| *v == 0.0) && r.norm() > 0.0 {
                return Err(SolveError::Unreachable {
                    body: constraints
                        .iter()
                        .find(|c| c.drag)
                        .or(constraints.first())
                        .map(body_name)
                        .unwrap_or_default(),
                });
            }
            let (du, condition, unmet) = bounded_kkt(&c, &r, &scales, &d, &u0, controls, opts);
            if !du.iter().all(|v| v.is_finite()) {
                return Err(SolveError::NonFinite);
            }
            // Round-off leaves ~ε‖C‖‖δu‖ unmet; a real conflict leaves a fraction of ‖r‖.
            if unmet > 1e-6 * r.norm() + 1e3 * f64::EPSILON * c.norm() * du.norm() {
                diagnostics.push(Diagnostic::Conflicting { residual: unmet });
            }
            if condition > 1e10 {
                diagnostics.push(Diagnostic::IllConditioned { condition });
            }
            // The pull towards the desired values comes second to the
            // constraints (paper §4.1: "once all constraints are
            // satisfied"). Its part in the null space of `C` can be far
            // longer than the correction, and where the motion is chaotic
            // (a tumbling mug's bounces, whose normals turn its pose at a
            // later bounce hundreds of times over) the linear model does not
            // hold that far: the step with the pull was refused until cut to
            // an eighth, or taken whole for a fifth of the decrease it
            // promised, and a settle crept for hundreds of updates. So the
            // step with the pull must also deliver half the decrease the
            // linear model promises (an Armijo test), and each step fraction
            // is tried without the pull as well.
            let plain = d
                .iter()
                .any(|v| *v != 0.0)
                .then(|| {
                    let zero = DVector::zeros(d.len());
                    bounded_kkt(&c, &r, &scales, &zero, &u0, controls, opts).0
                })
                .filter(|p| p.iter().all(|v| v.is_finite()) && p.norm() > 0.0)
                .map(|p| {
                    let cdu = &c * &du;
                    (p, r, cdu)
                });
            Some((du, condition, plain))
        }
        Ok((_, None)) => None,
        Err(ConstraintError::Tangent(e)) => {
            diagnostics.push(Diagnostic::Grazing(e.to_string()));
            None
        }
        Err(e) => return Err(e.into()),
    };
    drop(linearise);
    let (du, condition, plain) =
        step.unwrap_or_else(|| (DVector::zeros(controls.m()), f64::NAN, None));
    // Successive step reduction within the current smooth component: at
    // each fraction the step, then (when it pulls towards desired values)
    // the same fraction of the step without the pull. The first step that
    // leaves the component centres the sampling.
    let mut first_crossing: Option<DVector<f64>> = None;
    let mut eps = opts.step;
    if du.norm() > 0.0 {
        for _ in 0..=opts.halvings {
            let pulled = plain.as_ref().map(|(_, r, cdu)| (r - cdu * eps).norm());
            let tries =
                std::iter::once((&du, pulled)).chain(plain.as_ref().map(|(p, ..)| (p, None)));
            for (dir, promised) in tries {
                let u = &u0 + dir * eps;
                // Step-reduction trials carry tangents: the accepted one is
                // the next update's starting point, so it is not simulated
                // twice.
                let tried = crate::profile::time(crate::profile::Part::Trials, || {
                    trial(scene, controls, &u, constraints, true, until)
                });
                if let Some((res, tr)) = tried {
                    if prefix(&tr) == signature {
                        let enough = promised.is_none_or(|p| before - res >= 0.5 * (before - p));
                        if res < before && enough {
                            return Ok(UpdateResult {
                                u,
                                before,
                                after: res,
                                step: eps,
                                condition,
                                diagnostics,
                                trajectory: Some(tr),
                            });
                        }
                    } else if first_crossing.is_none() {
                        first_crossing = Some(dir * eps);
                    }
                }
            }
            eps *= 0.5;
        }
    }
    // Otherwise (and when no direction is known) sample around the step
    // that left the component — the largest one — and jump only if that
    // beats staying put (docs/design.md §7).
    let centre = first_crossing.unwrap_or_else(|| du.clone() * opts.step);
    let spread: DVector<f64> = if centre.norm() > 0.0 {
        centre
            .map(|v| 0.5 * v.abs())
            .add_scalar(0.1 * centre.norm() / (controls.m() as f64).sqrt())
    } else {
        scales.map(|s| 1e-2 / s.sqrt())
    };
    let mut rng = Rng(opts.seed ^ (before.to_bits().rotate_left(17)));
    let candidates: Vec<DVector<f64>> = (0..opts.samples)
        .map(|i| {
            if i == 0 {
                centre.clone()
            } else {
                DVector::from_iterator(
                    centre.len(),
                    centre
                        .iter()
                        .zip(spread.iter())
                        .map(|(c, s)| c + s * rng.gauss()),
                )
            }
        })
        .collect();
    // Candidates stay within the controls' bounds.
    let (lo, hi) = controls.bounds();
    let candidates: Vec<DVector<f64>> = candidates
        .into_iter()
        .map(|dv| {
            DVector::from_iterator(
                dv.len(),
                (0..dv.len()).map(|k| (u0[k] + dv[k]).clamp(lo[k], hi[k]) - u0[k]),
            )
        })
        .collect();
    // In batches, in order, stopping after the first batch whose best
    // halves the residual: a pop then costs one batch's simulations (a
    // frame's worth on two cores) unless the jump is hard to find. The
    // batches do not depend on the number of threads, nor does the result.
    let sampling = crate::profile::span(crate::profile::Part::Sampling);
    let mut best: Option<(f64, DVector<f64>, Trajectory)> = None;
    for batch in candidates.chunks(SAMPLE_BATCH) {
        let found = batch
            .par_iter()
            .filter_map(|dv| {
                trial(scene, controls, &(&u0 + dv), constraints, false, until)
                    .filter(|(_, tr)| opts.pop || prefix(tr) == signature)
                    .map(|(res, tr)| (res, dv.clone(), tr))
            })
            .min_by(|a, b| a.0.total_cmp(&b.0));
        if let Some(f) = found
            && best.as_ref().is_none_or(|b| f.0 < b.0)
        {
            best = Some(f);
        }
        if best.as_ref().is_some_and(|b| b.0 <= 0.5 * before) {
            break;
        }
    }
    drop(sampling);
    match best {
        Some((res, dv, tr)) if res < before => {
            let (from, to) = (traj.events.len(), tr.events.len());
            if prefix(&tr) != signature {
                diagnostics.push(Diagnostic::Pop { from, to });
            }
            Ok(UpdateResult {
                u: &u0 + &dv,
                before,
                after: res,
                step: 0.0,
                condition,
                diagnostics,
                trajectory: Some(tr),
            })
        }
        _ => {
            diagnostics.push(Diagnostic::Blocked);
            Ok(UpdateResult {
                u: u0,
                before,
                after: before,
                step: 0.0,
                condition,
                diagnostics,
                trajectory: None,
            })
        }
    }
}

#[cfg(test)]
mod tests;
