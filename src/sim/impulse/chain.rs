//! The impulse map's Jacobian: the hand-written chain rule on jets
//! (frictionless, and with friction implicitly through the friction
//! mode's linear system), the contact geometry's jets, and the dual-number
//! reference they are tested against.

use super::*;
use num_dual::Derivative;

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
    pub(super) fn central(&self) -> (bool, bool) {
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
