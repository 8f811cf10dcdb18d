//! The collision impulse map `Φ(q⁻, u)` (docs/design.md §4) and its exact
//! derivatives. The map is written once, generic in the scalar, and
//! evaluated with `f64` to apply the impulse and with forward-mode dual
//! numbers (num-dual) to get `E_q`, `Φ_q` and `Φ_u` in one pass — so the
//! impulse that is applied and the one that is differentiated are the same
//! code, including how the contact point and normal move with the bodies.

use super::jet::{self, Sj, Vj};
use super::state::BodyState;
use crate::geometry::{FeaturePair, PoseT, SideFeature};
use crate::math::{Mat3, Vec3};
use nalgebra::{
    Const, DMatrix, Isometry3, Matrix3, RealField, SMatrix, SVector, U1, Vector3, convert,
};
use num_dual::DualSVec64;

/// Number of outputs of the impulse model: `E`, then `v⁺, ω⁺` of a and of b.
pub const OUTPUTS: usize = 13;
/// Inputs with a static obstacle: `δq_a` (12), normal deviation (2),
/// restitution, `m_a`, `I_a` (3).
pub const INPUTS_OBSTACLE: usize = 19;
/// Inputs with two bodies: `δq_a`, `δq_b`, deviation (2), restitution,
/// `m_a`, `I_a`, `m_b`, `I_b`.
pub const INPUTS_BODIES: usize = 35;

/// One moving party of a collision.
#[derive(Debug, Clone)]
pub struct PartyCtx {
    pub state: BodyState,
    pub mass: f64,
    pub principal: Vec3,
    /// Principal axes in the body frame.
    pub axes: Mat3,
}

/// Everything the impulse map depends on besides its inputs.
#[derive(Debug, Clone)]
pub struct ImpulseCtx {
    pub feature: FeaturePair,
    pub a: PartyCtx,
    /// `None` for a static obstacle at `b_pose`.
    pub b: Option<PartyCtx>,
    pub b_pose: Isometry3<f64>,
    /// Restitution used at this event.
    pub restitution: f64,
    /// Controlled normal deviation `(a, b)`, if the event has normal controls.
    pub normal_dev: Option<[f64; 2]>,
    /// World axis used to build the tangent basis of the geometric normal.
    pub tangent_axis: Vec3,
    /// Coulomb coefficient; 0 means frictionless (friction never evaluated).
    pub friction: f64,
    /// Friction mode, decided by [`ImpulseCtx::apply`].
    pub mode: FrictionMode,
    /// A micro-collision (see `sim::rest`): when set to `v` (m/s), the
    /// contact leaves at `max(−v_n, v)` — elastically, or at `v` when it
    /// approached slower — instead of at `−e v_n`. Restitution then has no
    /// effect, and the dual-number Jacobian differentiates this map.
    pub min_separation: Option<f64>,
}

/// How friction acts at an impact (only with the `friction` effect).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FrictionMode {
    /// The tangential impulse stops the contact's sliding (inside the
    /// cone `|P_t| ≤ μ P_n`); else it pushes against the sliding at the
    /// cone's edge.
    pub stick: bool,
    /// A contact patch's couple stops the relative spin about the normal
    /// (within `|τ| ≤ μ ρ P_n`); else it opposes the spin at that limit.
    /// Meaningless at a one-point contact, which resists no spin.
    pub spin_stick: bool,
}

/// The applied impulse.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpulseResult {
    /// Feature-model signed distance at the pre-impulse state.
    pub distance: f64,
    /// Normal used for the impulse (after any controlled deviation).
    pub normal: Vec3,
    /// Contact point on a, world.
    pub point: Vec3,
    /// Relative normal velocity before the impulse (negative = approaching).
    pub approach: f64,
    /// Relative normal velocity after it.
    pub separation: f64,
    /// Post-impulse velocities of a and b (b zero for an obstacle).
    pub va: Vec3,
    pub wa: Vec3,
    pub vb: Vec3,
    pub wb: Vec3,
    /// Impulse applied to a, N·s.
    pub impulse: Vec3,
}

fn c<T: RealField>(v: f64) -> T {
    convert(v)
}

fn v3<T: RealField>(z: &[T], i: usize) -> Vector3<T> {
    Vector3::new(z[i].clone(), z[i + 1].clone(), z[i + 2].clone())
}

fn cv<T: RealField>(v: &Vec3) -> Vector3<T> {
    v.map(convert::<f64, T>)
}

fn cm<T: RealField>(m: &Mat3) -> Matrix3<T> {
    m.map(convert::<f64, T>)
}

fn skew<T: RealField>(v: &Vector3<T>) -> Matrix3<T> {
    Matrix3::new(
        T::zero(),
        -v.z.clone(),
        v.y.clone(),
        v.z.clone(),
        T::zero(),
        -v.x.clone(),
        -v.y.clone(),
        v.x.clone(),
        T::zero(),
    )
}

/// A party's pose, velocities and world inverse inertia, perturbed by the
/// tangent inputs `(δx, δθ, δv, δω)` at `z[at..at+12]` and with mass and
/// principal moments `z[pm]`, `z[pm+1..pm+4]`.
struct Moving<T: RealField> {
    pose: PoseT<T>,
    v: Vector3<T>,
    w: Vector3<T>,
    inv_mass: T,
    inv_inertia: Matrix3<T>,
}

/// A party's pose perturbed by `δx = z[at..at+3]`, `δθ = z[at+3..at+6]`.
fn pose<T: RealField>(p: &PartyCtx, z: &[T], at: usize) -> PoseT<T> {
    let r0 = cm::<T>(p.state.q.to_rotation_matrix().matrix());
    // First-order left perturbation: exact for first derivatives at δθ = 0.
    let r = (Matrix3::identity() + skew(&v3(z, at + 3))) * r0;
    let x = cv::<T>(&p.state.x) + v3(z, at);
    PoseT { x, r }
}

fn moving<T: RealField>(p: &PartyCtx, z: &[T], at: usize, pm: usize) -> Moving<T> {
    let pose = pose(p, z, at);
    let r = pose.r.clone();
    let v = cv::<T>(&p.state.v) + v3(z, at + 6);
    let w = cv::<T>(&p.state.w) + v3(z, at + 9);
    let inv_mass = T::one() / z[pm].clone();
    let diag = Matrix3::from_diagonal(&Vector3::new(
        T::one() / z[pm + 1].clone(),
        T::one() / z[pm + 2].clone(),
        T::one() / z[pm + 3].clone(),
    ));
    let q = cm::<T>(&p.axes);
    let rq = &r * q;
    let inv_inertia = &rq * diag * rq.transpose();
    Moving {
        pose,
        v,
        w,
        inv_mass,
        inv_inertia,
    }
}

impl ImpulseCtx {
    /// Number of inputs of the model.
    pub fn inputs(&self) -> usize {
        if self.b.is_some() {
            INPUTS_BODIES
        } else {
            INPUTS_OBSTACLE
        }
    }

    /// The input vector at the current state: zero tangents and the actual parameters.
    pub fn input(&self) -> Vec<f64> {
        let n = self.inputs();
        let mut z = vec![0.0; n];
        let p0 = if self.b.is_some() { 24 } else { 12 };
        let dev = self.normal_dev.unwrap_or([0.0, 0.0]);
        z[p0] = dev[0];
        z[p0 + 1] = dev[1];
        z[p0 + 2] = self.restitution;
        z[p0 + 3] = self.a.mass;
        z[p0 + 4..p0 + 7].copy_from_slice(self.a.principal.as_slice());
        if let Some(b) = &self.b {
            z[p0 + 7] = b.mass;
            z[p0 + 8..p0 + 11].copy_from_slice(b.principal.as_slice());
        }
        z
    }

    /// Index of the first parameter input (normal deviation a).
    pub fn param_offset(&self) -> usize {
        if self.b.is_some() { 24 } else { 12 }
    }

    /// The impulse model: `[E, v_a⁺, ω_a⁺, v_b⁺, ω_b⁺]`, in the friction
    /// `mode` given, or (with `None`) the one it decides: the first of
    /// stick/stick, stick/slide, slide/stick, slide/slide (impulse/spin)
    /// whose impulse lies in its friction cone and whose couple within its
    /// limit.
    fn model<T: RealField>(&self, z: &[T], mode: Option<FrictionMode>) -> (Vec<T>, FrictionMode) {
        let p0 = self.param_offset();
        let a = moving(&self.a, z, 0, p0 + 3);
        let b = self.b.as_ref().map(|b| moving(b, z, 12, p0 + 7));
        let pose_b = match &b {
            Some(m) => m.pose.clone(),
            None => PoseT {
                x: cv::<T>(&self.b_pose.translation.vector),
                r: cm::<T>(self.b_pose.rotation.to_rotation_matrix().matrix()),
            },
        };
        let geo = self.feature.evaluate(&a.pose, &pose_b);
        let mut n = geo.normal.clone();
        if self.normal_dev.is_some() {
            let t1 = n.cross(&cv::<T>(&self.tangent_axis));
            let t1 = &t1 / t1.norm();
            let t2 = n.cross(&t1);
            n = &n + t1 * z[p0].clone() + t2 * z[p0 + 1].clone();
            n = &n / n.norm();
        }
        let e = z[p0 + 2].clone();
        let ra = &geo.point_a - &a.pose.x;
        let zero = Vector3::<T>::zeros();
        let (vb, wb, rb) = match &b {
            Some(m) => (m.v.clone(), m.w.clone(), &geo.point_b - &m.pose.x),
            None => (zero.clone(), zero.clone(), zero.clone()),
        };
        let v_rel = &a.v + a.w.cross(&ra) - (&vb + wb.cross(&rb));
        let vn = n.dot(&v_rel);
        let sra = skew(&ra);
        let mut k = Matrix3::identity() * a.inv_mass.clone() - &sra * &a.inv_inertia * &sra;
        if let Some(m) = &b {
            let srb = skew(&rb);
            k += Matrix3::identity() * m.inv_mass.clone() - &srb * &m.inv_inertia * &srb;
        }
        // Normal speed the contact separates at: `−e v_n`, or the floor of
        // a micro-collision.
        let sep: T = match self.min_separation {
            Some(v) if -vn.clone() >= c::<T>(v) => -vn.clone(),
            Some(v) => c(v),
            None => -(e * vn.clone()),
        };
        let mut decided = FrictionMode::default();
        let (p, tau) = if self.friction > 0.0 {
            let mu: T = c(self.friction);
            let target = &n * sep.clone() - &v_rel;
            let vt = &v_rel - &n * vn.clone();
            let vt_norm = vt.norm();
            // Sliding impulses push against the tangential velocity before
            // the impact: `P = P_n (n − μ t̂)`.
            let slide_dir = if vt_norm == T::zero() {
                None
            } else {
                Some(&n - (vt / vt_norm) * mu.clone())
            };
            let rho = geo.spin_radius.clone();
            let cone = |p: &Vector3<T>| {
                let pn = n.dot(p);
                (p - &n * pn.clone()).norm() <= mu.clone() * pn
            };
            if rho > T::zero() {
                // A contact patch also resists spin about its normal: a
                // couple `τ n` with `|τ| ≤ μ ρ P_n` (the patch's torsional
                // radius ρ). The couple and the impulse are coupled
                // through `K₄ = [[K, k], [kᵀ, k_ττ]]`: `Δu = K P + k τ`
                // (contact velocity) and `Δs = kᵀ P + k_ττ τ` (relative
                // spin about `n`).
                let ia_n = &a.inv_inertia * &n;
                let mut k_ut = -(&sra * &ia_n);
                let mut k_tt = n.dot(&ia_n);
                let mut spin = n.dot(&a.w);
                if let Some(m) = &b {
                    let ib_n = &m.inv_inertia * &n;
                    k_ut -= skew(&rb) * &ib_n;
                    k_tt += n.dot(&ib_n);
                    spin -= n.dot(&m.w);
                }
                let sigma = if spin > T::zero() {
                    T::one()
                } else if spin < T::zero() {
                    -T::one()
                } else {
                    T::zero()
                };
                // The spin couple's limit per unit normal impulse, signed to
                // oppose the spin.
                let g = -(sigma * mu.clone() * rho.clone());
                let torque_ok =
                    |tau: &T, pn: &T| tau.clone().abs() <= mu.clone() * rho.clone() * pn.clone();
                // 1. Sticking in both.
                let stick_stick = || {
                    let mut k4 = nalgebra::Matrix4::<T>::zeros();
                    k4.fixed_view_mut::<3, 3>(0, 0).copy_from(&k);
                    k4.fixed_view_mut::<3, 1>(0, 3).copy_from(&k_ut);
                    k4.fixed_view_mut::<1, 3>(3, 0).copy_from(&k_ut.transpose());
                    k4[(3, 3)] = k_tt.clone();
                    let rhs = nalgebra::Vector4::new(
                        target.x.clone(),
                        target.y.clone(),
                        target.z.clone(),
                        -spin.clone(),
                    );
                    let x = k4.try_inverse().unwrap_or_else(nalgebra::Matrix4::zeros) * rhs;
                    (
                        Vector3::new(x[0].clone(), x[1].clone(), x[2].clone()),
                        x[3].clone(),
                    )
                };
                // 2. Sticking impulse, sliding spin: `τ = g P_n`.
                let stick_slide = || {
                    let m3 = &k + &k_ut * n.transpose() * g.clone();
                    let p = m3.try_inverse().unwrap_or_else(Matrix3::zeros) * &target;
                    let tau = n.dot(&p) * g.clone();
                    (p, tau)
                };
                // 3. Sliding impulse along `d`, sticking spin.
                let slide_stick = |d: &Vector3<T>| {
                    let (a11, a12) = (n.dot(&(&k * d)), n.dot(&k_ut));
                    let (a21, a22) = (k_ut.dot(d), k_tt.clone());
                    let (b1, b2) = (sep.clone() - vn.clone(), -spin.clone());
                    let det = a11.clone() * a22.clone() - a12.clone() * a21.clone();
                    let pn = (b1.clone() * a22 - a12 * b2.clone()) / det.clone();
                    let tau = (a11 * b2 - a21 * b1) / det;
                    (d * pn, tau)
                };
                // 4. Sliding in both.
                let slide_slide = |d: &Vector3<T>| {
                    let pn =
                        (sep.clone() - vn.clone()) / (n.dot(&(&k * d)) + n.dot(&k_ut) * g.clone());
                    (d * pn.clone(), g.clone() * pn)
                };
                let mode = mode.unwrap_or_else(|| {
                    let (p, tau) = stick_stick();
                    if cone(&p) && torque_ok(&tau, &n.dot(&p)) {
                        return FrictionMode {
                            stick: true,
                            spin_stick: true,
                        };
                    }
                    let (p, _) = stick_slide();
                    if cone(&p) {
                        return FrictionMode {
                            stick: true,
                            spin_stick: false,
                        };
                    }
                    if let Some(d) = &slide_dir {
                        let (p, tau) = slide_stick(d);
                        if torque_ok(&tau, &n.dot(&p)) {
                            return FrictionMode {
                                stick: false,
                                spin_stick: true,
                            };
                        }
                    }
                    FrictionMode {
                        stick: false,
                        spin_stick: false,
                    }
                });
                decided = mode;
                match (mode.stick, mode.spin_stick, &slide_dir) {
                    (true, true, _) | (false, true, None) => stick_stick(),
                    (true, false, _) | (false, false, None) => stick_slide(),
                    (false, true, Some(d)) => slide_stick(d),
                    (false, false, Some(d)) => slide_slide(d),
                }
            } else {
                let k_inv = k.clone().try_inverse().unwrap_or_else(Matrix3::zeros);
                let p_stick = k_inv * &target;
                decided.stick = match mode {
                    Some(m) => m.stick,
                    None => cone(&p_stick),
                };
                match &slide_dir {
                    Some(dir) if !decided.stick => {
                        let pn = (sep - vn.clone()) / n.dot(&(&k * dir));
                        (dir * pn, T::zero())
                    }
                    _ => (p_stick, T::zero()),
                }
            }
        } else {
            let j = (sep - vn.clone()) / n.dot(&(&k * &n));
            (&n * j, T::zero())
        };
        let mut out = Vec::with_capacity(OUTPUTS);
        out.push(geo.distance.clone());
        let couple = &n * tau;
        // A frictionless impulse on a ball centred on its body's centre of
        // mass acts along the line through that centre: no torque, exactly
        // (the lever from round-off witness points would spin it by 1e-12
        // to 3e-8 rad/s).
        let (central_a, central_b) = self.central();
        let torque = |r: &Vector3<T>, central: bool| {
            if central {
                Vector3::<T>::zeros()
            } else {
                r.cross(&p) + &couple
            }
        };
        let va = &a.v + &p * a.inv_mass.clone();
        let wa = &a.w + &a.inv_inertia * torque(&ra, central_a);
        out.extend(va.iter().cloned());
        out.extend(wa.iter().cloned());
        match &b {
            Some(m) => {
                let vb2 = &m.v - &p * m.inv_mass.clone();
                let wb2 = &m.w - &m.inv_inertia * torque(&rb, central_b);
                out.extend(vb2.iter().cloned());
                out.extend(wb2.iter().cloned());
            }
            None => out.extend(std::iter::repeat_n(T::zero(), 6)),
        }
        (out, decided)
    }

    /// The parties' poses at the current state, in plain numbers.
    fn poses(&self) -> (PoseT<f64>, PoseT<f64>) {
        let at = |s: &BodyState| PoseT::from_isometry(&Isometry3::from_parts(s.x.into(), s.q));
        let b = match &self.b {
            Some(b) => at(&b.state),
            None => PoseT::from_isometry(&self.b_pose),
        };
        (at(&self.a.state), b)
    }

    /// Apply the impulse at the current state (deciding the friction mode).
    pub fn apply(&mut self) -> ImpulseResult {
        let z = self.input();
        let (out, mode) = self.model::<f64>(&z, None);
        self.mode = mode;
        // Re-derive the quantities the report needs with the same model.
        let (a_pose, b_pose) = self.poses();
        let geo = self.feature.evaluate(&a_pose, &b_pose);
        let mut n = geo.normal;
        if let Some(dev) = self.normal_dev {
            let t1 = n.cross(&self.tangent_axis).normalize();
            let t2 = n.cross(&t1);
            n = (n + t1 * dev[0] + t2 * dev[1]).normalize();
        }
        let ra = geo.point_a - self.a.state.x;
        let (vb, wb, rb) = match &self.b {
            Some(b) => (b.state.v, b.state.w, geo.point_b - b.state.x),
            None => (Vec3::zeros(), Vec3::zeros(), Vec3::zeros()),
        };
        let rel =
            |va: Vec3, wa: Vec3, vb: Vec3, wb: Vec3| (va + wa.cross(&ra)) - (vb + wb.cross(&rb));
        let va = Vec3::new(out[1], out[2], out[3]);
        let wa = Vec3::new(out[4], out[5], out[6]);
        let vb2 = Vec3::new(out[7], out[8], out[9]);
        let wb2 = Vec3::new(out[10], out[11], out[12]);
        let approach = n.dot(&rel(self.a.state.v, self.a.state.w, vb, wb));
        let (vb_post, wb_post) = if self.b.is_some() {
            (vb2, wb2)
        } else {
            (Vec3::zeros(), Vec3::zeros())
        };
        let separation = n.dot(&rel(va, wa, vb_post, wb_post));
        ImpulseResult {
            distance: out[0],
            normal: n,
            point: geo.point_a,
            approach,
            separation,
            va,
            wa,
            vb: vb_post,
            wb: wb_post,
            impulse: (va - self.a.state.v) * self.a.mass,
        }
    }
}

mod chain;
#[cfg(test)]
mod tests;
