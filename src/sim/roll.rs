//! A ball on a level plane with Coulomb friction: it slips, then rolls.
//!
//! A ball of radius `r`, mass `m` and isotropic moment of inertia `I`
//! (`2/5 m r²` for a uniform solid ball), centred on its centre of mass and
//! pressed into a half-space by gravity's normal part `g_n`, touches the
//! plane at `−r n`. Its contact point slips at `u = v + r n × ω` (in the
//! plane). Coulomb friction `f = −μ m g_n û` opposes the slip, so while it
//! slips
//!
//! ```text
//! v̇ = −a û,  ω̇ = b (n × û),  a = μ g_n,  b = r μ m g_n / I,
//! u̇ = −k û,  k = a + r b = μ g_n (1 + m r² / I),
//! ```
//!
//! and on a plane normal to gravity `û` stays constant: the slip dies at
//! `t* = |u₀| / k` (a solid ball thrown without spin: `t* = 2 v₀ / 7 μ g`,
//! leaving at `5 v₀ / 7`). From then on the ball rolls without slipping at
//! constant `v` and `ω` (`ω`'s in-plane part is `n × v / r`; its spin about
//! `n` is never touched by a point contact), with no rolling resistance.
//! The switch is an event of the run (`sim::run::roll`).
//!
//! The angular velocity is linear in time, `ω(s) = ω₀ + s b e` with
//! `e = n × û`. When `ω₀ ∥ e` (no side spin, the common case) the ball turns
//! about a fixed axis and `q(τ) = exp(∫ω) q₀` exactly; otherwise the
//! orientation (which never feeds back into the translation) is integrated
//! by fourth-order Magnus steps of at most [`TURN_STEP`] rad, which for an
//! angular velocity linear in time leave errors far below 1e-9 rad. The
//! tangents are closed form in the same quantities, including how `t*`
//! moves with the start state (the motion is C¹ in position and
//! orientation across `t*`; the velocities' derivatives jump there, which
//! the switch event's Jacobian takes from the rolling side).
//!
//! Not modelled this way (the ball slides frictionless as before, see
//! `sim::rest`): an inclined plane (the slip direction turns), drag, a ball
//! off its centre of mass and an anisotropic inertia.

use super::dynamics::BodyDynamics;
use super::state::BodyState;
use crate::geometry::PartKind;
use crate::math::{Mat3, Vec3, exp_so3, left_jacobian, skew};
use crate::scene::Scene;
use nalgebra::{DMatrix, SMatrix, SVector, UnitQuaternion};

/// Transition of a 12-row tangent block (rows `δx, δθ, δv, δω`).
pub(crate) type Mat12 = SMatrix<f64, 12, 12>;

/// The largest turn (rad) of one Magnus step when the ball's axis of
/// rotation moves (side spin).
pub const TURN_STEP: f64 = 0.02;

/// A ball's friction with the plane it slides on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Roll {
    /// Radius, m.
    pub radius: f64,
    /// Deceleration of the centre while slipping, `a = μ g_n`, m/s².
    pub decel: f64,
    /// Angular acceleration while slipping, `b = r μ m g_n / I`, rad/s².
    pub spin_accel: f64,
    /// The ball rolls without slipping from the segment's start.
    pub rolling: bool,
}

/// A rolling ball `τ` after its segment began: its state, the transition
/// of the tangent (`δs = phi δs₀`) and the state's derivative in `b`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct RollAt {
    pub state: BodyState,
    pub phi: Mat12,
    pub d_b: SVector<f64, 12>,
}

/// Relative slip below which a ball counts as rolling.
const ROLLING: f64 = 1e-9;

impl Roll {
    /// The friction of body `body` sliding on a plane with unit normal `n`
    /// (gravity's normal part `g_n > 0`, tangential part `g_t`, pair
    /// friction `mu`) from `post`, or `None` where this model does not
    /// apply (see the module notes).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn new(
        scene: &Scene,
        d: &BodyDynamics,
        body: usize,
        n: &Vec3,
        g_n: f64,
        g_t: &Vec3,
        mu: f64,
        post: &BodyState,
    ) -> Option<Roll> {
        let [part] = scene.bodies[body].geometry.parts.as_slice() else {
            return None;
        };
        let PartKind::Ball { radius } = part.kind else {
            return None;
        };
        let p = d.principal;
        let i = p.x;
        let iso = (p.x - p.y).abs() <= 1e-12 * i && (p.y - p.z).abs() <= 1e-12 * i;
        let centred = part.offset.translation.vector.norm() <= 1e-12 * radius;
        let level = g_t.norm() <= 1e-12 * g_n;
        if !(mu > 0.0 && g_n > 0.0 && radius > 0.0 && i > 0.0)
            || d.drag_k.is_some()
            || d.integrate
            || !(iso && centred && level)
        {
            return None;
        }
        let mut roll = Roll {
            radius,
            decel: mu * g_n,
            spin_accel: radius * mu * d.mass * g_n / i,
            rolling: false,
        };
        let scale = post.v.norm() + radius * post.w.norm();
        roll.rolling = roll.slip(n, post).norm() <= ROLLING * scale;
        (roll.decel.is_finite() && roll.spin_accel.is_finite()).then_some(roll)
    }

    /// The in-plane slip `u = P (v + r n × ω)` of the contact point.
    pub fn slip(&self, n: &Vec3, s: &BodyState) -> Vec3 {
        let u = s.v + n.cross(&s.w) * self.radius;
        u - n * n.dot(&u)
    }

    /// The rate `k` at which the slip speed falls, m/s².
    pub fn slip_decay(&self) -> f64 {
        self.decel + self.radius * self.spin_accel
    }

    /// Seconds from `s0` until the ball rolls (`None` once it rolls).
    pub fn switch_after(&self, n: &Vec3, s0: &BodyState) -> Option<f64> {
        (!self.rolling).then(|| self.slip(n, s0).norm() / self.slip_decay())
    }

    /// This friction once the ball rolls.
    pub fn rolled(&self) -> Roll {
        Roll {
            rolling: true,
            ..*self
        }
    }

    /// `F = (v, ω, a, α)` of the ball in state `s`.
    pub(crate) fn flow(&self, n: &Vec3, s: &BodyState) -> [Vec3; 4] {
        let u = self.slip(n, s);
        match u.try_normalize(0.0) {
            Some(uh) if !self.rolling => {
                [s.v, s.w, -uh * self.decel, n.cross(&uh) * self.spin_accel]
            }
            _ => [s.v, s.w, Vec3::zeros(), Vec3::zeros()],
        }
    }

    /// The motion `τ` seconds after the segment began from `s0` on the
    /// plane with normal `n`; with `at_switch`, the state just after the
    /// switch (`τ` is then ignored).
    pub(crate) fn at(&self, n: &Vec3, s0: &BodyState, tau: f64, at_switch: bool) -> RollAt {
        let id = Mat3::identity();
        let u0 = self.slip(n, s0);
        let speed = u0.norm();
        let Some(uh) = u0
            .try_normalize(0.0)
            .filter(|_| !self.rolling && speed > 0.0)
        else {
            return constant(s0, tau);
        };
        let (a, b, k, r) = (self.decel, self.spin_accel, self.slip_decay(), self.radius);
        let t_star = speed / k;
        let nx = skew(n);
        let e = n.cross(&uh);
        // δû = gv δv₀ + gw δω₀; δt* = tv·δv₀ + tw·δω₀ (rows).
        let p = id - n * n.transpose();
        let gv = (p - uh * uh.transpose()) / speed;
        let gw = gv * nx * r;
        let tv = uh.transpose() / k;
        let tw = uh.transpose() * nx * (r / k);
        let slipping = !at_switch && tau < t_star;
        let ts = if slipping { tau } else { t_star };
        let sigma = if slipping || at_switch {
            0.0
        } else {
            tau - t_star
        };
        let (turn, m0, m1) = turn(&s0.w, &(e * b), ts);
        let v1 = s0.v - uh * (a * ts);
        let w1 = s0.w + e * (b * ts);
        let x1 = s0.x + s0.v * ts - uh * (0.5 * a * ts * ts);
        let mut phi = Mat12::zeros();
        let mut d_b = SVector::<f64, 12>::zeros();
        // Orientation at `ts` with `ts` held fixed.
        let th_th = *turn.to_rotation_matrix().matrix();
        let th_v = m1 * nx * gv * b;
        let th_w = m0 + m1 * nx * gw * b;
        let th_b = m1 * e;
        if slipping {
            put(&mut phi, 0, 0, &id);
            put(&mut phi, 0, 6, &(id * ts - gv * (0.5 * a * ts * ts)));
            put(&mut phi, 0, 9, &(-gw * (0.5 * a * ts * ts)));
            put(&mut phi, 3, 3, &th_th);
            put(&mut phi, 3, 6, &th_v);
            put(&mut phi, 3, 9, &th_w);
            put(&mut phi, 6, 6, &(id - gv * (a * ts)));
            put(&mut phi, 6, 9, &(-gw * (a * ts)));
            put(&mut phi, 9, 6, &(nx * gv * (b * ts)));
            put(&mut phi, 9, 9, &(id + nx * gw * (b * ts)));
            d_b.fixed_rows_mut::<3>(3).copy_from(&th_b);
            d_b.fixed_rows_mut::<3>(9).copy_from(&(e * ts));
            let state = BodyState {
                x: x1,
                q: turn * s0.q,
                v: v1,
                w: w1,
            };
            return RollAt { state, phi, d_b };
        }
        // Rolling from t*: the velocities' derivatives include how t*
        // moves; position and orientation are C¹ across it.
        let vv = id - (uh * tv + gv * t_star) * a;
        let vw = -(uh * tw + gw * t_star) * a;
        let wv = (e * tv + nx * gv * t_star) * b;
        let ww = id + (e * tw + nx * gw * t_star) * b;
        let dt_db = -t_star * r / k;
        let v_b = -uh * (a * dt_db);
        let w_b = e * (t_star + b * dt_db);
        let spin = w1 * sigma;
        let rot = exp_so3(&spin);
        let e_m = *rot.to_rotation_matrix().matrix();
        let jl = left_jacobian(&spin) * sigma;
        put(&mut phi, 0, 0, &id);
        put(
            &mut phi,
            0,
            6,
            &(id * t_star - gv * (0.5 * a * t_star * t_star) + vv * sigma),
        );
        put(
            &mut phi,
            0,
            9,
            &(-gw * (0.5 * a * t_star * t_star) + vw * sigma),
        );
        put(&mut phi, 3, 3, &(e_m * th_th));
        put(&mut phi, 3, 6, &(e_m * th_v + jl * wv));
        put(&mut phi, 3, 9, &(e_m * th_w + jl * ww));
        put(&mut phi, 6, 6, &vv);
        put(&mut phi, 6, 9, &vw);
        put(&mut phi, 9, 6, &wv);
        put(&mut phi, 9, 9, &ww);
        d_b.fixed_rows_mut::<3>(0).copy_from(&(v_b * sigma));
        d_b.fixed_rows_mut::<3>(3)
            .copy_from(&(e_m * th_b + jl * w_b));
        d_b.fixed_rows_mut::<3>(6).copy_from(&v_b);
        d_b.fixed_rows_mut::<3>(9).copy_from(&w_b);
        let state = BodyState {
            x: x1 + v1 * sigma,
            q: rot * turn * s0.q,
            v: v1,
            w: w1,
        };
        RollAt { state, phi, d_b }
    }

    /// The Jacobian `τ` after a segment that began from `s0` with Jacobian
    /// `j0`; `mass` is the mass's control column and the mass (`b ∝ m`,
    /// with the inertia held).
    pub(crate) fn jacobian(
        &self,
        n: &Vec3,
        s0: &BodyState,
        tau: f64,
        j0: &DMatrix<f64>,
        mass: Option<(usize, f64)>,
    ) -> DMatrix<f64> {
        let at = self.at(n, s0, tau, false);
        self.carry(&at, j0, mass)
    }

    /// `phi j0`, plus the mass column's part through `b`.
    pub(crate) fn carry(
        &self,
        at: &RollAt,
        j0: &DMatrix<f64>,
        mass: Option<(usize, f64)>,
    ) -> DMatrix<f64> {
        let mut j = DMatrix::zeros(12, j0.ncols());
        for c in 0..j0.ncols() {
            let col = at.phi * j0.fixed_view::<12, 1>(0, c);
            j.fixed_view_mut::<12, 1>(0, c).copy_from(&col);
        }
        if let Some((c, m)) = mass.filter(|(c, _)| *c < j0.ncols()) {
            let add = at.d_b * (self.spin_accel / m);
            let mut col = j.fixed_view_mut::<12, 1>(0, c);
            col += add;
        }
        j
    }

    /// The derivative of the switch time (from the segment start) with
    /// respect to the start state (`δx, δθ, δv, δω`) and to `b`.
    pub(crate) fn switch_gradient(&self, n: &Vec3, s0: &BodyState) -> (SVector<f64, 12>, f64) {
        let mut g = SVector::<f64, 12>::zeros();
        let u0 = self.slip(n, s0);
        let Some(uh) = u0.try_normalize(0.0).filter(|_| !self.rolling) else {
            return (g, 0.0);
        };
        let k = self.slip_decay();
        g.fixed_rows_mut::<3>(6).copy_from(&(uh / k));
        g.fixed_rows_mut::<3>(9)
            .copy_from(&((skew(n).transpose() * uh) * (self.radius / k)));
        (g, -u0.norm() / k * self.radius / k)
    }
}

fn put(phi: &mut Mat12, r: usize, c: usize, m: &Mat3) {
    phi.fixed_view_mut::<3, 3>(r, c).copy_from(m);
}

/// Constant `v` and `ω` (rolling): `δθ = e δθ₀ + τ J_l δω₀`.
fn constant(s0: &BodyState, tau: f64) -> RollAt {
    let id = Mat3::identity();
    let wt = s0.w * tau;
    let rot = exp_so3(&wt);
    let mut phi = Mat12::zeros();
    put(&mut phi, 0, 0, &id);
    put(&mut phi, 0, 6, &(id * tau));
    put(&mut phi, 3, 3, rot.to_rotation_matrix().matrix());
    put(&mut phi, 3, 9, &(left_jacobian(&wt) * tau));
    put(&mut phi, 6, 6, &id);
    put(&mut phi, 9, 9, &id);
    RollAt {
        state: BodyState {
            x: s0.x + s0.v * tau,
            q: rot * s0.q,
            ..*s0
        },
        phi,
        d_b: SVector::zeros(),
    }
}

/// Gauss–Legendre nodes and weights on [0, 1], five points.
const GAUSS: [(f64, f64); 5] = [
    (0.046_910_077_030_668_004, 0.118_463_442_528_094_54),
    (0.230_765_344_947_158_45, 0.239_314_335_249_683_23),
    (0.5, 0.284_444_444_444_444_45),
    (0.769_234_655_052_841_5, 0.239_314_335_249_683_23),
    (0.953_089_922_969_332, 0.118_463_442_528_094_54),
];

/// The turn `U(τ)` of a body whose world angular velocity is
/// `ω(s) = w0 + s β`, and the tangent integrals `M₀ = ∫ U(τ) U(s)ᵀ ds`,
/// `M₁ = ∫ U(τ) U(s)ᵀ s ds` over `[0, τ]` (so that
/// `δθ(τ) = U δθ₀ + M₀ δω₀ + M₁ δβ`). Magnus steps of fourth order, exact
/// when `w0 ∥ β`; composite Gauss–Legendre quadrature.
fn turn(w0: &Vec3, beta: &Vec3, tau: f64) -> (UnitQuaternion<f64>, Mat3, Mat3) {
    if tau <= 0.0 {
        return (UnitQuaternion::identity(), Mat3::zeros(), Mat3::zeros());
    }
    let comm = w0.cross(beta);
    let fixed_axis = comm.norm() <= 1e-12 * w0.norm() * beta.norm();
    let angle = tau * (w0.norm() + beta.norm() * tau);
    let step = if fixed_axis { 0.5 } else { TURN_STEP };
    let panels = (angle / step).ceil().clamp(1.0, 1e6) as usize;
    let h = tau / panels as f64;
    // Magnus from time `s` over `dt`.
    let magnus = |s: f64, dt: f64| {
        let w = w0 + beta * s;
        let mut om = w * dt + beta * (0.5 * dt * dt);
        if !fixed_axis {
            om -= w.cross(beta) * (dt * dt * dt / 12.0);
        }
        exp_so3(&om)
    };
    let mut u = UnitQuaternion::identity();
    let (mut s0, mut s1) = (Mat3::zeros(), Mat3::zeros());
    for k in 0..panels {
        let s = k as f64 * h;
        for (x, wgt) in GAUSS {
            let ut = (magnus(s, x * h) * u).inverse();
            let m = *ut.to_rotation_matrix().matrix() * (wgt * h);
            s0 += m;
            s1 += m * (s + x * h);
        }
        u = magnus(s, h) * u;
    }
    let um = *u.to_rotation_matrix().matrix();
    (u, um * s0, um * s1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tangent integrals against central differences of the turn.
    #[test]
    fn the_turn_of_a_linearly_growing_spin_has_its_tangent() {
        let w0 = Vec3::new(1.0, -2.0, 3.0);
        let beta = Vec3::new(4.0, 1.0, -2.0);
        let tau = 0.7;
        let (u, m0, m1) = turn(&w0, &beta, tau);
        let h = 1e-6;
        for c in 0..3 {
            let d = Vec3::ith(c, h);
            let diff = |p: &UnitQuaternion<f64>, m: &UnitQuaternion<f64>| {
                crate::math::log_so3(&(p * m.inverse())) / (2.0 * h)
            };
            let dw = diff(
                &turn(&(w0 + d), &beta, tau).0,
                &turn(&(w0 - d), &beta, tau).0,
            );
            let db = diff(
                &turn(&w0, &(beta + d), tau).0,
                &turn(&w0, &(beta - d), tau).0,
            );
            assert!(
                (dw - m0.column(c)).norm() < 1e-7,
                "{dw} vs {}",
                m0.column(c)
            );
            assert!(
                (db - m1.column(c)).norm() < 1e-7,
                "{db} vs {}",
                m1.column(c)
            );
        }
        // Halving the step changes the turn by far less than 1e-9 rad.
        let fine = {
            let mut q = UnitQuaternion::identity();
            let n = 20_000;
            for k in 0..n {
                let (s, dt) = (tau * k as f64 / n as f64, tau / n as f64);
                let w = w0 + beta * s;
                let om = w * dt + beta * (0.5 * dt * dt) - w.cross(&beta) * (dt * dt * dt / 12.0);
                q = exp_so3(&om) * q;
            }
            q
        };
        assert!(crate::math::log_so3(&(u * fine.inverse())).norm() < 1e-10);
        // About a fixed axis the turn is the exponential of the angle.
        let axis = Vec3::new(0.0, 1.0, 0.0);
        let (u, _, _) = turn(&(axis * -3.0), &(axis * 40.0), tau);
        let exact = exp_so3(&(axis * (-3.0 * tau + 20.0 * tau * tau)));
        assert!(crate::math::log_so3(&(u * exact.inverse())).norm() < 1e-13);
    }
}
