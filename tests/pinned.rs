//! A corner that friction holds is pinned (docs/design.md §4,
//! `sim::pivot::skid`): the body turns about it as a ball joint instead
//! of hopping on it in micro-collisions.

use nudge::controls::Controls;
use nudge::geometry::Geometry;
use nudge::math::Vec3;
use nudge::scene::Scene;
use nudge::sim::{PivotEnd, Side, SimOptions, simulate};
use nudge::testkit;

/// A square pyramid (10 cm base, 15 cm high) stood on its apex, tilted
/// 0.05 rad about x, set down 1 µm above a floor with friction 1.
fn pyramid() -> Scene {
    let mut s = testkit::on_ground(1.0, 1.0);
    let corners = [
        Vec3::new(0.05, 0.05, 0.0),
        Vec3::new(-0.05, 0.05, 0.0),
        Vec3::new(-0.05, -0.05, 0.0),
        Vec3::new(0.05, -0.05, 0.0),
        Vec3::new(0.0, 0.0, -0.15),
    ];
    let g = Geometry::convex_hull(&corners).unwrap();
    let com = g.mass_properties(1000.0).unwrap().com;
    let tilt = 0.05_f64;
    let apex = 0.15 + com.z;
    let mut b = testkit::body("pyramid", g, Vec3::new(0.0, 0.0, 1e-6 + apex * tilt.cos()));
    b.orientation = Vec3::new(tilt, 0.0, 0.0);
    b.friction = 1.0;
    b.restitution = 0.2;
    s.bodies.push(b);
    s
}

/// The apex from the centre of mass, body frame, m.
fn apex(s: &Scene) -> Vec3 {
    s.bodies[0].geometry.parts[0]
        .vertices()
        .into_iter()
        .min_by(|a, b| a.z.total_cmp(&b.z))
        .unwrap()
}

/// From its first contact the pyramid turns about its pinned apex: the
/// apex stays where it landed, at rest, the joint does no work, and the
/// fall is the inverted compound pendulum's — it reaches its final tilt
/// at the time of the energy integral `t = ∫ dθ / θ̇(θ)`, and slips where
/// that pendulum's contact force leaves the friction cone.
#[test]
fn a_pyramid_on_its_apex_falls_about_it_as_a_pendulum_until_it_slips() {
    let s = pyramid();
    let tr = simulate(&s, &Controls::new(&s), &SimOptions::default()).unwrap();
    let seg = tr.tracks[0]
        .segments
        .iter()
        .find(|seg| seg.pivot.is_some())
        .unwrap();
    let pv = seg.pivot.as_deref().unwrap();
    assert!(pv.pinned(), "the apex is pinned: {:?}", tr.signature());
    assert_eq!(pv.end, PivotEnd::Slips);
    assert_eq!(seg.t0, tr.events[0].t, "pinned from the first contact");
    let (t0, t1) = (seg.t0, seg.t0 + pv.duration);
    let tip = apex(&s);
    let anchor = seg.start.point(&tip);
    let d = &tr.dynamics[0];
    let scale = d.mass * 9.81 * 0.15;
    let e0 = testkit::energy(&tr, 0, t0);
    assert!(
        seg.start.point_velocity(&tip).norm() < 1e-12,
        "the apex is not stopped"
    );
    for k in 1..=200 {
        let t = t0 + (t1 - t0) * f64::from(k) / 200.0;
        let st = tr.state(0, t, Side::Post);
        let moved = (st.point(&tip) - anchor).norm();
        assert!(moved < 1e-12, "the apex moved by {moved:.2e} m at t = {t}");
        let u = st.point_velocity(&tip).norm();
        assert!(u < 1e-12, "the apex moves at {u:.2e} m/s at t = {t}");
        let off = st.w.y.abs() + st.w.z.abs();
        assert!(
            off < 1e-12,
            "the fall leaves its plane ({off:.2e} rad/s) at t = {t}"
        );
        let de = (testkit::energy(&tr, 0, t) - e0).abs() / scale;
        assert!(de < 1e-9, "energy changed by {de:.2e} of m g h at t = {t}");
    }
    // The pendulum about the apex: θ̈ = (m g L / I) sin θ from the vertical.
    let (m, g, l) = (d.mass, 9.81, tip.norm());
    let i = d.inertia[(0, 0)] + m * l * l;
    let tilt = |t: f64| {
        let st = tr.state(0, t, Side::Post);
        let up = st.q * Vec3::z();
        up.y.atan2(up.z).abs()
    };
    let (th0, th1) = (tilt(t0), tilt(t1));
    let w0 = seg.start.w.x.abs();
    let rate = |th: f64| (w0 * w0 + 2.0 * m * g * l / i * (th0.cos() - th.cos())).sqrt();
    // θ = θ₀ + u²: the integrand 2u / θ̇ stays finite where θ̇ is small.
    let n = 200_000;
    let du = (th1 - th0).sqrt() / f64::from(n);
    let t_fall: f64 = (0..n)
        .map(|k| {
            let u = (f64::from(k) + 0.5) * du;
            2.0 * u / rate(th0 + u * u) * du
        })
        .sum();
    assert!(
        (pv.duration - t_fall).abs() < 1e-8,
        "tilts to {th1} rad in {} s, the pendulum in {t_fall} s",
        pv.duration
    );
    // Where it slips, the pendulum's contact force is on the cone's edge:
    // along the fall m l θ̈ and m l θ̇² towards the apex.
    let (w, acc) = (rate(th1), m * g * l / i * th1.sin());
    let along = m * l * acc;
    let inward = m * l * w * w;
    // Force on the body = m a − m g, resolved vertically and horizontally.
    let (s1, c1) = (th1.sin(), th1.cos());
    let vertical = m * g - along * s1 - inward * c1;
    let horizontal = along * c1 - inward * s1;
    let ratio = horizontal.abs() / vertical;
    assert!((ratio - 1.0).abs() < 1e-6, "slips at |F_t| / F_n = {ratio}");
}
