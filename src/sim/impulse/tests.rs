//! Tests of the impulse map and its Jacobians.

use super::*;

mod basics {
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
            super::basics::assert_matches_central_differences(&ctx, &format!("{:?}", ctx.mode));
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
        let mut cases: Vec<(String, ImpulseCtx)> = super::basics::contexts()
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
