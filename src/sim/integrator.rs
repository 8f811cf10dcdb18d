//! Integration of the rotation of non-isotropic bodies on SO(3), with the
//! variational equation integrated alongside by the same stages.
//!
//! The angular velocity `w` is integrated in the body frame (Euler's
//! equations are autonomous in `w`); the orientation is advanced by the
//! Munthe-Kaas method: within a step `R(t) = R₀ exp([θ(t)]×)` with
//! `θ̇ = J_r⁻¹(θ) w`, which is exact for constant `w`. The tangent
//! `Y = ∂(η, δw)/∂(η₀, δw₀, δI)` (6×9, body-frame right perturbations)
//! obeys `η̇ = −[w]× η + δw`, `δẇ = Df(w) δw + ∂f/∂I δI`.

use super::dynamics::BodyDynamics;
use crate::math::{Mat3, Vec3, exp_so3, right_jacobian_inv_mul, skew};
use nalgebra::UnitQuaternion;

/// Size of the integrated vector: `w` (3), `θ` (3), `Y` (6×9).
pub const Z_LEN: usize = 60;
/// Size with the transition block of `Y` only (its first 6 columns).
pub const Z_TRANSITION: usize = 42;
/// Size without the tangent.
pub const Z_STATE: usize = 6;

/// Which columns of the tangent `Y` a rotation integrates: none (no free
/// control reaches the rotation), the 6 of the state transition, or those
/// and the 3 of the principal inertia (only when the inertia is free: its
/// columns are a third of the variational work).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Columns {
    /// The state only.
    None,
    /// `∂(η, δw)/∂(η₀, δw₀)`.
    Transition,
    /// The transition and `∂(η, δw)/∂I`.
    WithInertia,
}

impl Columns {
    /// Length of the integrated vector.
    pub fn vector_len(self) -> usize {
        match self {
            Columns::None => Z_STATE,
            Columns::Transition => Z_TRANSITION,
            Columns::WithInertia => Z_LEN,
        }
    }
}

/// Euler's equations for torque-free motion: `ẇ = −I⁻¹ (w × I w)` (body frame).
pub fn euler_rhs(inertia: &Mat3, inertia_inv: &Mat3, w: &Vec3) -> Vec3 {
    -(inertia_inv * w.cross(&(inertia * w)))
}

fn vec3(z: &[f64], at: usize) -> Vec3 {
    Vec3::new(z[at], z[at + 1], z[at + 2])
}

/// `θ̇ = J_r⁻¹(θ) w`: the only rows of [`rhs`] that depend on `θ`.
fn theta_rate(theta: &Vec3, w: &Vec3) -> Vec3 {
    right_jacobian_inv_mul(theta, w)
}

/// Right-hand side of the integrated system; `z` has one of the lengths of
/// [`Columns`].
#[inline(always)]
pub fn rhs(d: &BodyDynamics, z: &[f64], dz: &mut [f64]) {
    let w = vec3(z, 0);
    let theta = vec3(z, 3);
    let iw = d.inertia * w;
    let f = -(d.inertia_inv * w.cross(&iw));
    dz[0..3].copy_from_slice(f.as_slice());
    dz[3..6].copy_from_slice(theta_rate(&theta, &w).as_slice());
    if z.len() < Z_TRANSITION {
        return;
    }
    // Df(w) δw = −I⁻¹ (δw × I w + w × I δw) = −I⁻¹ ([w]× I − [I w]×) δw.
    let df = -(d.inertia_inv * (skew(&w) * d.inertia - skew(&iw)));
    let sw = skew(&w);
    // Y is 6×9 column-major at z[6..]: column c occupies z[6 + 6c .. 6 + 6c + 6].
    for c in 0..(z.len() - Z_STATE) / 6 {
        let base = 6 + 6 * c;
        let eta = vec3(z, base);
        let dw = vec3(z, base + 3);
        let deta = -(sw * eta) + dw;
        let mut ddw = df * dw;
        if c >= 6 {
            // ∂f/∂p_k = −I⁻¹ (E_k f + w × E_k w), E_k = a_k a_kᵀ (principal axis a_k).
            let a = d.axes.column(c - 6).into_owned();
            let ek_f = a * a.dot(&f);
            let ek_w = a * a.dot(&w);
            ddw -= d.inertia_inv * (ek_f + w.cross(&ek_w));
        }
        dz[base..base + 3].copy_from_slice(deta.as_slice());
        dz[base + 3..base + 6].copy_from_slice(ddw.as_slice());
    }
}

/// Initial integrated vector for body-frame angular velocity `w`.
pub fn initial(w: &Vec3, columns: Columns) -> Vec<f64> {
    let mut z = vec![0.0; columns.vector_len()];
    z[0..3].copy_from_slice(w.as_slice());
    if columns != Columns::None {
        for i in 0..6 {
            z[6 + 6 * i + i] = 1.0;
        }
    }
    z
}

/// The orientation at the end of a step from `q0` with local rotation `θ`.
pub fn advance(q0: &UnitQuaternion<f64>, z: &[f64]) -> UnitQuaternion<f64> {
    let q = q0 * exp_so3(&vec3(z, 3));
    UnitQuaternion::new_normalize(q.into_inner())
}

/// Butcher tableau of an explicit Runge–Kutta method.
struct Tableau {
    c: &'static [f64],
    a: &'static [&'static [f64]],
    b: &'static [f64],
    /// `b − b̂` for the embedded error estimate (empty for RK4).
    e: &'static [f64],
}

const RK4: Tableau = Tableau {
    c: &[0.0, 0.5, 0.5, 1.0],
    a: &[&[], &[0.5], &[0.0, 0.5], &[0.0, 0.0, 1.0]],
    b: &[1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0],
    e: &[],
};

const DOPRI5: Tableau = Tableau {
    c: &[0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0],
    a: &[
        &[],
        &[0.2],
        &[3.0 / 40.0, 9.0 / 40.0],
        &[44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0],
        &[
            19372.0 / 6561.0,
            -25360.0 / 2187.0,
            64448.0 / 6561.0,
            -212.0 / 729.0,
        ],
        &[
            9017.0 / 3168.0,
            -355.0 / 33.0,
            46732.0 / 5247.0,
            49.0 / 176.0,
            -5103.0 / 18656.0,
        ],
        &[
            35.0 / 384.0,
            0.0,
            500.0 / 1113.0,
            125.0 / 192.0,
            -2187.0 / 6784.0,
            11.0 / 84.0,
        ],
    ],
    b: &[
        35.0 / 384.0,
        0.0,
        500.0 / 1113.0,
        125.0 / 192.0,
        -2187.0 / 6784.0,
        11.0 / 84.0,
        0.0,
    ],
    e: &[
        71.0 / 57600.0,
        0.0,
        -71.0 / 16695.0,
        71.0 / 1920.0,
        -17253.0 / 339200.0,
        22.0 / 525.0,
        -1.0 / 40.0,
    ],
};

/// Shampine's dense-output coefficients for Dormand–Prince 5(4).
const DOPRI_D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

/// One step of an explicit RK method from `z0` (whose `θ` part is zero):
/// the end value into `z1` and the stage derivatives into `k`, stage-major
/// (stage `i` at `[i·n, (i+1)·n)`, `n = z0.len()`). The caller owns both
/// buffers, so a step allocates nothing here. `first`, when given, is
/// `f(z0)` (see [`first_stage`]) and is not evaluated again.
fn rk_step(
    tab: &Tableau,
    d: &BodyDynamics,
    z0: &[f64],
    first: Option<&[f64]>,
    h: f64,
    evals: &mut u64,
    out: (&mut [f64], &mut [f64]),
) {
    // One instance per length of `Columns::vector_len`, so the loops over
    // the vector have a constant trip count (the state alone, the common
    // case when exploring, is 6 long).
    match z0.len() {
        Z_STATE => rk_step_n::<Z_STATE>(tab, d, z0, first, h, evals, out),
        Z_TRANSITION => rk_step_n::<Z_TRANSITION>(tab, d, z0, first, h, evals, out),
        _ => rk_step_n::<Z_LEN>(tab, d, z0, first, h, evals, out),
    }
}

/// [`rk_step`] for a vector of length `N`.
#[inline(always)]
fn rk_step_n<const N: usize>(
    tab: &Tableau,
    d: &BodyDynamics,
    z0: &[f64],
    first: Option<&[f64]>,
    h: f64,
    evals: &mut u64,
    (z1, k): (&mut [f64], &mut [f64]),
) {
    let n = N;
    let z0 = &z0[..N];
    let s = tab.c.len();
    let mut stage = [0.0; N];
    let zi = &mut stage[..];
    let start = match first {
        Some(f0) => {
            k[..n].copy_from_slice(f0);
            1
        }
        None => 0,
    };
    for i in start..s {
        zi.copy_from_slice(z0);
        let (done, rest) = k.split_at_mut(i * n);
        for (j, aij) in tab.a[i].iter().enumerate() {
            if *aij != 0.0 {
                for (zv, kv) in zi.iter_mut().zip(&done[j * n..(j + 1) * n]) {
                    *zv += h * aij * kv;
                }
            }
        }
        rhs(d, zi, &mut rest[..n]);
        *evals += 1;
    }
    z1.copy_from_slice(z0);
    for (i, bi) in tab.b.iter().enumerate() {
        if *bi != 0.0 {
            for (zv, kv) in z1.iter_mut().zip(&k[i * n..(i + 1) * n]) {
                *zv += h * bi * kv;
            }
        }
    }
}

/// An RK4 step's end value from `z0` (stages on the stack).
fn rk4_end(d: &BodyDynamics, z0: &[f64], h: f64, evals: &mut u64, z1: &mut [f64]) {
    let n = z0.len();
    let mut k = [0.0; 4 * Z_LEN];
    rk_step(&RK4, d, z0, None, h, evals, (z1, &mut k[..4 * n]));
}

/// A completed integration step, kept so the state can be queried anywhere inside it.
#[derive(Debug, Clone)]
pub struct Step {
    /// Start time, s.
    pub t0: f64,
    /// Step length, s.
    pub h: f64,
    /// Orientation at the start.
    pub q0: UnitQuaternion<f64>,
    /// Length `n` of the integrated vector.
    n: usize,
    /// The integrated vector at the start (its `θ` part is zero) and at
    /// the end, then (Dormand–Prince only, for dense output) the stage
    /// derivatives, stage-major: one allocation per step.
    data: Vec<f64>,
    /// Whether the step used the adaptive pair.
    pub adaptive: bool,
}

impl Step {
    /// How many numbers the step stores.
    pub fn stored_len(&self) -> usize {
        self.data.len()
    }
}

/// Take one RK4 step.
pub fn step_rk4(
    d: &BodyDynamics,
    t0: f64,
    q0: UnitQuaternion<f64>,
    z0: &[f64],
    h: f64,
    evals: &mut u64,
) -> Step {
    let n = z0.len();
    let mut data = vec![0.0; 2 * n];
    data[..n].copy_from_slice(z0);
    let (z0, z1) = data.split_at_mut(n);
    rk4_end(d, z0, h, evals, z1);
    Step {
        t0,
        h,
        q0,
        n,
        data,
        adaptive: false,
    }
}

/// Torque-free rotation by `steps` fixed RK4 steps of `h` from orientation
/// `q` and body-frame angular velocity `w`, exactly as the simulator takes
/// them (step, Munthe-Kaas update and renormalisation of the quaternion,
/// local rotation reset), without storing the steps: for long-run checks
/// and benchmarks. `visit` sees the state after every step.
pub fn free_rotation(
    d: &BodyDynamics,
    mut q: UnitQuaternion<f64>,
    w: &Vec3,
    h: f64,
    steps: usize,
    mut visit: impl FnMut(usize, &UnitQuaternion<f64>, &Vec3),
) -> (UnitQuaternion<f64>, Vec3) {
    let mut z = initial(w, Columns::None);
    let mut evals = 0;
    for k in 0..steps {
        let step = step_rk4(d, k as f64 * h, q, &z, h, &mut evals);
        q = step.end_into(&mut z);
        visit(k, &q, &body_rate(&z));
    }
    (q, body_rate(&z))
}

/// The tangent's error tolerance relative to the state's. A tangent
/// accurate to `100 · tol` (1e-7 at the default 1e-9) is far more than the
/// solver's steps need (each is checked against a real simulation), and
/// costs half the extra steps of holding it to `tol` (`nudge bench`: the
/// price of the tangents drops from about 3.5× to 2× a plain simulation).
pub const TANGENT_TOL_FACTOR: f64 = 100.0;

/// The first stage of a step from `z0`: `f(z0)`. An adaptive step that is
/// retried shorter after a rejection starts from the same `z0` and needs it
/// once; after an accepted Dormand–Prince step, [`Step::end_derivative`]
/// gives it without an evaluation.
pub fn first_stage(d: &BodyDynamics, z0: &[f64], evals: &mut u64) -> Vec<f64> {
    let mut f0 = vec![0.0; z0.len()];
    rhs(d, z0, &mut f0);
    *evals += 1;
    f0
}

/// Try one Dormand–Prince step; returns the step and its scaled error norm
/// (accept when ≤ 1). Error control covers the state (`w`, `θ`) and, when
/// it is integrated, the tangent `Y`: the larger of the two RMS norms, each
/// entry scaled by `tol · (1 + |entry|)` (as CVODES does with sensitivity
/// error control on; the tangent's `tol` is [`TANGENT_TOL_FACTOR`] times
/// the state's). The state alone would not do: for a steady spin about a
/// principal axis `w` is constant, so the state's error estimate is zero
/// and the step grows to the largest allowed while the perturbations about
/// that spin (the variational equation) still oscillate or grow.
///
/// `f0` is `f(z0)` ([`first_stage`] or [`Step::end_derivative`]).
#[allow(clippy::too_many_arguments)]
pub fn step_dopri(
    d: &BodyDynamics,
    t0: f64,
    q0: UnitQuaternion<f64>,
    z0: &[f64],
    f0: &[f64],
    h: f64,
    tol: f64,
    evals: &mut u64,
) -> (Step, f64) {
    let n = z0.len();
    let s = DOPRI5.c.len();
    // `z0`; `z1`, which the step starts from `z0`; the first stage, `f0`;
    // the other stages, zeroed until the step writes them.
    let mut data = Vec::with_capacity((2 + s) * n);
    data.extend_from_slice(z0);
    data.extend_from_slice(z0);
    data.extend_from_slice(f0);
    data.resize((2 + s) * n, 0.0);
    let (ends, k) = data.split_at_mut(2 * n);
    let (z0, z1) = ends.split_at_mut(n);
    rk_step(&DOPRI5, d, z0, Some(f0), h, evals, (z1, k));
    // The error estimate `Σ_j e_j k_j` (times h below), one stage at a time.
    let mut err = [0.0; Z_LEN];
    let err = &mut err[..n];
    for (ej, kj) in DOPRI5.e.iter().zip(k.chunks_exact(n)) {
        if *ej != 0.0 {
            for (ev, kv) in err.iter_mut().zip(kj) {
                *ev += ej * kv;
            }
        }
    }
    let scaled_rms = |range: std::ops::Range<usize>, tol: f64| {
        let len = range.len();
        let mut sum = 0.0;
        for i in range {
            let e = err[i] * h;
            let sc = tol + tol * z0[i].abs().max(z1[i].abs());
            sum += (e / sc) * (e / sc);
        }
        (sum / len as f64).sqrt()
    };
    let mut norm = scaled_rms(0..Z_STATE, tol);
    if n > Z_STATE {
        norm = norm.max(scaled_rms(Z_STATE..n, tol * TANGENT_TOL_FACTOR));
    }
    (
        Step {
            t0,
            h,
            q0,
            n,
            data,
            adaptive: true,
        },
        norm,
    )
}

impl Step {
    /// The integrated vector at the start (its `θ` part is zero).
    pub fn z0(&self) -> &[f64] {
        &self.data[..self.n]
    }

    /// The integrated vector at the end.
    pub fn z1(&self) -> &[f64] {
        &self.data[self.n..2 * self.n]
    }

    /// Where the next step starts: the orientation at the end, returned,
    /// and the integrated vector at the end with its local rotation `θ`
    /// reset to zero (folded into the orientation), into `z`.
    pub fn end_into(&self, z: &mut [f64]) -> UnitQuaternion<f64> {
        z.copy_from_slice(self.z1());
        z[3..6].fill(0.0);
        advance(&self.q0, self.z1())
    }

    /// Stage derivatives, stage-major (Dormand–Prince only; empty for RK4).
    fn k(&self) -> &[f64] {
        &self.data[2 * self.n..]
    }

    /// `f` at the start of the next step, `z1` with its local rotation `θ`
    /// reset to zero, into `f`, without evaluating it: Dormand–Prince's
    /// last stage is evaluated at `z1` itself (first same as last), and of
    /// `f` only the `θ̇` rows depend on `θ`. `false` (and `f` untouched)
    /// for an RK4 step.
    pub fn end_derivative_into(&self, f: &mut Vec<f64>) -> bool {
        if !self.adaptive {
            return false;
        }
        let n = self.n;
        f.clear();
        f.extend_from_slice(&self.k()[(DOPRI5.c.len() - 1) * n..]);
        let w = vec3(self.z1(), 0);
        f[3..6].copy_from_slice(theta_rate(&Vec3::zeros(), &w).as_slice());
        true
    }

    /// End time.
    pub fn t1(&self) -> f64 {
        self.t0 + self.h
    }

    /// Orientation and integrated vector at `t` in `[t0, t0 + h]`:
    /// Dormand–Prince dense output, or for RK4 a fresh step of length `t − t0`
    /// (both as accurate as the step itself).
    pub fn at(&self, d: &BodyDynamics, t: f64, evals: &mut u64) -> (UnitQuaternion<f64>, Vec<f64>) {
        let mut z = vec![0.0; self.n];
        let q = self.at_into(d, t, evals, &mut z);
        (q, z)
    }

    /// As [`Step::at`] for the state part only (`w`, `θ`): the state does not
    /// depend on the tangent, so this gives the same numbers at a fraction of
    /// the cost, without allocating (used by the event search).
    pub fn at_state(
        &self,
        d: &BodyDynamics,
        t: f64,
        evals: &mut u64,
    ) -> (UnitQuaternion<f64>, [f64; Z_STATE]) {
        let mut z = [0.0; Z_STATE];
        let q = self.at_into(d, t, evals, &mut z);
        (q, z)
    }

    /// The first `out.len()` entries of the integrated vector at `t` into
    /// `out`; returns the orientation.
    fn at_into(
        &self,
        d: &BodyDynamics,
        t: f64,
        evals: &mut u64,
        out: &mut [f64],
    ) -> UnitQuaternion<f64> {
        let n = out.len();
        let tau = t - self.t0;
        let (z0, z1) = (self.z0(), self.z1());
        if tau <= 0.0 {
            out.copy_from_slice(&z0[..n]);
            return self.q0;
        }
        if tau >= self.h {
            out.copy_from_slice(&z1[..n]);
            return advance(&self.q0, z1);
        }
        if self.adaptive {
            let s = tau / self.h;
            let s1 = 1.0 - s;
            let stride = self.n;
            let k = self.k();
            for (i, o) in out.iter_mut().enumerate() {
                let y0 = z0[i];
                let y1 = z1[i];
                let ydiff = y1 - y0;
                let bspl = self.h * k[i] - ydiff;
                let r4 = ydiff - self.h * k[6 * stride + i] - bspl;
                let r5: f64 = self.h
                    * DOPRI_D
                        .iter()
                        .zip(k.chunks_exact(stride))
                        .map(|(dd, kk)| dd * kk[i])
                        .sum::<f64>();
                *o = y0 + s * (ydiff + s1 * (bspl + s * (r4 + s1 * r5)));
            }
        } else {
            rk4_end(d, &z0[..n], tau, evals, out);
        }
        advance(&self.q0, out)
    }
}

/// The 6×9 tangent block `Y` of an integrated vector (columns it does not
/// integrate are zero).
pub fn tangent_block(z: &[f64]) -> nalgebra::SMatrix<f64, 6, 9> {
    let mut y = nalgebra::SMatrix::<f64, 6, 9>::zeros();
    if z.len() >= Z_TRANSITION {
        y.as_mut_slice()[..z.len() - Z_STATE].copy_from_slice(&z[Z_STATE..]);
    }
    y
}

/// Body-frame angular velocity of an integrated vector.
pub fn body_rate(z: &[f64]) -> Vec3 {
    vec3(z, 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn top() -> BodyDynamics {
        let inertia = Mat3::from_diagonal(&Vec3::new(1.0, 2.0, 3.0));
        BodyDynamics {
            mass: 1.0,
            principal: Vec3::new(1.0, 2.0, 3.0),
            axes: Mat3::identity(),
            inertia,
            inertia_inv: inertia.try_inverse().unwrap(),
            drag_k: None,
            drag_c: 0.0,
            integrate: true,
            reach: 1.0,
        }
    }

    /// The variational right-hand side is the derivative of the state
    /// right-hand side (checked by central differences in w and I).
    #[test]
    fn variational_rhs_matches_central_differences() {
        let d = top();
        let w = Vec3::new(0.3, -1.1, 0.7);
        let z = initial(&w, Columns::WithInertia);
        let mut dz = vec![0.0; Z_LEN];
        rhs(&d, &z, &mut dz);
        let y = tangent_block(&dz);
        let h = 1e-6;
        for i in 0..3 {
            let mut wp = w;
            wp[i] += h;
            let mut wm = w;
            wm[i] -= h;
            let fd = (euler_rhs(&d.inertia, &d.inertia_inv, &wp)
                - euler_rhs(&d.inertia, &d.inertia_inv, &wm))
                / (2.0 * h);
            let col = y.fixed_view::<3, 1>(3, 3 + i).into_owned();
            assert!((fd - col).norm() < 1e-8, "Df column {i}");
        }
        for k in 0..3 {
            let mut p = d.clone();
            let mut m = d.clone();
            p.principal[k] += h;
            m.principal[k] -= h;
            for x in [&mut p, &mut m] {
                x.inertia = Mat3::from_diagonal(&x.principal);
                x.inertia_inv = x.inertia.try_inverse().unwrap();
            }
            let fd = (euler_rhs(&p.inertia, &p.inertia_inv, &w)
                - euler_rhs(&m.inertia, &m.inertia_inv, &w))
                / (2.0 * h);
            let col = y.fixed_view::<3, 1>(3, 6 + k).into_owned();
            assert!((fd - col).norm() < 1e-8, "∂f/∂I_{k}: {fd:?} vs {col:?}");
        }
    }

    /// One Dormand–Prince step of `h` from `z0` at t = 0 (tolerance 1e-9).
    fn dopri_from(d: &BodyDynamics, z0: &[f64], h: f64) -> (Step, f64) {
        let mut evals = 0;
        let f0 = first_stage(d, z0, &mut evals);
        let q0 = UnitQuaternion::identity();
        step_dopri(d, 0.0, q0, z0, &f0, h, 1e-9, &mut evals)
    }

    #[test]
    fn the_end_derivative_is_the_next_steps_first_stage_exactly() {
        let d = top();
        for columns in [Columns::None, Columns::Transition, Columns::WithInertia] {
            let z0 = initial(&Vec3::new(0.3, 2.0, 0.1), columns);
            let (st, _) = dopri_from(&d, &z0, 0.05);
            // The step turned the body: θ is not zero at its end.
            assert!(vec3(st.z1(), 3).norm() > 0.05);
            let mut next = st.z1().to_vec();
            next[3..6].fill(0.0);
            let fresh = first_stage(&d, &next, &mut 0);
            let mut reused = Vec::new();
            assert!(st.end_derivative_into(&mut reused), "an adaptive step");
            // Bit for bit: reusing it changes no result of the simulator.
            assert_eq!(reused, fresh, "{columns:?}");
        }
        let z0 = initial(&Vec3::new(0.3, 2.0, 0.1), Columns::None);
        let st = step_rk4(&d, 0.0, UnitQuaternion::identity(), &z0, 0.05, &mut 0);
        assert!(!st.end_derivative_into(&mut Vec::new()));
    }

    /// Dense output reproduces the step end and is close to a fresh step inside.
    #[test]
    fn dopri_dense_output_is_consistent() {
        let d = top();
        let z0 = initial(&Vec3::new(0.3, 2.0, 0.1), Columns::None);
        let mut evals = 0;
        let (st, err) = dopri_from(&d, &z0, 0.05);
        assert!(err.is_finite());
        let (_, zend) = st.at(&d, 0.05 - 1e-15, &mut evals);
        assert!((zend[0] - st.z1()[0]).abs() < 1e-12);
        let (_, zmid) = st.at(&d, 0.02, &mut evals);
        let (fresh, _) = dopri_from(&d, &z0, 0.02);
        for (i, (a, b)) in zmid.iter().zip(fresh.z1()).take(6).enumerate() {
            assert!((a - b).abs() < 1e-8, "component {i}");
        }
    }
}
