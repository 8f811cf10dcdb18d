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
use num_dual::{Derivative, DualSVec64};

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

/// Contact geometry as jets over the `N` model inputs.
struct JetGeometry<const N: usize> {
    distance: Sj<N>,
    normal: Vj<N>,
    point_a: Vj<N>,
    point_b: Vj<N>,
    spin_radius: Sj<N>,
}

/// The parts of an impulse model every friction mode shares, as jets (see
/// [`ImpulseCtx::jet_contact`]).
struct JetContact<const N: usize> {
    geometry: JetGeometry<N>,
    n: Vj<N>,
    a: JetParty<N>,
    b: Option<JetParty<N>>,
    v_rel: Vj<N>,
    vn: Sj<N>,
    sep: Sj<N>,
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

/// One moving party of an impulse, as jets: its velocities, inverse mass,
/// lever `r` in world axes, and what applying its inverse inertia to a jet
/// takes.
struct JetParty<const N: usize> {
    v: Vj<N>,
    w: Vj<N>,
    r: Vj<N>,
    inv_mass: Sj<N>,
    /// World principal axes `R A`, inverse principal moments, `I⁻¹`.
    axes: Mat3,
    d_inv: Vec3,
    inv_inertia: Mat3,
    /// First tangent input (`δx`, `δθ`, `δv`, `δω`) and mass input.
    at: usize,
    pm: usize,
}

impl<const N: usize> JetParty<N> {
    /// `at`: the party's first tangent input (`δx`, `δθ`, `δv`, `δω`);
    /// `pm`: its mass input, followed by its three principal moments.
    fn new(p: &PartyCtx, at: usize, pm: usize, point: &Vj<N>) -> Self {
        let axes = p.state.q.to_rotation_matrix().matrix() * p.axes;
        let d_inv = p.principal.map(|i| 1.0 / i);
        JetParty {
            v: Vj::input(p.state.v, at + 6),
            w: Vj::input(p.state.w, at + 9),
            r: point.sub(&Vj::input(p.state.x, at)),
            inv_mass: Sj::input(p.mass, pm).recip(),
            axes,
            d_inv,
            inv_inertia: axes * Mat3::from_diagonal(&d_inv) * axes.transpose(),
            at,
            pm,
        }
    }

    /// `I⁻¹ y` with `I⁻¹ = R A D⁻¹ Aᵀ Rᵀ`, `R = (1 + [δθ]×) R₀`,
    /// `D = diag(I₁, I₂, I₃)`: `d(I⁻¹y) = I⁻¹ dy + (I⁻¹[y]× − [I⁻¹y]×) dθ
    /// − Σ A_k (A_kᵀ y) dI_k / I_k²`.
    fn inv_inertia_mul(&self, y: &Vj<N>) -> Vj<N> {
        let aty = self.axes.transpose() * y.v;
        let v = self.axes * self.d_inv.component_mul(&aty);
        let mut d = self.inv_inertia * y.d;
        let dtheta = self.inv_inertia * jet::skew(&y.v) - jet::skew(&v);
        for k in 0..3 {
            if self.at + 3 + k < N {
                let mut col = d.column_mut(self.at + 3 + k);
                col += dtheta.column(k);
            }
            if self.pm + 1 + k < N {
                let mut col = d.column_mut(self.pm + 1 + k);
                col -= self.axes.column(k) * (aty[k] * self.d_inv[k] * self.d_inv[k]);
            }
        }
        Vj { v, d }
    }

    /// Velocity of the material point at the contact: `v + ω × r`.
    fn contact_velocity(&self) -> Vj<N> {
        self.v.add(&self.w.cross(&self.r))
    }

    /// The values alone, as constant jets of width `M`.
    fn as_constant<const M: usize>(&self) -> JetParty<M> {
        JetParty {
            v: self.v.as_constant(),
            w: self.w.as_constant(),
            r: self.r.as_constant(),
            inv_mass: self.inv_mass.as_constant(),
            axes: self.axes,
            d_inv: self.d_inv,
            inv_inertia: self.inv_inertia,
            at: self.at,
            pm: self.pm,
        }
    }
}

/// How an impulse `P` on a (`−P` on b) and a couple `τ n` about the
/// normal change the contact: the relative velocity of the contact points
/// by `Δu = Σ P/m + (I⁻¹(r × P + τ n)) × r` (the `K P + k τ` of
/// [`ImpulseCtx::model`]), the relative spin about `n` by
/// `Δs = Σ n · I⁻¹(r × P + τ n)`; also each party's `I⁻¹(r × P + τ n)`.
struct Response<const N: usize> {
    du: Vj<N>,
    ds: Sj<N>,
    turn_a: Vj<N>,
    turn_b: Option<Vj<N>>,
}

fn response<const N: usize>(
    a: &JetParty<N>,
    b: Option<&JetParty<N>>,
    n: &Vj<N>,
    p: &Vj<N>,
    tau: &Sj<N>,
) -> Response<N> {
    let couple = n.scale(tau);
    let turn_a = a.inv_inertia_mul(&a.r.cross(p).add(&couple));
    let mut du = p.scale(&a.inv_mass).add(&turn_a.cross(&a.r));
    let mut ds = n.dot(&turn_a);
    let turn_b = b.map(|b| {
        let turn = b.inv_inertia_mul(&b.r.cross(p).add(&couple));
        du = du.add(&p.scale(&b.inv_mass)).add(&turn.cross(&b.r));
        ds = ds.add(&n.dot(&turn));
        turn
    });
    Response {
        du,
        ds,
        turn_a,
        turn_b,
    }
}

/// How the relative spin of a frictional impulse is held.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Spin {
    /// No contact patch: no couple.
    Free,
    /// The couple stops the spin (one more unknown and equation).
    Stick,
    /// The couple is at its limit, `τ = g P_n`.
    Slide,
}

/// The linear system of a frictional impulse in its friction mode, as
/// [`ImpulseCtx::model`] solves it: unknowns `x` (the impulse `P`, or
/// `P_n` along the sliding direction `d`; then `τ` when the spin sticks)
/// and equations (`Δu = target`, or `n · Δu = sep − v_n` when sliding;
/// then `Δs = −spin` when the spin sticks).
struct FrictionSystem<const N: usize> {
    n: Vj<N>,
    slide: Option<Vj<N>>,
    spin: Spin,
    /// The spin couple's limit per unit normal impulse.
    g: Sj<N>,
}

impl<const N: usize> FrictionSystem<N> {
    fn unknowns(&self) -> usize {
        let p = if self.slide.is_some() { 1 } else { 3 };
        p + usize::from(self.spin == Spin::Stick)
    }

    /// The impulse and couple for unknowns `x`.
    fn impulse(&self, x: &[Sj<N>]) -> (Vj<N>, Sj<N>) {
        let p = match &self.slide {
            Some(d) => d.scale(&x[0]),
            None => Vj::from_components([x[0], x[1], x[2]]),
        };
        let tau = match self.spin {
            Spin::Free => Sj::constant(0.0),
            Spin::Stick => x[x.len() - 1],
            Spin::Slide => self.g.mul(&self.n.dot(&p)),
        };
        (p, tau)
    }

    /// The left-hand sides of the equations for a response.
    fn equations(&self, r: &Response<N>) -> Vec<Sj<N>> {
        let mut e = match self.slide {
            Some(_) => vec![self.n.dot(&r.du)],
            None => (0..3).map(|i| r.du.component(i)).collect(),
        };
        if self.spin == Spin::Stick {
            e.push(r.ds);
        }
        e
    }

    fn as_constant<const M: usize>(&self) -> FrictionSystem<M> {
        FrictionSystem {
            n: self.n.as_constant(),
            slide: self.slide.as_ref().map(|d| d.as_constant()),
            spin: self.spin,
            g: self.g.as_constant(),
        }
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

    /// Jacobian of the model outputs with respect to its inputs (13 × inputs),
    /// in the friction mode chosen by [`ImpulseCtx::apply`].
    ///
    /// Frictionless impulses (the common case) take the hand-written chain
    /// rule of [`ImpulseCtx::jacobian_jet`]; with friction, the generic model
    /// is differentiated with dual numbers ([`ImpulseCtx::jacobian_dual`]).
    pub fn jacobian(&self) -> DMatrix<f64> {
        self.jacobian_with(true)
    }

    /// As [`ImpulseCtx::jacobian`]; with `params: false` the frictionless
    /// map is differentiated by the states only (12 or 24 columns): when no
    /// normal, restitution, mass or inertia of this impact is a control,
    /// carrying their derivatives would only cost time.
    pub fn jacobian_with(&self, params: bool) -> DMatrix<f64> {
        if self.friction > 0.0 {
            return self.jacobian_friction(params);
        }
        if params {
            return self.jacobian_jet();
        }
        if self.b.is_some() {
            let j = self.jet::<24>();
            DMatrix::from_column_slice(OUTPUTS, 24, j.as_slice())
        } else {
            let j = self.jet::<12>();
            DMatrix::from_column_slice(OUTPUTS, 12, j.as_slice())
        }
    }

    /// The frictionless impulse map differentiated by hand with jets
    /// (`sim::jet`); only the contact geometry — the feature model, written
    /// once for every feature kind — goes through dual numbers, and only
    /// along the 6 (or 12) configuration directions it depends on.
    pub fn jacobian_jet(&self) -> DMatrix<f64> {
        assert!(self.friction == 0.0, "the jet Jacobian is frictionless");
        if self.b.is_some() {
            let j = self.jet::<INPUTS_BODIES>();
            DMatrix::from_column_slice(OUTPUTS, INPUTS_BODIES, j.as_slice())
        } else {
            let j = self.jet::<INPUTS_OBSTACLE>();
            DMatrix::from_column_slice(OUTPUTS, INPUTS_OBSTACLE, j.as_slice())
        }
    }

    /// The configuration directions the contact geometry depends on, as
    /// geometry directions (`0..6`: `δx_a, δθ_a`; `6..12`: `δx_b, δθ_b`). A
    /// ball centred on its body's centre of mass turns without moving its
    /// surface, so its rotation directions are left out: carrying them
    /// would only cost dual-number width.
    fn geometry_directions(&self) -> Vec<usize> {
        let (centred_a, centred_b) = self.centred();
        let mut dirs: Vec<usize> = (0..3).collect();
        if !centred_a {
            dirs.extend(3..6);
        }
        if self.b.is_some() {
            dirs.extend(6..9);
            if !centred_b {
                dirs.extend(9..12);
            }
        }
        dirs
    }

    /// Whether each party touches with a ball centred on its centre of
    /// mass (no contact patch): its contact normal passes through that
    /// centre whatever the configuration, so its turning does not move the
    /// contact, and a normal impulse along the contact normal (not tilted
    /// by a normal control) exerts no torque on it.
    fn centred(&self) -> (bool, bool) {
        let centred = |side: &SideFeature| {
            self.feature.patch.is_empty()
                && matches!(side, SideFeature::Point { p, radius, .. } if *radius > 0.0 && *p == Vec3::zeros())
        };
        (centred(&self.feature.a), centred(&self.feature.b))
    }

    /// Whether the impulse on each party passes through its centre of mass
    /// exactly: a frictionless impulse along the untilted normal of a
    /// centred ball (see [`ImpulseCtx::centred`]).
    fn central(&self) -> (bool, bool) {
        let (a, b) = self.centred();
        let along_normal = self.friction == 0.0 && self.normal_dev.is_none();
        (a && along_normal, b && along_normal)
    }

    /// Contact geometry with its derivatives along the configuration
    /// directions `dirs` (geometry directions, see
    /// [`ImpulseCtx::geometry_directions`]; `G` of them), spread into the
    /// `N` model inputs; the other directions' derivatives are zero.
    fn geometry_jet<const N: usize, const G: usize>(&self, dirs: &[usize]) -> JetGeometry<N> {
        let all = if self.b.is_some() { 12 } else { 6 };
        let seeds: Vec<DualSVec64<G>> = (0..all)
            .map(|g| match dirs.iter().position(|&d| d == g) {
                Some(k) => DualSVec64::new(0.0, Derivative::derivative_generic(Const::<G>, U1, k)),
                None => DualSVec64::from_re(0.0),
            })
            .collect();
        // A party whose rotation is not carried keeps a constant rotation
        // matrix (no dual-number product for it).
        let posed = |p: &PartyCtx, at: usize| {
            if dirs.contains(&(at + 3)) {
                pose(p, &seeds, at)
            } else {
                PoseT {
                    x: cv::<DualSVec64<G>>(&p.state.x) + v3(&seeds, at),
                    r: cm(p.state.q.to_rotation_matrix().matrix()),
                }
            }
        };
        let pa = posed(&self.a, 0);
        let pb = match &self.b {
            Some(b) => posed(b, 6),
            None => PoseT {
                x: cv(&self.b_pose.translation.vector),
                r: cm(self.b_pose.rotation.to_rotation_matrix().matrix()),
            },
        };
        let geo = self.feature.evaluate(&pa, &pb);
        // Geometry direction g is model input g for a, 12 + (g − 6) for b.
        let col = |k: usize| {
            let g = dirs[k];
            if g < 6 { g } else { g + 6 }
        };
        let scalar = |x: &DualSVec64<G>| {
            let mut s = Sj::<N>::constant(x.re);
            let eps = x.eps.unwrap_generic(Const::<G>, U1);
            for k in 0..G {
                s.d[col(k)] = eps[k];
            }
            s
        };
        let vector = |x: &Vector3<DualSVec64<G>>| {
            let mut v = Vj::<N>::constant(x.map(|c| c.re));
            for r in 0..3 {
                let eps = x[r].eps.unwrap_generic(Const::<G>, U1);
                for k in 0..G {
                    v.d[(r, col(k))] = eps[k];
                }
            }
            v
        };
        JetGeometry {
            distance: scalar(&geo.distance),
            normal: vector(&geo.normal),
            point_a: vector(&geo.point_a),
            point_b: vector(&geo.point_b),
            spin_radius: scalar(&geo.spin_radius),
        }
    }

    /// The patch corners within `within` (m) of their face, each as the
    /// gradient of its gap with respect to the model's state inputs
    /// (`δx, δθ, δv, δω` of `a`, then of `b`: 12 or 24 entries; gaps
    /// depend on the configuration only). A flat landing's event time is
    /// the earliest of its corners' own, `min_i t_i(u)`: where two touch at
    /// once it has a kink, and these give its one-sided derivatives (see
    /// `Sim::saltation`). Empty where fewer than two corners touch (no
    /// kink).
    pub fn touching_corners(&self, within: f64) -> Vec<Vec<f64>> {
        if self.feature.patch.len() < 2 {
            return Vec::new();
        }
        // Gaps in plain numbers first: most corners of a patch hover, and
        // only touching ones need their gradient.
        let (plain, plain_b) = self.poses();
        let touching: Vec<&crate::geometry::PatchCorner> = self
            .feature
            .patch
            .iter()
            .filter(|c| c.gap(&plain, &plain_b).abs() <= within)
            .collect();
        if touching.len() < 2 {
            return Vec::new();
        }
        let seeds: Vec<DualSVec64<12>> = (0..12)
            .map(|g| DualSVec64::new(0.0, Derivative::derivative_generic(Const::<12>, U1, g)))
            .collect();
        let pa = pose(&self.a, &seeds, 0);
        let pb = match &self.b {
            Some(b) => pose(b, &seeds, 6),
            None => PoseT {
                x: cv(&self.b_pose.translation.vector),
                r: cm(self.b_pose.rotation.to_rotation_matrix().matrix()),
            },
        };
        let ns = if self.b.is_some() { 24 } else { 12 };
        touching
            .into_iter()
            .map(|corner| {
                let eps = corner.gap(&pa, &pb).eps.unwrap_generic(Const::<12>, U1);
                let mut row = vec![0.0; ns];
                row[..6].copy_from_slice(&eps.as_slice()[..6]);
                if ns == 24 {
                    row[12..18].copy_from_slice(&eps.as_slice()[6..]);
                }
                row
            })
            .collect()
    }

    /// The geometry jet along the directions the contact depends on.
    fn geometry_jet_any<const N: usize>(&self) -> JetGeometry<N> {
        let dirs = self.geometry_directions();
        match dirs.len() {
            3 => self.geometry_jet::<N, 3>(&dirs),
            6 => self.geometry_jet::<N, 6>(&dirs),
            9 => self.geometry_jet::<N, 9>(&dirs),
            _ => self.geometry_jet::<N, 12>(&dirs),
        }
    }

    /// Jacobian of the impulse map with friction (any mode), by jets over
    /// the states and, with `params`, the parameters (else over the states
    /// only: 12 or 24 columns, as [`ImpulseCtx::jacobian_with`]); the
    /// contact geometry along the few configuration directions it depends
    /// on ([`ImpulseCtx::geometry_jet`]), the mode's linear system by
    /// implicit differentiation ([`ImpulseCtx::friction_jet`]). Equal to
    /// [`ImpulseCtx::jacobian_dual`] (tested), at a fraction of its cost.
    pub fn jacobian_friction(&self, params: bool) -> DMatrix<f64> {
        match (self.b.is_some(), params) {
            (false, false) => self.friction_n::<12>(),
            (false, true) => self.friction_n::<INPUTS_OBSTACLE>(),
            (true, false) => self.friction_n::<24>(),
            (true, true) => self.friction_n::<INPUTS_BODIES>(),
        }
    }

    fn friction_n<const N: usize>(&self) -> DMatrix<f64> {
        let j = self.friction_jet::<N>();
        DMatrix::from_column_slice(OUTPUTS, N, j.as_slice())
    }

    /// What every impulse model shares, as jets over the `N` inputs: the
    /// contact geometry, the (deviated) normal, the parties, the relative
    /// contact velocity, its normal part and the separation speed.
    fn jet_contact<const N: usize>(&self) -> JetContact<N> {
        let p0 = self.param_offset();
        let geometry = self.geometry_jet_any::<N>();
        let mut n = geometry.normal;
        if let Some(dev) = self.normal_dev {
            let t1 = n.cross_const(&self.tangent_axis).normalize();
            let t2 = n.cross(&t1);
            n = n
                .add(&t1.scale(&Sj::input(dev[0], p0)))
                .add(&t2.scale(&Sj::input(dev[1], p0 + 1)))
                .normalize();
        }
        let a = JetParty::<N>::new(&self.a, 0, p0 + 3, &geometry.point_a);
        let b = self
            .b
            .as_ref()
            .map(|b| JetParty::<N>::new(b, 12, p0 + 7, &geometry.point_b));
        let mut v_rel = a.contact_velocity();
        if let Some(b) = &b {
            v_rel = v_rel.sub(&b.contact_velocity());
        }
        let vn = n.dot(&v_rel);
        let sep = match self.min_separation {
            Some(v) if -vn.v >= v => vn.neg(),
            Some(v) => Sj::constant(v),
            None => Sj::input(self.restitution, p0 + 2).mul(&vn).neg(),
        };
        JetContact {
            geometry,
            n,
            a,
            b,
            v_rel,
            vn,
            sep,
        }
    }

    /// The outputs' derivatives for impulse `p` and, with `turn_a` /
    /// `turn_b`, the parties' changes of angular velocity.
    fn jet_outputs<const N: usize>(
        contact: &JetContact<N>,
        p: &Vj<N>,
        turn_a: &Vj<N>,
        turn_b: Option<&Vj<N>>,
    ) -> SMatrix<f64, OUTPUTS, N> {
        let (a, b) = (&contact.a, &contact.b);
        let mut out = SMatrix::<f64, OUTPUTS, N>::zeros();
        out.row_mut(0).copy_from(&contact.geometry.distance.d);
        out.fixed_rows_mut::<3>(1)
            .copy_from(&a.v.add(&p.scale(&a.inv_mass)).d);
        out.fixed_rows_mut::<3>(4).copy_from(&a.w.add(turn_a).d);
        if let (Some(b), Some(turn_b)) = (b, turn_b) {
            out.fixed_rows_mut::<3>(7)
                .copy_from(&b.v.sub(&p.scale(&b.inv_mass)).d);
            out.fixed_rows_mut::<3>(10).copy_from(&b.w.sub(turn_b).d);
        }
        out
    }

    /// The impulse map's Jacobian with friction, in the friction mode
    /// [`ImpulseCtx::apply`] chose, by implicit differentiation: the
    /// mode's linear system `A(u) x = c(u)` (see [`FrictionSystem`]) is
    /// solved in plain numbers, and `dx = A⁻¹ (dc − (dA) x)`, where `(dA) x`
    /// is the derivative of the system's left-hand side at constant `x`.
    /// No matrix of jets is formed or inverted.
    fn friction_jet<const N: usize>(&self) -> SMatrix<f64, OUTPUTS, N> {
        let contact = self.jet_contact::<N>();
        let JetContact {
            n,
            a,
            b,
            v_rel,
            vn,
            sep,
            ..
        } = &contact;
        let mu = self.friction;
        let target = n.scale(sep).sub(v_rel);
        let vt = v_rel.sub(&n.scale(vn));
        // Sliding impulses push against the tangential velocity before
        // the impact: `P = P_n (n − μ t̂)`.
        let slide_dir =
            (vt.v.norm() != 0.0).then(|| n.sub(&vt.normalize().scale(&Sj::constant(mu))));
        let rho = &contact.geometry.spin_radius;
        let mut spin_rel = n.dot(&a.w);
        if let Some(b) = b {
            spin_rel = spin_rel.sub(&n.dot(&b.w));
        }
        let mode = self.mode;
        // The impulse slides only in a sliding mode with a sliding direction.
        let slide = slide_dir.filter(|_| !mode.stick);
        let spin = if rho.v <= 0.0 {
            Spin::Free
        } else if mode.spin_stick {
            Spin::Stick
        } else {
            Spin::Slide
        };
        let sigma = if spin_rel.v > 0.0 {
            1.0
        } else if spin_rel.v < 0.0 {
            -1.0
        } else {
            0.0
        };
        let g = rho.mul(&Sj::constant(-sigma * mu));
        let mut rhs = match &slide {
            Some(_) => vec![sep.sub(vn)],
            None => (0..3).map(|i| target.component(i)).collect(),
        };
        if spin == Spin::Stick {
            rhs.push(spin_rel.neg());
        }
        let system = FrictionSystem {
            n: *n,
            slide,
            spin,
            g,
        };
        // `A`, column by column, from the system in plain numbers (jets of
        // width 0); unused rows and columns of the 4×4 are the identity.
        let k = system.unknowns();
        let plain = system.as_constant::<0>();
        let (a0, b0) = (
            a.as_constant::<0>(),
            b.as_ref().map(|b| b.as_constant::<0>()),
        );
        let mut am = nalgebra::Matrix4::<f64>::identity();
        for col in 0..k {
            let x: Vec<Sj<0>> = (0..k)
                .map(|i| Sj::constant(if i == col { 1.0 } else { 0.0 }))
                .collect();
            let (p, tau) = plain.impulse(&x);
            let e = plain.equations(&response(&a0, b0.as_ref(), &plain.n, &p, &tau));
            for (row, ei) in e.iter().enumerate() {
                am[(row, col)] = ei.v;
            }
        }
        // As the model: a singular system gives no impulse.
        let a_inv = am.try_inverse().unwrap_or_else(nalgebra::Matrix4::zeros);
        let mut c = nalgebra::Vector4::zeros();
        let mut dc = SMatrix::<f64, 4, N>::zeros();
        for (row, ri) in rhs.iter().enumerate() {
            c[row] = ri.v;
            dc.set_row(row, &ri.d);
        }
        let x0 = a_inv * c;
        let xc: Vec<Sj<N>> = (0..k).map(|i| Sj::constant(x0[i])).collect();
        let (p, tau) = system.impulse(&xc);
        let lhs = system.equations(&response(a, b.as_ref(), n, &p, &tau));
        for (row, li) in lhs.iter().enumerate() {
            let mut r = dc.row_mut(row);
            r -= li.d;
        }
        let dx = a_inv * dc;
        let x: Vec<Sj<N>> = (0..k)
            .map(|i| Sj {
                v: x0[i],
                d: dx.row(i).into_owned(),
            })
            .collect();
        let (p, tau) = system.impulse(&x);
        let r = response(a, b.as_ref(), n, &p, &tau);
        Self::jet_outputs(&contact, &p, &r.turn_a, r.turn_b.as_ref())
    }

    fn jet<const N: usize>(&self) -> SMatrix<f64, OUTPUTS, N> {
        let contact = self.jet_contact::<N>();
        let JetContact {
            n, a, b, vn, sep, ..
        } = &contact;
        // Frictionless: p = j n with j = (sep − v_n) / (n·K n), and
        // `n·K n = 1/m_a + (r_a × n)·I_a⁻¹(r_a × n) (+ b's terms)`; each
        // party turns by `I⁻¹(r × n) j`.
        // A centred ball's lever `r × n` is zero in value and derivative
        // (see [`ImpulseCtx::central`]).
        let (central_a, central_b) = self.central();
        let lever = |party: &JetParty<N>, central: bool| {
            let c = if central {
                Vj::constant(Vec3::zeros())
            } else {
                party.r.cross(n)
            };
            let ic = party.inv_inertia_mul(&c);
            (party.inv_mass.add(&c.dot(&ic)), ic)
        };
        let (mut nkn, ic_a) = lever(a, central_a);
        let ic_b = b.as_ref().map(|b| {
            let (k, ic) = lever(b, central_b);
            nkn = nkn.add(&k);
            ic
        });
        let j = sep.sub(vn).div(&nkn);
        let p = n.scale(&j);
        let turn_a = ic_a.scale(&j);
        let turn_b = ic_b.map(|ic| ic.scale(&j));
        Self::jet_outputs(&contact, &p, &turn_a, turn_b.as_ref())
    }

    /// Jacobian of the generic model by forward-mode dual numbers (any
    /// friction mode); the reference the jet Jacobian is tested against.
    pub fn jacobian_dual(&self) -> DMatrix<f64> {
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
        let mode = Some(self.mode);
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
        self.model::<f64>(z, Some(self.mode)).0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::UnitQuaternion;

    fn party(x: [f64; 3], axisangle: [f64; 3], v: [f64; 3], w: [f64; 3]) -> PartyCtx {
        PartyCtx {
            state: BodyState {
                x: Vec3::from(x),
                q: UnitQuaternion::from_scaled_axis(Vec3::from(axisangle)),
                v: Vec3::from(v),
                w: Vec3::from(w),
            },
            mass: 0.7,
            principal: Vec3::new(0.011, 0.023, 0.029),
            axes: *UnitQuaternion::from_scaled_axis(Vec3::new(0.2, -0.1, 0.4))
                .to_rotation_matrix()
                .matrix(),
        }
    }

    fn point(p: [f64; 3], radius: f64) -> SideFeature {
        SideFeature::Point {
            p: Vec3::from(p),
            radius,
            vertices: Vec::new(),
        }
    }

    fn line(point: [f64; 3], dir: [f64; 3]) -> SideFeature {
        SideFeature::Line {
            point: Vec3::from(point),
            dir: Vec3::from(dir),
            vertices: [0, 1],
        }
    }

    fn plane(normal: [f64; 3], point: [f64; 3]) -> SideFeature {
        SideFeature::Plane {
            normal: Vec3::from(normal).normalize(),
            point: Vec3::from(point),
            vertices: Vec::new(),
        }
    }

    /// Contacts of every kind the jet path handles: a body's vertex on a
    /// tilted floor (with and without normal controls, and as a
    /// micro-collision on both sides of its floor), a ball on a body's
    /// face, two crossed edges, and two balls.
    pub(super) fn contexts() -> Vec<(&'static str, ImpulseCtx)> {
        let a = party(
            [0.1, 0.2, 0.35],
            [0.3, -0.2, 0.5],
            [0.4, -0.3, -2.5],
            [3.0, -1.0, 2.0],
        );
        let b = party(
            [0.12, 0.18, 0.0],
            [-0.1, 0.2, 0.1],
            [0.0, 0.1, 0.6],
            [-1.0, 2.0, 0.5],
        );
        let ctx = |feature: FeaturePair, b: Option<PartyCtx>| ImpulseCtx {
            feature,
            a: a.clone(),
            b,
            b_pose: Isometry3::rotation(Vec3::new(0.05, -0.03, 0.0)),
            restitution: 0.6,
            normal_dev: None,
            tangent_axis: Vec3::x(),
            friction: 0.0,
            mode: FrictionMode::default(),
            min_separation: None,
        };
        let pair = |fa, fb| FeaturePair {
            a: fa,
            b: fb,
            part_a: 0,
            part_b: 0,
            sign: 1.0,
            patch: Vec::new(),
            patch_depth: 0.0,
            patch_face: None,
        };
        let vertex_floor = ctx(
            pair(
                point([0.05, -0.1, -0.3], 0.0),
                plane([0.0, 0.0, 1.0], [0.0; 3]),
            ),
            None,
        );
        let mut controlled = vertex_floor.clone();
        controlled.normal_dev = Some([0.1, -0.2]);
        let mut micro_fast = vertex_floor.clone();
        micro_fast.min_separation = Some(1e-3);
        let mut micro_slow = vertex_floor.clone();
        micro_slow.min_separation = Some(10.0);
        let ball_face = ctx(
            pair(
                point([0.0, 0.0, -0.05], 0.3),
                plane([0.1, 0.0, 1.0], [0.0, 0.0, 0.02]),
            ),
            Some(b.clone()),
        );
        let edges = ctx(
            pair(
                line([0.0, 0.0, -0.2], [1.0, 0.2, 0.0]),
                line([0.0, 0.0, 0.15], [0.1, 1.0, 0.1]),
            ),
            Some(b.clone()),
        );
        let mut balls = ctx(pair(point([0.0; 3], 0.2), point([0.0; 3], 0.15)), Some(b));
        balls.normal_dev = Some([-0.05, 0.3]);
        vec![
            ("vertex on floor", vertex_floor),
            ("with normal controls", controlled),
            ("micro-collision, fast", micro_fast),
            ("micro-collision, slow", micro_slow),
            ("ball on a face", ball_face),
            ("crossed edges", edges),
            ("two balls", balls),
        ]
    }

    /// With friction, the geometry jets plus dual numbers over the model's
    /// inputs give the full dual-number Jacobian to round-off, for every
    /// contact kind and both input sets (all inputs, states only).
    #[test]
    fn the_friction_jacobian_equals_the_full_dual_number_jacobian() {
        for (name, mut ctx) in contexts() {
            if ctx.min_separation.is_some() {
                continue;
            }
            for mu in [0.05, 2.0] {
                ctx.friction = mu;
                ctx.apply();
                let (fast, dual) = (ctx.jacobian_friction(true), ctx.jacobian_dual());
                let scale = dual.norm();
                let err = (&fast - &dual).norm();
                assert!(err < 1e-12 * scale, "{name}, μ = {mu}: {err:.2e}");
                let n = if ctx.b.is_some() { 24 } else { 12 };
                let states = ctx.jacobian_friction(false);
                let err = (dual.columns(0, n) - &states).norm();
                assert!(err < 1e-12 * scale, "{name}, μ = {mu}, states: {err:.2e}");
            }
        }
    }

    /// Differentiated by the states only, the jet gives the state columns
    /// of the full Jacobian (parameters become constants, whatever they
    /// are: a controlled normal still tilts the impulse).
    #[test]
    fn the_state_only_jet_is_the_full_jets_state_columns() {
        for (name, ctx) in contexts() {
            let (full, states) = (ctx.jacobian(), ctx.jacobian_with(false));
            let n = if ctx.b.is_some() { 24 } else { 12 };
            assert_eq!(states.shape(), (OUTPUTS, n), "{name}");
            let err = (full.columns(0, n) - &states).norm() / full.norm();
            assert!(err < 1e-14, "{name}: {err:.2e}");
        }
    }

    /// The hand-written chain rule agrees with dual numbers through the
    /// generic model to round-off, for every input (state, normal
    /// deviation, restitution, masses, inertias).
    #[test]
    fn the_jet_jacobian_equals_the_dual_number_jacobian() {
        for (name, ctx) in contexts() {
            let (jet, dual) = (ctx.jacobian_jet(), ctx.jacobian_dual());
            let scale = dual.norm();
            assert!(scale > 1.0, "{name}: a degenerate case");
            for c in 0..dual.ncols() {
                let err = (jet.column(c) - dual.column(c)).norm();
                assert!(
                    err < 1e-12 * scale,
                    "{name}, input {c}: {err:.2e}\n{}\n{}",
                    jet.column(c).transpose(),
                    dual.column(c).transpose()
                );
            }
        }
    }

    /// And both are the derivative of the map that is applied: central
    /// differences of `evaluate`, with the rotation inputs perturbing the
    /// orientation as the model does.
    #[test]
    fn the_impulse_jacobian_matches_central_differences() {
        for (name, ctx) in contexts() {
            assert_matches_central_differences(&ctx, name);
        }
    }

    /// `ctx.jacobian()` against central differences of `ctx.evaluate`
    /// (in the friction mode `ctx` decided), every output and input.
    pub(super) fn assert_matches_central_differences(ctx: &ImpulseCtx, name: &str) {
        let j = ctx.jacobian();
        let z = ctx.input();
        for c in 0..z.len() {
            let h = 1e-6 * z[c].abs().max(1.0);
            let (mut zp, mut zm) = (z.clone(), z.clone());
            zp[c] += h;
            zm[c] -= h;
            let (fp, fm) = (ctx.evaluate(&zp), ctx.evaluate(&zm));
            for r in 0..OUTPUTS {
                let fd = (fp[r] - fm[r]) / (2.0 * h);
                // The model perturbs rotations to first order only, so
                // compare at the finite-difference error level.
                assert!(
                    (fd - j[(r, c)]).abs() < 1e-6 * (1.0 + fd.abs()),
                    "{name}: ∂out{r}/∂in{c}: {fd} vs {}",
                    j[(r, c)]
                );
            }
        }
    }
}

/// Friction at a contact patch: the impulse and the couple that resists
/// spin about the normal, in each of their four modes.
#[cfg(test)]
mod patch_friction {
    use super::*;
    use crate::geometry::{Corner, PatchCorner, SideFeature};
    use nalgebra::UnitQuaternion;

    const HALF: f64 = 0.05;

    /// A 10 cm box's bottom face landing nearly flat on a floor with
    /// friction `mu`, falling at 2 m/s, sliding at `slide` m/s along x and
    /// spinning at `spin` rad/s about the vertical.
    fn landing(mu: f64, slide: f64, spin: f64) -> ImpulseCtx {
        let a = PartyCtx {
            state: BodyState {
                x: Vec3::new(0.0, 0.0, HALF),
                q: UnitQuaternion::from_scaled_axis(Vec3::new(0.002, -0.001, 0.3)),
                v: Vec3::new(slide, 0.0, -2.0),
                w: Vec3::new(0.1, -0.2, spin),
            },
            mass: 1.0,
            principal: Vec3::new(0.0017, 0.0016, 0.0015),
            axes: Mat3::identity(),
        };
        let bottom = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
        let corners = bottom
            .iter()
            .enumerate()
            .map(|(index, &(sx, sy))| PatchCorner {
                corner: Corner::A {
                    index,
                    p: Vec3::new(sx * HALF, sy * HALF, -HALF),
                },
                face_on_a: false,
                face_normal: Vec3::z(),
                face_point: Vec3::zeros(),
            })
            .collect();
        let touching = FeaturePair {
            a: SideFeature::Point {
                p: Vec3::new(HALF, HALF, -HALF),
                radius: 0.0,
                vertices: Vec::new(),
            },
            b: SideFeature::Plane {
                normal: Vec3::z(),
                point: Vec3::zeros(),
                vertices: Vec::new(),
            },
            part_a: 0,
            part_b: 0,
            sign: 1.0,
            patch: Vec::new(),
            patch_depth: 0.0,
            patch_face: None,
        };
        ImpulseCtx {
            feature: touching.at_patch(corners, 0.01, (false, Vec3::z())),
            a,
            b: None,
            b_pose: Isometry3::identity(),
            restitution: 0.3,
            normal_dev: None,
            tangent_axis: Vec3::x(),
            friction: mu,
            mode: FrictionMode::default(),
            min_separation: None,
        }
    }

    /// Relative spin about the normal and tangential contact velocity after
    /// the impulse, the normal impulse and the couple.
    fn after(ctx: &ImpulseCtx, res: &ImpulseResult) -> (f64, f64, f64, f64) {
        let a = &ctx.a;
        let pn = res.normal.dot(&res.impulse);
        let r = res.point - a.state.x;
        let inertia = {
            let rq = a.state.q.to_rotation_matrix().matrix() * a.axes;
            rq * Mat3::from_diagonal(&a.principal) * rq.transpose()
        };
        // ΔL = r × P + τ n, so τ = n · (I Δω − r × P).
        let tau = res
            .normal
            .dot(&(inertia * (res.wa - a.state.w) - r.cross(&res.impulse)));
        let u = res.va + res.wa.cross(&r);
        let ut = (u - res.normal * res.normal.dot(&u)).norm();
        (res.normal.dot(&res.wa), ut, pn, tau)
    }

    #[test]
    fn each_friction_mode_obeys_its_cone_and_stops_what_it_holds() {
        let cases = [
            ("stick/stick", 0.8, 0.1, 2.0, true, true),
            ("stick/slide", 0.8, 0.1, 200.0, true, false),
            ("slide/stick", 0.2, 3.0, 0.5, false, true),
            ("slide/slide", 0.2, 3.0, 40.0, false, false),
        ];
        for (name, mu, slide, spin, stick, spin_stick) in cases {
            let mut ctx = landing(mu, slide, spin);
            let res = ctx.apply();
            assert_eq!(
                ctx.mode,
                FrictionMode { stick, spin_stick },
                "{name}: the mode decided"
            );
            let (spin_after, ut, pn, tau) = after(&ctx, &res);
            assert!(pn > 0.0, "{name}: P_n = {pn}");
            let rho = ctx
                .feature
                .evaluate(
                    &PoseT::from_isometry(&Isometry3::from_parts(
                        ctx.a.state.x.into(),
                        ctx.a.state.q,
                    )),
                    &PoseT::from_isometry(&ctx.b_pose),
                )
                .spin_radius;
            assert!((rho - HALF * 2f64.sqrt()).abs() < 1e-3, "{name}: ρ = {rho}");
            let limit = mu * rho * pn;
            if spin_stick {
                assert!(spin_after.abs() < 1e-12, "{name}: spin left {spin_after}");
                assert!(
                    tau.abs() <= limit * (1.0 + 1e-12),
                    "{name}: {tau} > {limit}"
                );
            } else {
                assert!(
                    (tau.abs() - limit).abs() < 1e-9 * limit,
                    "{name}: {tau} vs {limit}"
                );
                assert!(tau * spin < 0.0, "{name}: the couple opposes the spin");
                assert!(
                    spin_after * spin > 0.0,
                    "{name}: a sliding couple does not reverse the spin"
                );
            }
            let pt = (res.impulse - res.normal * pn).norm();
            if stick {
                assert!(ut < 1e-9, "{name}: still sliding at {ut}");
                assert!(pt <= mu * pn * (1.0 + 1e-12), "{name}: outside the cone");
            } else {
                assert!(
                    (pt - mu * pn).abs() < 1e-9 * pn,
                    "{name}: |P_t| {pt} vs μP_n {}",
                    mu * pn
                );
            }
            let energy = |v: &Vec3, w: &Vec3| {
                let rq = ctx.a.state.q.to_rotation_matrix().matrix() * ctx.a.axes;
                let inertia = rq * Mat3::from_diagonal(&ctx.a.principal) * rq.transpose();
                0.5 * ctx.a.mass * v.norm_squared() + 0.5 * w.dot(&(inertia * w))
            };
            let (before, now) = (
                energy(&ctx.a.state.v, &ctx.a.state.w),
                energy(&res.va, &res.wa),
            );
            assert!(
                now <= before * (1.0 + 1e-12),
                "{name}: energy {before} -> {now}"
            );
            assert!(
                (res.separation + ctx.restitution * res.approach).abs() < 1e-9,
                "{name}: separation {} approach {}",
                res.separation,
                res.approach
            );
        }
    }

    /// Every mode's Jacobian (the fast path the simulator takes and the full
    /// dual-number reference) matches central differences of the map that
    /// is applied.
    #[test]
    fn the_patch_friction_jacobian_matches_central_differences() {
        for (mu, slide, spin) in [
            (0.8, 0.1, 2.0),
            (0.8, 0.1, 200.0),
            (0.2, 3.0, 0.5),
            (0.2, 3.0, 40.0),
        ] {
            let mut ctx = landing(mu, slide, spin);
            ctx.apply();
            let j = ctx.jacobian();
            let dual = ctx.jacobian_dual();
            assert!((&j - &dual).norm() < 1e-12 * dual.norm(), "{:?}", ctx.mode);
            super::tests::assert_matches_central_differences(&ctx, &format!("{:?}", ctx.mode));
        }
    }

    /// Implicit differentiation of each friction mode's linear system
    /// gives the dual-number derivative of the model, in every mode: the
    /// one `apply` decides and the others, forced (a mode's system is
    /// well-posed away from its cone too). Patch landings (six systems) and
    /// the one-point contexts of the frictionless tests, with all inputs
    /// and with the states only.
    #[test]
    fn every_friction_modes_jacobian_equals_the_dual_number_jacobian() {
        let mut cases: Vec<(String, ImpulseCtx)> = super::tests::contexts()
            .into_iter()
            .filter(|(_, c)| c.min_separation.is_none())
            .map(|(name, mut c)| {
                c.friction = 0.4;
                (name.to_string(), c)
            })
            .collect();
        cases.push(("patch landing".into(), landing(0.3, 1.5, 20.0)));
        let mut modes_seen = 0;
        for (name, mut ctx) in cases {
            ctx.apply();
            for (stick, spin_stick) in [(true, true), (true, false), (false, true), (false, false)]
            {
                ctx.mode = FrictionMode { stick, spin_stick };
                let dual = ctx.jacobian_dual();
                let scale = dual.norm();
                let err = (ctx.jacobian_friction(true) - &dual).norm();
                assert!(err < 1e-12 * scale, "{name}, {:?}: {err:.2e}", ctx.mode);
                let n = if ctx.b.is_some() { 24 } else { 12 };
                let err = (ctx.jacobian_friction(false) - dual.columns(0, n)).norm();
                assert!(
                    err < 1e-12 * scale,
                    "{name}, {:?}, states: {err:.2e}",
                    ctx.mode
                );
                modes_seen += 1;
            }
        }
        assert!(modes_seen >= 4 * 6);
    }

    /// Without the friction effect a patch resists no spin, and with
    /// friction a one-point contact has no torsional lever: the couple is
    /// zero and the spin about the normal passes through unchanged.
    #[test]
    fn no_spin_friction_without_friction_or_without_a_patch() {
        let mut frictionless = landing(0.0, 0.1, 2.0);
        let res = frictionless.apply();
        let (_, _, _, tau) = after(&frictionless, &res);
        assert!(tau.abs() < 1e-12, "frictionless couple {tau}");
        let mut point = landing(0.8, 0.1, 2.0);
        point.feature.patch.clear();
        point.feature.patch_face = None;
        let res = point.apply();
        let (_, _, _, tau) = after(&point, &res);
        assert!(tau.abs() < 1e-12, "one-point couple {tau}");
    }
}
