//! Rotation: long spins, the exponential map's switch, the intermediate axis.

use super::*;

/// Rotation angle between two orientations, rad.
fn angle(a: &nalgebra::UnitQuaternion<f64>, b: &nalgebra::UnitQuaternion<f64>) -> f64 {
    (a * b.inverse()).angle()
}

/// 100 revolutions at constant ω: the integrated orientation matches
/// exp(ω t) R₀ to 1e-9 rad, with the fixed-step and the adaptive
/// integrator.
#[test]
fn a_hundred_revolutions_at_constant_spin_match_the_analytic_rotation() {
    for adaptive in [false, true] {
        let mut s = load("spin.toml");
        if adaptive {
            s.accuracy.method = nudge::scene::Method::Adaptive {
                tol: 1e-10,
                max_step: 0.05,
            };
        }
        let q0 = nudge::math::exp_so3(&s.bodies[0].orientation);
        let w = q0 * (s.bodies[0].inertia_axes * Vec3::new(0.0, 0.0, 2.0 * std::f64::consts::PI));
        s.bodies[0].angular_velocity = w;
        let tr = run_ok(&s);
        assert!(tr.counters.gyroscopic.get() > 0, "rotation is integrated");
        let mut worst: f64 = 0.0;
        for k in 0..=200 {
            let t = s.duration * k as f64 / 200.0;
            let exact = nudge::math::exp_so3(&(w * t)) * q0;
            worst = worst.max(angle(&tr.state(0, t, Side::Post).q, &exact));
        }
        assert!(
            worst < 1e-9,
            "adaptive={adaptive}: orientation error {worst:.3e} rad"
        );
        eprintln!("expmap 100 revs (adaptive={adaptive}): orientation error {worst:.2e} rad");
    }
}

/// Nudging an orientation control past π keeps |r| ≤ π after every
/// reparameterisation, and the body really turns by each nudge.
#[test]
fn an_orientation_control_pushed_past_pi_is_reparameterised_and_follows_the_nudges() {
    use nudge::edit::{Core, Edit, Editor};
    use nudge::scene::StateQuantity;
    let s = load("expmap-pi.toml");
    let mut e = Editor::new(s, None).unwrap();
    e.apply(Edit::SelectTime(0.0)).unwrap();
    let step = Vec3::new(0.25, 0.0, 0.0);
    let mut crossed = 0;
    let mut prev = e.scene().bodies[0].orientation;
    for k in 0..10 {
        let target = nudge::math::exp_so3(&step) * e.trajectory().state(0, 0.0, Side::Post).q;
        e.apply(Edit::Nudge {
            quantity: StateQuantity::Orientation,
            delta: step,
        })
        .unwrap();
        let r = e.scene().bodies[0].orientation;
        assert!(
            r.norm() <= std::f64::consts::PI + 1e-12,
            "nudge {k}: |r| = {}",
            r.norm()
        );
        if r.dot(&prev) < 0.0 {
            crossed += 1;
        }
        prev = r;
        let got = e.trajectory().state(0, 0.0, Side::Post).q;
        assert!(
            angle(&got, &target) < 1e-6,
            "nudge {k}: off by {:.2e} rad",
            angle(&got, &target)
        );
    }
    assert!(crossed >= 1, "the nudges carried r past π");
}

/// The orientation Jacobian matches central differences on both sides of
/// the switch at |r| = π (3.14 and its reparameterised twin).
#[test]
fn the_jacobian_matches_finite_differences_across_the_exponential_map_switch() {
    use nudge::tangent::{FiniteDifference, Scheme, max_relative_error};
    let axis = Vec3::new(1.0, 0.4, -0.2).normalize();
    for len in [std::f64::consts::PI - 1e-3, std::f64::consts::PI + 1e-3] {
        let mut s = load("expmap-pi.toml");
        let (r, switched) = nudge::math::reparameterize(&(axis * len));
        assert_eq!(switched, len > std::f64::consts::PI);
        s.bodies[0].orientation = r;
        s.accuracy.root_tol = 1e-14;
        let controls = Controls::new(&s);
        let tr = simulate(&s, &controls, &SimOptions::default()).unwrap();
        let fd = FiniteDifference::new(&s, &controls, Scheme::Central).unwrap();
        let mut worst: f64 = 0.0;
        for t in [0.2, 0.5, 0.9] {
            let mask = fd.comparable_until(t);
            assert!(
                mask[3..6].iter().all(|c| *c),
                "orientation columns comparable at {t}"
            );
            let jt = tr.jacobian(0, t, Side::Post).unwrap();
            let err = max_relative_error(&jt, &fd.at(0, t, Side::Post), &mask, 1e-3);
            worst = worst.max(err);
        }
        assert!(worst < 1e-6, "|r| = {len}: tangent vs FD {worst:.2e}");
        eprintln!(
            "expmap |r| = {len:.4} (switched {}): tangent vs FD {worst:.2e}",
            len > std::f64::consts::PI
        );
    }
}

/// A million RK4 steps of a tumbling body: the quaternion stays unit to
/// 1e-12 (the simulator's own step, update and renormalisation).
#[test]
fn a_million_steps_keep_the_quaternion_unit() {
    let s = load("spin.toml");
    let d = nudge::sim::BodyDynamics::new(&s, 0, &Controls::new(&s));
    assert!(d.integrate);
    let q0 = nudge::math::exp_so3(&s.bodies[0].orientation);
    // Tumbling about no principal axis: ω changes every step.
    let mut worst: f64 = 0.0;
    let (q, _) = nudge::sim::free_rotation(
        &d,
        q0,
        &Vec3::new(1.0, 3.0, -2.0),
        1e-3,
        1_000_000,
        |_, q, _| {
            worst = worst.max((q.coords.norm() - 1.0).abs());
        },
    );
    assert!(worst < 1e-12, "|q| drifted by {worst:.2e}");
    assert!(q.coords.iter().all(|v| v.is_finite()));
    eprintln!("quaternion drift over 1e6 steps: {worst:.2e}");
}

/// The T-handle spun about its intermediate axis flips periodically with
/// energy and |L| conserved to 1e-6 over 100 s; about the major or minor
/// axis it keeps spinning the same way.
#[test]
fn a_t_handle_flips_about_its_intermediate_axis_and_not_the_others() {
    for axis in [1usize, 0, 2] {
        let mut s = load("t-handle.toml");
        let b = &s.bodies[0];
        let frame = nudge::math::exp_so3(&b.orientation) * b.inertia_axes;
        let mut wp = Vec3::repeat(1e-3);
        wp[axis] = 6.0;
        s.bodies[0].angular_velocity = frame * wp;
        let axes = s.bodies[0].inertia_axes;
        let tr = run_ok(&s);
        let d = &tr.dynamics[0];
        let invariants = |t: f64| {
            let st = tr.state(0, t, Side::Post);
            let r = *st.q.to_rotation_matrix().matrix();
            let l = r * d.inertia * r.transpose() * st.w;
            (0.5 * st.w.dot(&l), l.norm(), (st.q * axes).inverse() * st.w)
        };
        let (e0, l0, _) = invariants(0.0);
        let mut flips = Vec::new();
        let mut last_sign = 1.0;
        let mut min_along = f64::INFINITY;
        let mut drift: f64 = 0.0;
        let n = 20_000;
        for k in 0..=n {
            let t = s.duration * k as f64 / n as f64;
            let (e, l, wb) = invariants(t);
            drift = drift.max(((e - e0) / e0).abs()).max(((l - l0) / l0).abs());
            min_along = min_along.min(wb[axis] / 6.0);
            if wb[axis] * last_sign < 0.0 {
                flips.push(t);
                last_sign = -last_sign;
            }
        }
        assert!(
            drift < 1e-6,
            "axis {axis}: energy/momentum drift {drift:.2e}"
        );
        if axis == 1 {
            assert!(flips.len() >= 4, "intermediate axis flips: {flips:?}");
            let gaps: Vec<f64> = flips.windows(2).map(|w| w[1] - w[0]).collect();
            let mean = gaps.iter().sum::<f64>() / gaps.len() as f64;
            assert!(
                gaps.iter().all(|g| (g - mean).abs() < 0.05 * mean),
                "periodic: {gaps:?}"
            );
            eprintln!(
                "t-handle intermediate: {} flips, period {:.4} s, drift {drift:.1e}",
                flips.len(),
                2.0 * mean
            );
        } else {
            assert!(
                flips.is_empty() && min_along > 0.99,
                "axis {axis}: flips {flips:?}, min {min_along}"
            );
            eprintln!(
                "t-handle axis {axis}: no flip, spin component ≥ {min_along:.6} of initial, drift {drift:.1e}"
            );
        }
    }
}

// ---------------------------------------------------------------------------
// Chaotic horizons.
// ---------------------------------------------------------------------------
