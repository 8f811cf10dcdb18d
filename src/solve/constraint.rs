//! Constraints: where they are anchored, what they ask for, and their
//! residual rows and Jacobian rows on a trajectory.

use crate::math::{Vec3, log_so3, right_jacobian_inv, skew};
use crate::scene::Side;
use crate::scene::StateQuantity;
use crate::sim::{BodyState, TangentError, Trajectory};
use nalgebra::{DMatrix, DVector, Matrix3};

/// When a constraint is evaluated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Anchor {
    /// At a fixed time, s.
    Time(f64),
    /// At the body's `collision`-th collision (0-based), just before or
    /// after the impulse; the time floats with `u`.
    Event { collision: usize, side: Side },
}

/// What a constraint asks for.
#[derive(Debug, Clone, PartialEq)]
pub enum Kind {
    /// The listed quantities equal `target` (3 numbers each; orientation as
    /// an exponential-map vector). A nail (fixed time), a floating
    /// constraint (event), or the drag a nudge creates.
    State {
        quantities: Vec<StateQuantity>,
        target: Vec<f64>,
    },
    /// `|v_body| = |v_other|`.
    EqualSpeed { other: usize },
    /// `|ω| = value`.
    AngularSpeed { value: f64 },
    /// The body-frame `point` lies on the plane `normal · p = offset`.
    PointOnPlane {
        point: Vec3,
        normal: Vec3,
        offset: f64,
    },
    /// The body-frame unit vector `axis` points straight up (world +z,
    /// against the conventional gravity): "upright", whatever the turn
    /// about the vertical. Residual `ẑ − R axis` (3 rows, rank 2 at the
    /// solution, so the solver's rank-revealing solve drops the third);
    /// upside down it is 2, not 0.
    Upright { axis: Vec3 },
    /// The angular velocity lies along the world unit vector `axis` (the
    /// vertical, +z): the body may spin about it but not tumble, so a body
    /// standing upright does not tip over. Residual `−(ω − (ω·a) a)` (3
    /// rows, rank 2).
    Steady { axis: Vec3 },
    /// `|p − p_other| = value` between body-frame points.
    Distance {
        other: usize,
        point: Vec3,
        other_point: Vec3,
        value: f64,
    },
}

/// A constraint on one body.
#[derive(Debug, Clone, PartialEq)]
pub struct Constraint {
    pub body: usize,
    pub anchor: Anchor,
    pub kind: Kind,
    /// A temporary drag constraint (not saved, not listed).
    pub drag: bool,
}

/// Why a constraint cannot be evaluated on a trajectory.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ConstraintError {
    /// The body has fewer collisions than the floating constraint refers to.
    #[error("body has only {have} collisions; the constraint refers to collision {want}")]
    MissingEvent { have: usize, want: usize },
    /// The Jacobian is unavailable (grazing contact or a non-finite tangent).
    #[error(transparent)]
    Tangent(#[from] TangentError),
}

struct Eval {
    state: BodyState,
    /// Total derivative of the state (12 × m), `None` for residual-only evaluation.
    jac: Option<DMatrix<f64>>,
}

impl Constraint {
    /// Number of residual rows.
    pub fn rows(&self) -> usize {
        match &self.kind {
            Kind::State { quantities, .. } => 3 * quantities.len(),
            Kind::Upright { .. } | Kind::Steady { .. } => 3,
            _ => 1,
        }
    }

    /// A short kind label for panels and reports.
    /// The kind a saved file records (a drag saves as nothing; see
    /// [`Constraint::label`]).
    pub fn kind(&self) -> crate::scene::ConstraintKind {
        use crate::scene::ConstraintKind as K;
        match (&self.kind, self.anchor) {
            (Kind::State { .. }, Anchor::Time(_)) => K::Nail,
            (Kind::State { .. }, Anchor::Event { .. }) => K::Floating,
            (Kind::EqualSpeed { .. }, _) => K::EqualSpeed,
            (Kind::AngularSpeed { .. }, _) => K::AngularSpeed,
            (Kind::PointOnPlane { .. }, _) => K::PointOnPlane,
            (Kind::Upright { .. }, _) => K::Upright,
            (Kind::Steady { .. }, _) => K::Steady,
            (Kind::Distance { .. }, _) => K::Distance,
        }
    }

    pub fn label(&self) -> &'static str {
        match (&self.kind, self.anchor, self.drag) {
            (_, _, true) => "drag",
            (Kind::State { .. }, Anchor::Time(_), _) => "nail",
            (Kind::State { .. }, Anchor::Event { .. }, _) => "floating",
            (Kind::EqualSpeed { .. }, ..) => "equal_speed",
            (Kind::AngularSpeed { .. }, ..) => "angular_speed",
            (Kind::PointOnPlane { .. }, ..) => "point_on_plane",
            (Kind::Upright { .. }, ..) => "upright",
            (Kind::Steady { .. }, ..) => "steady",
            (Kind::Distance { .. }, ..) => "distance",
        }
    }

    /// The bodies whose states the constraint reads.
    pub fn bodies(&self) -> Vec<usize> {
        match &self.kind {
            Kind::EqualSpeed { other } | Kind::Distance { other, .. } => vec![self.body, *other],
            _ => vec![self.body],
        }
    }

    /// The time of the anchor on this trajectory.
    pub fn time(&self, traj: &Trajectory) -> Option<f64> {
        match self.anchor {
            Anchor::Time(t) => Some(t),
            Anchor::Event { collision, .. } => {
                traj.body_events(self.body).get(collision).map(|e| e.t)
            }
        }
    }

    fn eval(
        &self,
        traj: &Trajectory,
        body: usize,
        with_jac: bool,
    ) -> Result<Eval, ConstraintError> {
        match self.anchor {
            Anchor::Time(t) => {
                let state = traj.state(body, t, Side::Post);
                let jac = if with_jac {
                    Some(traj.jacobian(body, t, Side::Post)?)
                } else {
                    None
                };
                Ok(Eval { state, jac })
            }
            Anchor::Event { collision, side } => {
                // Events are anchored on the constrained body; a second body
                // in an expression is evaluated at the same (floating) time.
                let events = traj.body_events(self.body);
                let e = events.get(collision).ok_or(ConstraintError::MissingEvent {
                    have: events.len(),
                    want: collision,
                })?;
                let state = traj.state(body, e.t, side);
                let jac = if with_jac {
                    Some(traj.jacobian_at_event(body, e, side)?)
                } else {
                    None
                };
                Ok(Eval { state, jac })
            }
        }
    }

    /// Residual `r` (the change wanted, `target − current`) and, with
    /// `with_jac`, the rows `C` with `C δu ≈ r`.
    pub fn evaluate(
        &self,
        traj: &Trajectory,
        with_jac: bool,
    ) -> Result<(DVector<f64>, Option<DMatrix<f64>>), ConstraintError> {
        let m = traj.m;
        let e = self.eval(traj, self.body, with_jac)?;
        let s = &e.state;
        match &self.kind {
            Kind::State { quantities, target } => {
                let n = 3 * quantities.len();
                let mut r = DVector::zeros(n);
                let mut c = e.jac.as_ref().map(|_| DMatrix::zeros(n, m));
                for (k, q) in quantities.iter().enumerate() {
                    let goal = Vec3::new(target[3 * k], target[3 * k + 1], target[3 * k + 2]);
                    let (res, map) = match q {
                        StateQuantity::Position => (goal - s.x, None),
                        StateQuantity::Velocity => (goal - s.v, None),
                        StateQuantity::AngularVelocity => (goal - s.w, None),
                        StateQuantity::Orientation => {
                            // r = log(R_goal Rᵀ); δr ≈ −J_r(r)⁻¹ δθ, so C = J_r(r)⁻¹ J_θ.
                            let rg = crate::math::exp_so3(&goal);
                            let res = log_so3(&(rg * s.q.inverse()));
                            (res, Some(right_jacobian_inv(&res)))
                        }
                    };
                    r.rows_mut(3 * k, 3).copy_from(&res);
                    if let (Some(c), Some(j)) = (c.as_mut(), e.jac.as_ref()) {
                        let rows = j.rows(q.row(), 3).into_owned();
                        let rows = match map {
                            Some(mm) => dynamic(&(mm * rows)),
                            None => rows,
                        };
                        c.rows_mut(3 * k, 3).copy_from(&rows);
                    }
                }
                Ok((r, c))
            }
            Kind::EqualSpeed { other } => {
                let o = self.eval(traj, *other, with_jac)?;
                let (va, vb) = (s.v, o.state.v);
                let g = va.norm() - vb.norm();
                let c = match (e.jac, o.jac) {
                    (Some(ja), Some(jb)) => {
                        let ua = va.try_normalize(1e-12).unwrap_or_default();
                        let ub = vb.try_normalize(1e-12).unwrap_or_default();
                        Some(dynamic(
                            &(ua.transpose() * ja.rows(6, 3) - ub.transpose() * jb.rows(6, 3)),
                        ))
                    }
                    _ => None,
                };
                Ok((DVector::from_element(1, -g), c))
            }
            Kind::AngularSpeed { value } => {
                let g = s.w.norm() - value;
                let c = e.jac.map(|j| {
                    dynamic(
                        &(s.w.try_normalize(1e-12).unwrap_or_default().transpose() * j.rows(9, 3)),
                    )
                });
                Ok((DVector::from_element(1, -g), c))
            }
            Kind::PointOnPlane {
                point,
                normal,
                offset,
            } => {
                let n = normal.normalize();
                let arm = s.q * point;
                let g = n.dot(&(s.x + arm)) - offset;
                let c = e.jac.map(|j| {
                    dynamic(&(n.transpose() * (j.rows(0, 3) - skew(&arm) * j.rows(3, 3))))
                });
                Ok((DVector::from_element(1, -g), c))
            }
            Kind::Upright { axis } => {
                let a = s.q * axis.normalize();
                let r = Vec3::z() - a;
                // δa = δθ × a = −[a]× δθ.
                let c = e.jac.map(|j| dynamic(&(-skew(&a) * j.rows(3, 3))));
                Ok((DVector::from_column_slice(r.as_slice()), c))
            }
            Kind::Steady { axis } => {
                let a = axis.normalize();
                let across = Matrix3::identity() - a * a.transpose();
                let r = -(across * s.w);
                let c = e.jac.map(|j| dynamic(&(across * j.rows(9, 3))));
                Ok((DVector::from_column_slice(r.as_slice()), c))
            }
            Kind::Distance {
                other,
                point,
                other_point,
                value,
            } => {
                let o = self.eval(traj, *other, with_jac)?;
                let arm_a = s.q * point;
                let arm_b = o.state.q * other_point;
                let d = (s.x + arm_a) - (o.state.x + arm_b);
                let g = d.norm() - value;
                let c = match (e.jac, o.jac) {
                    (Some(ja), Some(jb)) => {
                        let u = d.try_normalize(1e-12).unwrap_or_default().transpose();
                        let pa = ja.rows(0, 3) - skew(&arm_a) * ja.rows(3, 3);
                        let pb = jb.rows(0, 3) - skew(&arm_b) * jb.rows(3, 3);
                        Some(dynamic(&(u * (pa - pb))))
                    }
                    _ => None,
                };
                Ok((DVector::from_element(1, -g), c))
            }
        }
    }

    /// The current values of the constrained quantities (for nails).
    pub fn current_values(state: &BodyState, quantities: &[StateQuantity]) -> Vec<f64> {
        let mut out = Vec::new();
        for q in quantities {
            let v = match q {
                StateQuantity::Position => state.x,
                StateQuantity::Orientation => log_so3(&state.q),
                StateQuantity::Velocity => state.v,
                StateQuantity::AngularVelocity => state.w,
            };
            out.extend(v.iter());
        }
        out
    }
}

/// Copy any matrix into a dynamically sized one.
fn dynamic<R: nalgebra::Dim, C: nalgebra::Dim, S: nalgebra::RawStorage<f64, R, C>>(
    m: &nalgebra::Matrix<f64, R, C, S>,
) -> DMatrix<f64> {
    DMatrix::from_iterator(m.nrows(), m.ncols(), m.iter().cloned())
}
