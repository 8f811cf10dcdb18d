//! The simulator against closed forms and conservation laws.

use nudge::controls::Controls;
use nudge::geometry::Geometry;
use nudge::math::Vec3;
use nudge::sim::{SimOptions, StateSide, simulate};
use nudge::testkit::{self, body, body_with_inertia, ground};

fn run(scene: &nudge::scene::Scene) -> nudge::sim::Trajectory {
    let controls = Controls::new(scene);
    simulate(
        scene,
        &controls,
        &SimOptions {
            tangent: false,
            ..SimOptions::default()
        },
    )
    .expect("simulates")
}

#[test]
fn ballistic_flight_matches_the_closed_form() {
    let mut s = testkit::scene(2.0);
    let mut b = body(
        "ball",
        Geometry::sphere(0.1).unwrap(),
        Vec3::new(0.0, 0.0, 10.0),
    );
    b.velocity = Vec3::new(1.0, -2.0, 3.0);
    s.bodies.push(b);
    let tr = run(&s);
    for t in [0.0, 0.37, 1.0, 2.0] {
        let st = tr.state(0, t, StateSide::After);
        let exact = Vec3::new(t, -2.0 * t, 10.0 + 3.0 * t - 0.5 * 9.81 * t * t);
        assert!((st.x - exact).norm() < 1e-12, "t={t}");
        assert!((st.v - Vec3::new(1.0, -2.0, 3.0 - 9.81 * t)).norm() < 1e-12);
    }
    assert!(tr.events.is_empty());
}

#[test]
fn bouncing_ball_follows_the_geometric_series_and_rests_on_time() {
    let e: f64 = 0.8;
    let h0: f64 = 1.0;
    let r = 0.1;
    let g = 9.81;
    let mut s = testkit::scene(6.0);
    let mut b = body(
        "ball",
        Geometry::sphere(r).unwrap(),
        Vec3::new(0.0, 0.0, h0 + r),
    );
    b.restitution = e;
    s.bodies.push(b);
    s.obstacles.push(ground());
    let tr = run(&s);
    let t0 = (2.0 * h0 / g).sqrt();
    let v0 = g * t0;
    let mut expected = t0;
    for (k, ev) in tr.events.iter().enumerate() {
        if ev.rest {
            break;
        }
        assert!(
            (ev.t - expected).abs() < 1e-9,
            "bounce {k}: {} vs {expected}",
            ev.t
        );
        expected += 2.0 * v0 * e.powi(k as i32 + 1) / g;
    }
    let last = tr.events.last().expect("bounces");
    assert!(last.rest, "the ball comes to rest");
    let total = t0 * (1.0 + e) / (1.0 - e);
    let rest_time = last.rest_time.expect("rest time");
    assert!(
        (rest_time - total).abs() < 1e-6,
        "rest at {rest_time}, series limit {total}"
    );
    let end = tr.state(0, 6.0, StateSide::After);
    assert!(end.x.z > r - 1e-9 && end.v.norm() == 0.0);
}

/// A symmetric top (I₁ = I₂) precesses about its angular momentum: in the
/// body frame ω rotates about the symmetry axis at Ω = (I₃ − I₁)/I₁ ω₃.
#[test]
fn torque_free_symmetric_top_matches_analytic_precession() {
    for adaptive in [false, true] {
        let mut s = testkit::scene(5.0);
        s.effects = nudge::scene::Effects {
            gyroscopic: true,
            ..Default::default()
        };
        if adaptive {
            testkit::adaptive(&mut s, 1e-11);
        }
        let (i1, i3) = (1.0, 2.0);
        let mut b = body_with_inertia(
            "top",
            Geometry::cuboid(Vec3::new(0.5, 0.5, 0.2)).unwrap(),
            Vec3::zeros(),
            1.0,
            Vec3::new(i1, i1, i3),
        );
        let w0 = Vec3::new(0.3, 0.0, 2.0);
        b.angular_velocity = w0;
        s.bodies.push(b);
        let tr = run(&s);
        let omega = (i3 - i1) / i1 * w0.z;
        for t in [0.5, 2.0, 5.0] {
            let st = tr.state(0, t, StateSide::After);
            let wb = st.q.inverse() * st.w;
            let exact = Vec3::new(0.3 * (omega * t).cos(), 0.3 * (omega * t).sin(), 2.0);
            assert!(
                (wb - exact).norm() < 1e-7,
                "adaptive={adaptive} t={t}: {wb:?} vs {exact:?}"
            );
            // Angular momentum in the world is fixed.
            let l0 = Vec3::new(i1 * 0.3, 0.0, i3 * 2.0);
            let lw = st.q * (nalgebra::Matrix3::from_diagonal(&Vec3::new(i1, i1, i3)) * wb);
            assert!((lw - l0).norm() < 1e-7);
        }
        assert!(tr.counters.gyroscopic.get() > 0);
    }
}

#[test]
fn asymmetric_body_conserves_energy_and_momentum_over_100_s() {
    let mut s = testkit::scene(100.0);
    s.effects = nudge::scene::Effects {
        gyroscopic: true,
        ..Default::default()
    };
    let inertia = Vec3::new(1.0, 2.0, 3.0);
    let mut b = body_with_inertia(
        "box",
        Geometry::cuboid(Vec3::new(0.3, 0.2, 0.1)).unwrap(),
        Vec3::zeros(),
        1.0,
        inertia,
    );
    b.angular_velocity = Vec3::new(0.1, 3.0, 0.2);
    s.bodies.push(b);
    s.accuracy.method = nudge::scene::Method::Rk4 { step: 1e-3 };
    let tr = run(&s);
    let energy = |t: f64| {
        let st = tr.state(0, t, StateSide::After);
        let wb = st.q.inverse() * st.w;
        (
            0.5 * wb.component_mul(&inertia).dot(&wb),
            (st.q * wb.component_mul(&inertia)).norm(),
        )
    };
    let (e0, l0) = energy(0.0);
    for t in [10.0, 50.0, 100.0] {
        let (e, l) = energy(t);
        assert!(
            ((e - e0) / e0).abs() < 1e-6,
            "energy drift at {t}: {}",
            (e - e0) / e0
        );
        assert!(((l - l0) / l0).abs() < 1e-6, "momentum drift at {t}");
    }
}

#[test]
fn body_body_impacts_conserve_momentum_and_never_gain_energy() {
    for ratio in [1e-6, 1e-3, 1.0, 1e3, 1e6] {
        for e in [0.0, 0.5, 1.0] {
            // Stop before the spinning box, pushed along by the ball, meets it again.
            let mut s = testkit::scene(0.42);
            s.effects = nudge::scene::Effects {
                collisions: true,
                ..Default::default()
            };
            let mut a = body_with_inertia(
                "a",
                Geometry::cuboid(Vec3::new(0.2, 0.15, 0.1)).unwrap(),
                Vec3::new(-1.0, 0.05, 0.02),
                1.0,
                Vec3::new(0.01, 0.02, 0.025),
            );
            let mut b = body_with_inertia(
                "b",
                Geometry::sphere(0.2).unwrap(),
                Vec3::new(1.0, 0.0, 0.0),
                ratio,
                Vec3::repeat(0.016 * ratio),
            );
            a.velocity = Vec3::new(3.0, 0.0, 0.0);
            a.angular_velocity = Vec3::new(0.0, 0.0, 1.0);
            b.velocity = Vec3::new(-1.0, 0.0, 0.0);
            a.restitution = e;
            b.restitution = 1.0;
            s.bodies.push(a);
            s.bodies.push(b);
            s.pairs.push([0, 1]);
            let tr = run(&s);
            assert!(!tr.events.is_empty(), "ratio {ratio}: they collide");
            let ev = &tr.events[0];
            let (m1, m2) = (1.0, ratio);
            let p = |i: usize, st: &[nudge::sim::BodyState; 2]| {
                st[0].v * m1 * (1 - i) as f64 + st[1].v * m2 * i as f64
            };
            let before = p(0, &ev.pre) + p(1, &ev.pre);
            let after = p(0, &ev.post) + p(1, &ev.post);
            assert!(
                (before - after).norm() <= 1e-9 * (m1 + m2) * 3.0,
                "ratio {ratio} e {e}: momentum {before:?} → {after:?}"
            );
            let ke = |st: &[nudge::sim::BodyState; 2]| {
                let ia = nudge::math::Vec3::new(0.01, 0.02, 0.025);
                let wa = st[0].q.inverse() * st[0].w;
                0.5 * m1 * st[0].v.norm_squared()
                    + 0.5 * wa.component_mul(&ia).dot(&wa)
                    + 0.5 * m2 * st[1].v.norm_squared()
                    + 0.5 * 0.016 * ratio * st[1].w.norm_squared()
            };
            let (k0, k1) = (ke(&ev.pre), ke(&ev.post));
            assert!(
                k1 <= k0 * (1.0 + 1e-12),
                "ratio {ratio} e {e}: energy {k0} → {k1}"
            );
        }
    }
}

/// A spinning box pressed inelastically against a heavy ball keeps
/// re-colliding: the simulator stops with a typed error instead of looping.
#[test]
fn sustained_body_contact_is_reported_not_looped() {
    let mut s = testkit::scene(1.0);
    s.effects = nudge::scene::Effects {
        collisions: true,
        ..Default::default()
    };
    let mut a = body_with_inertia(
        "a",
        Geometry::cuboid(Vec3::new(0.2, 0.15, 0.1)).unwrap(),
        Vec3::new(-1.0, 0.05, 0.02),
        1.0,
        Vec3::new(0.01, 0.02, 0.025),
    );
    let mut b = body_with_inertia(
        "b",
        Geometry::sphere(0.2).unwrap(),
        Vec3::new(1.0, 0.0, 0.0),
        1e6,
        Vec3::repeat(0.016e6),
    );
    a.velocity = Vec3::new(3.0, 0.0, 0.0);
    a.angular_velocity = Vec3::new(0.0, 0.0, 1.0);
    a.restitution = 0.0;
    b.velocity = Vec3::new(-1.0, 0.0, 0.0);
    s.bodies.push(a);
    s.bodies.push(b);
    s.pairs.push([0, 1]);
    let err = simulate(
        &s,
        &Controls::new(&s),
        &SimOptions {
            tangent: false,
            ..SimOptions::default()
        },
    )
    .unwrap_err();
    assert!(
        matches!(err, nudge::sim::SimError::SustainedContact { .. }),
        "{err}"
    );
    assert!(
        err.to_string().contains("\"a\" and \"b\" stay in contact"),
        "{err}"
    );
}
