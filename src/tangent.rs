//! Finite-difference Jacobians: the built-in check of the tangent
//! propagation and the baseline the benchmark compares against.
//!
//! Central differences use the step `h_i = ε^{1/3} max(|u_i|, 1)`; forward
//! differences `ε^{1/2} max(|u_i|, 1)`. A column is *comparable* only when
//! both perturbed runs keep the collision sequence (the motion's signature)
//! of the nominal run: across a signature change the motion is not
//! differentiable and a difference quotient means nothing.

use crate::controls::Controls;
use crate::math::{Vec3, log_so3};
use crate::scene::Scene;
use crate::sim::{BodyState, Side, SimError, SimOptions, Trajectory, simulate};
use nalgebra::{DMatrix, DVector};

/// The 12-vector `b − a` in tangent coordinates `(δx, δθ, δv, δω)`, with
/// `δθ = log(R_b R_aᵀ)` a world-frame rotation.
pub fn state_difference(a: &BodyState, b: &BodyState) -> DVector<f64> {
    let dth: Vec3 = log_so3(&(b.q * a.q.inverse()));
    let parts = [b.x - a.x, dth, b.v - a.v, b.w - a.w];
    DVector::from_iterator(12, parts.iter().flat_map(|v| v.iter().cloned()))
}

/// Difference scheme.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Scheme {
    Central,
    Forward,
}

impl Scheme {
    /// The step for a control of value `u`.
    pub fn step(self, u: f64) -> f64 {
        let base = match self {
            Scheme::Central => f64::EPSILON.cbrt(),
            Scheme::Forward => f64::EPSILON.sqrt(),
        };
        base * u.abs().max(1.0)
    }
}

/// Perturbed simulations for a finite-difference Jacobian.
pub struct FiniteDifference {
    pub scheme: Scheme,
    /// Step per column (negative for a one-sided difference taken below
    /// the control's value).
    pub steps: Vec<f64>,
    /// The nominal run (no tangents).
    pub nominal: Trajectory,
    /// `(plus, minus)` runs per column; `minus` is the nominal run for
    /// forward and one-sided differences.
    runs: Vec<(Trajectory, Option<Trajectory>)>,
    /// Whether both perturbed runs keep the nominal signature, per column.
    pub comparable: Vec<bool>,
    /// How each column's quotient was taken.
    pub columns: Vec<ColumnKind>,
}

/// How a column's difference quotient was taken.
#[derive(Debug, Clone, PartialEq)]
pub enum ColumnKind {
    /// As the scheme says.
    AsScheme,
    /// The simulator refused one perturbed run (a body pushed into what it
    /// rests on): a one-sided difference from the nominal run with the
    /// other, first order. The reason is the refused run's error.
    OneSided(String),
    /// Every perturbed run was refused: no quotient (the column is not
    /// comparable). The reason is the first run's error.
    Refused(String),
}

/// The signature of the events up to time `t` (inclusive).
fn prefix(tr: &Trajectory, t: f64) -> Vec<String> {
    let n = tr.events.iter().take_while(|e| e.t <= t).count();
    tr.signature().into_iter().take(n).collect()
}

fn perturbed(
    scene: &Scene,
    controls: &Controls,
    u: &DVector<f64>,
    col: usize,
    h: f64,
) -> Result<Trajectory, SimError> {
    let mut s = scene.clone();
    let mut v = u.clone();
    v[col] += h;
    // Write without reparameterising orientation: a difference across the
    // switch would compare two parameterisations.
    for (c, &i) in controls.free.iter().enumerate() {
        controls.set(&mut s, i, v[c]);
    }
    simulate(&s, controls, &SimOptions::without_tangents())
}

impl FiniteDifference {
    /// Run the `2m` (central) or `m` (forward) perturbed simulations. A
    /// perturbed run the simulator refuses makes its column one-sided or
    /// refused ([`ColumnKind`]), never the whole check fail.
    ///
    /// # Errors
    /// When the nominal run fails.
    pub fn new(
        scene: &Scene,
        controls: &Controls,
        scheme: Scheme,
    ) -> Result<FiniteDifference, SimError> {
        Self::with_steps(scene, controls, scheme, None)
    }

    /// As [`FiniteDifference::new`] with a given step for every column.
    pub fn with_steps(
        scene: &Scene,
        controls: &Controls,
        scheme: Scheme,
        step: Option<f64>,
    ) -> Result<FiniteDifference, SimError> {
        let u = controls.values(scene);
        let nominal = simulate(scene, controls, &SimOptions::without_tangents())?;
        let sig = nominal.signature();
        let mut runs = Vec::new();
        let mut steps = Vec::new();
        let mut comparable = Vec::new();
        let mut columns = Vec::new();
        for col in 0..controls.m() {
            let h = step.unwrap_or_else(|| scheme.step(u[col]));
            let plus = perturbed(scene, controls, &u, col, h);
            let minus = match scheme {
                Scheme::Central => Some(perturbed(scene, controls, &u, col, -h)),
                Scheme::Forward => None,
            };
            let (run, kind) = match (plus, minus) {
                (Ok(p), Some(Ok(m))) => ((h, p, Some(m)), ColumnKind::AsScheme),
                (Ok(p), None) => ((h, p, None), ColumnKind::AsScheme),
                (Ok(p), Some(Err(e))) => ((h, p, None), ColumnKind::OneSided(e.to_string())),
                (Err(e), Some(Ok(m))) => ((-h, m, None), ColumnKind::OneSided(e.to_string())),
                (Err(e), _) => (
                    (h, nominal.clone(), None),
                    ColumnKind::Refused(e.to_string()),
                ),
            };
            let (h, plus, minus) = run;
            comparable.push(
                !matches!(kind, ColumnKind::Refused(_))
                    && plus.signature() == sig
                    && minus.as_ref().is_none_or(|m| m.signature() == sig),
            );
            steps.push(h);
            runs.push((plus, minus));
            columns.push(kind);
        }
        Ok(FiniteDifference {
            scheme,
            steps,
            nominal,
            runs,
            comparable,
            columns,
        })
    }

    /// Per column: whether both perturbed runs keep the nominal collision
    /// sequence up to time `t` — what a state at `t` depends on (events
    /// later in the motion may differ without affecting it).
    pub fn comparable_until(&self, t: f64) -> Vec<bool> {
        // Margin: a perturbed event just after `t` may move to just before it.
        let reference = prefix(&self.nominal, t);
        self.runs
            .iter()
            .zip(&self.steps)
            .zip(&self.columns)
            .map(|(((p, m), h), kind)| {
                let window = t + 1e3 * h.abs();
                let same = |tr: &Trajectory| {
                    prefix(tr, t) == reference
                        && prefix(tr, window) == prefix(&self.nominal, window)
                };
                !matches!(kind, ColumnKind::Refused(_)) && same(p) && m.as_ref().is_none_or(same)
            })
            .collect()
    }

    /// The difference-quotient Jacobian of `body`'s state at time `t`.
    pub fn at(&self, body: usize, t: f64, side: Side) -> DMatrix<f64> {
        self.quotients(|tr| tr.state(body, t, side))
    }

    /// The difference-quotient Jacobian of `body`'s state just before or after
    /// its `k`-th event — taken at each run's own event time (a floating
    /// quantity), or `None` if a run lacks that event.
    pub fn at_event(&self, k: usize, body: usize, side: Side) -> Option<DMatrix<f64>> {
        let pick = |tr: &Trajectory| tr.events.get(k).map(|e| tr.state(body, e.t, side));
        if self
            .runs
            .iter()
            .any(|(p, m)| pick(p).is_none() || m.as_ref().is_some_and(|m| pick(m).is_none()))
        {
            return None;
        }
        pick(&self.nominal)?;
        Some(self.quotients(|tr| pick(tr).unwrap_or_else(|| tr.state(body, 0.0, side))))
    }

    /// The difference quotient of event `k`'s time.
    pub fn event_time(&self, k: usize) -> Option<DVector<f64>> {
        let t0 = self.nominal.events.get(k)?.t;
        let mut out = DVector::zeros(self.runs.len());
        for (c, (p, m)) in self.runs.iter().enumerate() {
            let tp = p.events.get(k)?.t;
            out[c] = match m {
                Some(m) => (tp - m.events.get(k)?.t) / (2.0 * self.steps[c]),
                None => (tp - t0) / self.steps[c],
            };
        }
        Some(out)
    }

    fn quotients(&self, state: impl Fn(&Trajectory) -> BodyState) -> DMatrix<f64> {
        let mut j = DMatrix::zeros(12, self.runs.len());
        let s0 = state(&self.nominal);
        for (c, (p, m)) in self.runs.iter().enumerate() {
            let sp = state(p);
            let col = match m {
                Some(m) => state_difference(&state(m), &sp) / (2.0 * self.steps[c]),
                None => state_difference(&s0, &sp) / self.steps[c],
            };
            j.set_column(c, &col);
        }
        j
    }
}

/// Largest relative disagreement between two Jacobians, column by column:
/// `|a_c − b_c| / max(|b_c|, floor)` over the columns where `mask` is true.
pub fn max_relative_error(a: &DMatrix<f64>, b: &DMatrix<f64>, mask: &[bool], floor: f64) -> f64 {
    let mut worst: f64 = 0.0;
    for c in 0..a.ncols() {
        if !mask.get(c).copied().unwrap_or(true) {
            continue;
        }
        let d = (a.column(c) - b.column(c)).norm();
        worst = worst.max(d / b.column(c).norm().max(floor));
    }
    worst
}

/// Tangent Jacobian of a body at a time, simulated with tangents.
pub fn tangent_jacobian(
    scene: &Scene,
    controls: &Controls,
    body: usize,
    t: f64,
    side: Side,
) -> Result<DMatrix<f64>, String> {
    let tr = simulate(scene, controls, &SimOptions::default()).map_err(|e| e.to_string())?;
    tr.jacobian(body, t, side).map_err(|e| e.to_string())
}
