//! The collision impulse map `Φ(q⁻, u)` (DESIGN §4) and its exact
//! derivatives. The map is written once, generic in the scalar, and
//! evaluated with `f64` to apply the impulse and with forward-mode dual
//! numbers (num-dual) to get `E_q`, `Φ_q` and `Φ_u` in one pass — so the
//! impulse that is applied and the one that is differentiated are the same
//! code, including how the contact point and normal move with the bodies.

use super::state::BodyState;
use crate::geometry::{FeaturePair, PoseT};
use crate::math::{Mat3, Vec3};
use nalgebra::{DMatrix, Isometry3, Matrix3, RealField, SMatrix, SVector, Vector3, convert};
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
    /// Friction mode (decided by [`ImpulseCtx::apply`]): sticking or sliding.
    pub stick: bool,
    /// A micro-collision (see `sim::rest`): when set to `v` (m/s), the
    /// contact leaves at `max(−v_n, v)` — elastically, or at `v` when it
    /// approached slower — instead of at `−e v_n`. Restitution then has no
    /// effect, and the dual-number Jacobian differentiates this map.
    pub min_separation: Option<f64>,
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

fn moving<T: RealField>(p: &PartyCtx, z: &[T], at: usize, pm: usize) -> Moving<T> {
    let r0 = cm::<T>(p.state.q.to_rotation_matrix().matrix());
    // First-order left perturbation: exact for first derivatives at δθ = 0.
    let r = (Matrix3::identity() + skew(&v3(z, at + 3))) * r0;
    let x = cv::<T>(&p.state.x) + v3(z, at);
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
        pose: PoseT { x, r },
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

    /// The impulse model: `[E, v_a⁺, ω_a⁺, v_b⁺, ω_b⁺]`; with `decide`, also
    /// returns whether the sticking impulse lies in the friction cone.
    fn model<T: RealField>(&self, z: &[T], mode: Option<bool>) -> (Vec<T>, bool) {
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
        let mut stick = false;
        let p = if self.friction > 0.0 {
            let mu: T = c(self.friction);
            let target = &n * sep.clone();
            let k_inv = k.clone().try_inverse().unwrap_or_else(Matrix3::zeros);
            let p_stick = k_inv * (target - &v_rel);
            let pn = n.dot(&p_stick);
            let pt = &p_stick - &n * pn.clone();
            stick = match mode {
                Some(s) => s,
                None => pt.norm() <= mu.clone() * pn.clone(),
            };
            let vt = &v_rel - &n * vn.clone();
            let vt_norm = vt.norm();
            if stick || vt_norm == T::zero() {
                p_stick
            } else {
                let dir = &n - (vt / vt_norm) * mu;
                let pn = (sep - vn.clone()) / n.dot(&(&k * &dir));
                dir * pn
            }
        } else {
            let j = (sep - vn.clone()) / n.dot(&(&k * &n));
            &n * j
        };
        let mut out = Vec::with_capacity(OUTPUTS);
        out.push(geo.distance.clone());
        let va = &a.v + &p * a.inv_mass.clone();
        let wa = &a.w + &a.inv_inertia * ra.cross(&p);
        out.extend(va.iter().cloned());
        out.extend(wa.iter().cloned());
        match &b {
            Some(m) => {
                let vb2 = &m.v - &p * m.inv_mass.clone();
                let wb2 = &m.w - &m.inv_inertia * rb.cross(&p);
                out.extend(vb2.iter().cloned());
                out.extend(wb2.iter().cloned());
            }
            None => out.extend(std::iter::repeat_n(T::zero(), 6)),
        }
        (out, stick)
    }

    /// Apply the impulse at the current state (deciding the friction mode).
    pub fn apply(&mut self) -> ImpulseResult {
        let z = self.input();
        let (out, stick) = self.model::<f64>(&z, None);
        self.stick = stick;
        // Re-derive the quantities the report needs with the same model.
        let a_pose = PoseT::from_isometry(&Isometry3::from_parts(
            self.a.state.x.into(),
            self.a.state.q,
        ));
        let b_pose = match &self.b {
            Some(b) => PoseT::from_isometry(&Isometry3::from_parts(b.state.x.into(), b.state.q)),
            None => PoseT::from_isometry(&self.b_pose),
        };
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

    /// Jacobian of the model outputs with respect to its inputs (13 × inputs),
    /// in the friction mode chosen by [`ImpulseCtx::apply`].
    pub fn jacobian(&self) -> DMatrix<f64> {
        let z = self.input();
        if self.b.is_some() {
            let j = self.jac_n::<INPUTS_BODIES>(&z);
            DMatrix::from_column_slice(OUTPUTS, INPUTS_BODIES, j.as_slice())
        } else {
            let j = self.jac_n::<INPUTS_OBSTACLE>(&z);
            DMatrix::from_column_slice(OUTPUTS, INPUTS_OBSTACLE, j.as_slice())
        }
    }

    fn jac_n<const N: usize>(&self, z: &[f64]) -> SMatrix<f64, OUTPUTS, N> {
        let x = SVector::<f64, N>::from_column_slice(z);
        let mode = Some(self.stick);
        let (_, j) = num_dual::jacobian(
            |zd: SVector<DualSVec64<N>, N>| {
                let (out, _) = self.model(zd.as_slice(), mode);
                SVector::<DualSVec64<N>, OUTPUTS>::from_iterator(out)
            },
            &x,
        );
        j
    }

    /// Evaluate the model at arbitrary inputs (for finite-difference checks).
    pub fn evaluate(&self, z: &[f64]) -> Vec<f64> {
        self.model::<f64>(z, Some(self.stick)).0
    }
}
