//! A skid against its invariants and a closed form: the ends stay on the
//! plane, without friction no horizontal force acts and energy is kept,
//! with friction energy falls by the friction forces' work, and a box
//! balanced on its edge slides to a stop in `v₀ / μg` seconds along
//! `x(t) = v₀ t − ½ μ g t²`.

use super::super::{Pivot, PivotEnd, PivotStart};
use crate::controls::Controls;
use crate::geometry::Geometry;
use crate::math::Vec3;
use crate::scene::Scene;
use crate::sim::dynamics::BodyDynamics;
use crate::sim::rest;
use crate::sim::state::BodyState;
use crate::testkit;
use nalgebra::UnitQuaternion;

const G: f64 = 9.81;

/// A 30 × 20 × 10 cm box on the ground, turned by `tilt` about x so that
/// (for `0 < tilt < π/2`) its edge at body `y = −0.1, z = −0.05` touches
/// the plane, moving at `v` and spinning at `w`; the scene, the body's
/// dynamics and its state.
fn on_edge(tilt: f64, v: Vec3, w: Vec3) -> (Scene, BodyDynamics, BodyState) {
    let mut s = testkit::scene(2.0);
    s.effects.friction = true;
    s.obstacles.push(testkit::ground());
    let half = Vec3::new(0.15, 0.1, 0.05);
    let mut b = testkit::body("box", Geometry::cuboid(half).unwrap(), Vec3::zeros());
    let q = UnitQuaternion::from_scaled_axis(Vec3::new(tilt, 0.0, 0.0));
    b.position = Vec3::new(0.0, 0.0, -(q * Vec3::new(0.0, -0.1, -0.05)).z);
    b.orientation = Vec3::new(tilt, 0.0, 0.0);
    s.bodies.push(b);
    let d = BodyDynamics::new(&s, 0, &Controls::new(&s));
    let state = BodyState {
        x: s.bodies[0].position,
        q,
        v,
        w,
    };
    (s, d, state)
}

/// The box of [`on_edge`] turned by the rotation vector `turn` instead,
/// its lowest corner on the plane.
fn on_corner(turn: Vec3, v: Vec3) -> (Scene, BodyDynamics, BodyState) {
    let (mut s, _, _) = on_edge(0.0, v, Vec3::zeros());
    let q = UnitQuaternion::from_scaled_axis(turn);
    let low = [-1.0, 1.0]
        .iter()
        .flat_map(|&x| [-1.0, 1.0].map(|y| (x, y)))
        .flat_map(|(x, y)| [-1.0, 1.0].map(|z| (q * Vec3::new(0.15 * x, 0.1 * y, 0.05 * z)).z))
        .fold(f64::INFINITY, f64::min);
    s.bodies[0].position = Vec3::new(0.0, 0.0, -low);
    s.bodies[0].orientation = turn;
    let d = BodyDynamics::new(&s, 0, &Controls::new(&s));
    let state = BodyState {
        x: s.bodies[0].position,
        q,
        v,
        w: Vec3::zeros(),
    };
    (s, d, state)
}

/// The skid that starts from `state` with friction `mu`.
fn skid(s: &Scene, d: &BodyDynamics, state: &BodyState, mu: f64) -> (Pivot, BodyState) {
    let supports = rest::supports(s, 0, 0, state, 1e-9);
    assert!(!supports.is_empty(), "the box touches the plane");
    Pivot::enter_skid(&PivotStart {
        scene: s,
        dynamics: d,
        gravity: Vec3::new(0.0, 0.0, -G),
        body: 0,
        obstacle: 0,
        part: 0,
        post: *state,
        supports: &supports,
        friction: mu,
        horizon: 2.0,
        v_rest: 1e-3,
        lean: None,
        topple: false,
    })
    .expect("the box skids")
}

fn energy(d: &BodyDynamics, s: &BodyState) -> f64 {
    let r = *s.q.to_rotation_matrix().matrix();
    let ic = r * d.inertia * r.transpose();
    0.5 * (d.mass * s.v.norm_squared() + s.w.dot(&(ic * s.w))) + d.mass * G * s.x.z
}

/// Samples of the skid every millisecond, to its end.
fn samples(pv: &Pivot) -> Vec<(f64, BodyState)> {
    let n = (pv.duration / 1e-3).floor() as usize;
    (0..=n)
        .map(|k| k as f64 * 1e-3)
        .chain(std::iter::once(pv.duration))
        .map(|t| (t, pv.at(t)))
        .collect()
}

#[test]
fn without_friction_a_toppling_box_keeps_its_energy_and_its_centre_falls_straight() {
    let (s, d, state) = on_edge(0.35, Vec3::new(0.2, 0.0, 0.0), Vec3::zeros());
    let (pv, start) = skid(&s, &d, &state, 0.0);
    assert_eq!(pv.end, PivotEnd::Lands, "it topples onto its face");
    assert!(pv.duration > 0.05, "{}", pv.duration);
    keeps_energy_and_momentum(&d, &pv, &start);
}

#[test]
fn with_friction_energy_falls_by_the_work_of_the_friction_forces() {
    let (s, d, state) = on_edge(0.35, Vec3::new(0.8, -0.3, 0.0), Vec3::new(0.0, 0.0, 2.0));
    let (pv, start) = skid(&s, &d, &state, 0.3);
    loses_the_work_of_friction(&d, &pv, &start);
    // On one corner, too.
    let (s, d, state) = on_corner(Vec3::new(0.5, 0.4, 0.0), Vec3::new(0.8, -0.3, 0.0));
    let (pv, start) = skid(&s, &d, &state, 0.3);
    loses_the_work_of_friction(&d, &pv, &start);
}

/// Asserts that within the skid `pv` from `start` the body's energy falls
/// by the friction forces' work (Simpson's rule on 1 ms samples), and by
/// a visible amount.
fn loses_the_work_of_friction(d: &BodyDynamics, pv: &Pivot, start: &BodyState) {
    let skid = pv.skid().expect("a skid");
    let pts = samples(pv);
    let mut work = 0.0;
    let mut lost_max: f64 = 0.0;
    for w in pts.windows(2) {
        let ((t0, s0), (t1, s1)) = (w[0], w[1]);
        // Simpson's rule on the step, its midpoint from the skid.
        let mid = pv.at(0.5 * (t0 + t1));
        work += (t1 - t0) / 6.0
            * (skid.friction_power(&s0)
                + 4.0 * skid.friction_power(&mid)
                + skid.friction_power(&s1));
        let lost = energy(d, &s1) - energy(d, start);
        lost_max = lost_max.max(-lost);
        assert!(
            (lost - work).abs() < 1e-6 * (d.mass * G * 0.1),
            "t {t1}: energy changed by {lost}, friction did {work}"
        );
    }
    assert!(
        lost_max > 1e-2 * d.mass * G * 0.1,
        "friction did little: {lost_max}"
    );
}

#[test]
fn a_box_balanced_on_its_edge_slides_to_a_stop_as_in_closed_form() {
    // The centre of mass straight above the edge: tan(tilt) = 0.1 / 0.05.
    let tilt = (0.1_f64 / 0.05).atan();
    let (v0, mu) = (1.0, 0.3);
    let (s, d, state) = on_edge(tilt, Vec3::new(v0, 0.0, 0.0), Vec3::zeros());
    let (pv, start) = skid(&s, &d, &state, mu);
    assert_eq!(pv.end, PivotEnd::Sticks);
    let stop = v0 / (mu * G);
    assert!(
        (pv.duration - stop).abs() <= 1e-3 + 1e-3 / (mu * G),
        "stops at {} s, closed form {stop} s",
        pv.duration
    );
    // The closed form holds while the box slips: up to the last step,
    // within which the slip falls below the onset speed (1 mm/s) and
    // friction lets go.
    let end = pv.at(pv.duration);
    assert!(end.v.norm() < 2e-3, "still sliding at {:?}", end.v);
    for (t, st) in samples(&pv)
        .into_iter()
        .filter(|(t, _)| *t < pv.duration - 1e-3)
    {
        let x = v0 * t - 0.5 * mu * G * t * t;
        assert!(
            (st.x.x - start.x.x - x).abs() < 1e-9,
            "t {t}: x {} vs {x}",
            st.x.x
        );
        assert!(
            (st.v.x - (v0 - mu * G * t)).abs() < 1e-9,
            "t {t}: v {}",
            st.v.x
        );
        assert!(
            (st.x.yz() - start.x.yz()).norm() < 1e-9,
            "t {t}: {:?}",
            st.x
        );
        assert!(st.q.angle_to(&start.q) < 1e-9, "t {t}: turned");
    }
}

#[test]
fn an_edge_at_rest_skids_when_friction_cannot_hold_it_and_not_when_it_can() {
    let (s, d, state) = on_edge(0.35, Vec3::zeros(), Vec3::zeros());
    let supports = rest::supports(&s, 0, 0, &state, 1e-9);
    let start = |mu: f64| PivotStart {
        scene: &s,
        dynamics: &d,
        gravity: Vec3::new(0.0, 0.0, -G),
        body: 0,
        obstacle: 0,
        part: 0,
        post: state,
        supports: &supports,
        friction: mu,
        horizon: 2.0,
        v_rest: 1e-3,
        lean: None,
        topple: false,
    };
    // Grippy: the hinge's domain, no skid.
    assert!(Pivot::enter_skid(&start(1.0)).is_none());
    // Slippery: the edge kicks out from under the falling centre, along y
    // (away from it), while the centre moves less far the other way.
    let (pv, _) = Pivot::enter_skid(&start(0.02)).expect("it skids");
    let edge = Vec3::new(0.0, -0.1, -0.05);
    let later = pv.at(0.05_f64.min(pv.duration));
    let kick = later.point(&edge) - state.point(&edge);
    let fall = later.x - state.x;
    assert!(
        kick.y < -1e-4 && fall.y > 0.0,
        "edge {kick:?}, centre {fall:?}"
    );
    assert!(kick.x.abs() < 1e-12 && kick.z.abs() < 1e-12, "{kick:?}");
    assert!(fall.y < -kick.y, "centre {fall:?}, edge {kick:?}");
}

#[test]
fn a_box_on_one_corner_skids_without_friction_keeping_its_energy() {
    let (s, d, state) = on_corner(Vec3::new(0.5, 0.4, 0.0), Vec3::new(0.3, -0.1, 0.0));
    let supports = rest::supports(&s, 0, 0, &state, 1e-9);
    assert_eq!(supports.len(), 1, "one corner down");
    let (pv, start) = skid(&s, &d, &state, 0.0);
    assert_eq!(pv.end, PivotEnd::Lands, "it falls onto an edge or face");
    assert!(pv.duration > 0.02, "{}", pv.duration);
    keeps_energy_and_momentum(&d, &pv, &start);
}

/// Asserts that within the frictionless skid `pv` from `start` the ends
/// stay on the plane (1e-12 m, 1e-12 m/s), the energy stays put (1e-9 of
/// `m g · 10 cm`) and, no horizontal force acting, the centre moves on at
/// its start velocity.
fn keeps_energy_and_momentum(d: &BodyDynamics, pv: &Pivot, start: &BodyState) {
    let skid = pv.skid().expect("a skid");
    let e0 = energy(d, start);
    for (t, st) in samples(pv) {
        for (height, speed) in skid.contact(&st) {
            assert!(
                height.abs() < 1e-12,
                "t {t}: an end left the plane by {height}"
            );
            assert!(
                speed.abs() < 1e-12,
                "t {t}: an end moves along n at {speed}"
            );
        }
        let de = (energy(d, &st) - e0).abs() / (d.mass * G * 0.1);
        assert!(de < 1e-9, "t {t}: energy changed by {de:e} of m g (10 cm)");
        let drift = st.x.xy() - (start.x.xy() + start.v.xy() * t);
        assert!(drift.norm() < 1e-12, "t {t}: centre drifted by {drift:?}");
    }
}
