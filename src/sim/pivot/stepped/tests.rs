//! The stepping against closed forms and its invariants: a box sliding
//! flat on a frictionless table keeps its velocity (`x(t) = x₀ + v₀ t`)
//! and its height; with friction it slows by `μ g` every second
//! (`v(t) = v₀ − μ g t`) and comes to rest; a box dropped onto a springy
//! table stops stepping where it strikes; and a tumbling box never sinks
//! into the table and only loses energy.

use super::super::{Pivot, PivotEnd};
use super::{CLEARANCE, STEP, SteppedStart};
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

/// A 30 × 20 × 10 cm box over a table (a 2 m slab whose top is at
/// `z = 0`) with friction `mu` and restitution `e`: the scene and the
/// box's dynamics.
fn table(mu: f64, e: f64) -> (Scene, BodyDynamics) {
    let mut s = testkit::scene(1.0);
    s.effects.friction = mu > 0.0;
    s.effects.gyroscopic = true;
    let mut t = testkit::obstacle(
        "table",
        Geometry::cuboid(Vec3::new(1.0, 1.0, 0.05)).unwrap(),
        Vec3::new(0.0, 0.0, -0.05),
    );
    t.friction = mu;
    t.restitution = e;
    s.obstacles.push(t);
    let mut b = testkit::body(
        "box",
        Geometry::cuboid(Vec3::new(0.15, 0.1, 0.05)).unwrap(),
        Vec3::new(0.0, 0.0, 0.05),
    );
    b.friction = mu;
    b.restitution = 1.0;
    s.bodies.push(b);
    let d = BodyDynamics::new(&s, 0, &Controls::new(&s));
    (s, d)
}

/// The stepped motion from `post`, with the rest speed and band the run
/// loop would use.
fn stepped(s: &Scene, d: &BodyDynamics, post: BodyState, horizon: f64) -> Option<Pivot> {
    let gravity = Vec3::new(0.0, 0.0, -G);
    let (v_rest, band) = rest::thresholds(s, d, &gravity, 1e-9);
    Pivot::enter_stepped(&SteppedStart {
        scene: s,
        dynamics: d,
        gravity,
        body: 0,
        post,
        horizon,
        v_rest,
        band,
        obstacle: 0,
        part: 0,
    })
    .map(|(pv, _)| pv)
}

/// The lowest point of the box over the table's top at state `st`.
fn lowest(st: &BodyState) -> f64 {
    [-1.0, 1.0]
        .iter()
        .flat_map(|&x| [-1.0, 1.0].map(|y| (x, y)))
        .flat_map(|(x, y)| [-1.0, 1.0].map(|z| st.point(&Vec3::new(0.15 * x, 0.1 * y, 0.05 * z)).z))
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn a_box_sliding_on_a_frictionless_table_keeps_its_velocity_and_height() {
    let (s, d) = table(0.0, 0.05);
    let v0 = Vec3::new(0.5, 0.2, 0.0);
    let start = BodyState {
        x: Vec3::new(0.0, 0.0, 0.05),
        q: UnitQuaternion::identity(),
        v: v0,
        w: Vec3::zeros(),
    };
    let pv = stepped(&s, &d, start, 0.2).expect("the box is stepped");
    assert_eq!(pv.end, PivotEnd::Duration);
    let v_rest = rest::thresholds(&s, &d, &Vec3::new(0.0, 0.0, -G), 1e-9).0;
    for k in 0..=100 {
        let tau = 0.2 * k as f64 / 100.0;
        let st = pv.at(tau);
        // x(t) = x₀ + v₀ t along the table; no turn.
        let along = (st.x - start.x - v0 * tau).xy().norm();
        assert!(along < 1e-12, "{along:e} m off x₀ + v₀ t at {tau} s");
        // The normal impulses are solved to 1e-4 of the rest speed: the
        // four corners' share of the weight leaves no turn beyond that.
        assert!(
            (st.v.xy() - v0.xy()).norm() < 1e-12 && st.w.norm() * d.reach < 1e-4 * v_rest,
            "{:?} m/s, {:?} rad/s at {tau} s",
            st.v,
            st.w
        );
        // Held just off the top: within the clearance and round-off.
        let gap = lowest(&st);
        assert!((-1e-12..=1e-6).contains(&gap), "gap {gap:e} at {tau} s");
    }
}

#[test]
fn a_box_sliding_with_friction_slows_by_mu_g_and_rests() {
    let mu = 0.4;
    let (s, d) = table(mu, 0.05);
    let v0 = 1.0;
    // Held at the clearance already (from the table's top, the first
    // step's normal impulse would also lift it there).
    let start = BodyState {
        x: Vec3::new(0.0, 0.0, 0.05 + CLEARANCE * d.reach),
        q: UnitQuaternion::identity(),
        v: Vec3::new(v0, 0.0, 0.0),
        w: Vec3::zeros(),
    };
    let pv = stepped(&s, &d, start, 0.6).expect("the box is stepped");
    assert_eq!(pv.end, PivotEnd::Rests);
    // Velocity after each step until it stops: v₀ − μ g t, at the step's
    // end (the velocity a step drifts with has that step's friction).
    let stop = v0 / (mu * G);
    let mut k = 0;
    while (k as f64 + 1.0) * STEP < stop - STEP {
        let st = pv.at(k as f64 * STEP);
        let expected = v0 - mu * G * (k as f64 + 1.0) * STEP;
        assert!(
            (st.v.x - expected).abs() < 1e-7 && st.v.y.abs() < 1e-7,
            "step {k}: {:?} m/s against {expected} m/s along x",
            st.v
        );
        k += 1;
    }
    // It rests once slower than the rest speed: within a step of v₀ / μg.
    assert!(
        (pv.duration - stop).abs() <= 2.0 * STEP,
        "rests at {} s, stops at {stop} s",
        pv.duration
    );
    assert_eq!(pv.at(pv.duration).v, Vec3::zeros());
}

#[test]
fn a_box_tipping_onto_a_springy_table_stops_stepping_where_it_strikes() {
    // On the edge at y = −0.1, z = −0.05 (body), tilted 0.3 rad, with
    // friction that holds the edge: it tips back onto its face, which
    // strikes a springy table (restitution 1) at a speed that bounces.
    let (mut s, _) = table(1.0, 1.0);
    let tilt = 0.3;
    let q = UnitQuaternion::from_scaled_axis(Vec3::new(tilt, 0.0, 0.0));
    s.bodies[0].position = Vec3::new(0.0, 0.0, -(q * Vec3::new(0.0, -0.1, -0.05)).z);
    let d = BodyDynamics::new(&s, 0, &Controls::new(&s));
    let start = BodyState {
        x: s.bodies[0].position,
        q,
        v: Vec3::zeros(),
        w: Vec3::zeros(),
    };
    let pv = stepped(&s, &d, start, 1.0).expect("the box is stepped");
    assert_eq!(pv.end, PivotEnd::Lands, "the face strikes: {pv:?}");
    let at = pv.at(pv.duration);
    let (part, point) = pv.landing.expect("the landing point");
    assert_eq!(part, 0);
    // The corner that strikes is on the far edge (y = +0.1, z = −0.05),
    // touching the table, and the face is nearly flat.
    assert!((point.y - 0.1).abs() < 1e-12 && (point.z + 0.05).abs() < 1e-12);
    assert!(at.point(&point).z.abs() < 1e-9, "{:e}", at.point(&point).z);
    assert!(lowest(&at) > -1e-9);
    let tilt_now = (at.q * Vec3::z()).dot(&Vec3::z()).acos();
    assert!(tilt_now < 1e-3, "tilted {tilt_now} rad");
    // As a hinge about the held edge the box falls onto its face in
    // `∫ dθ / θ̇`, `θ̇² = 2 m g ρ (cos(φ − θ₀)... )`: the steps take it
    // within a few of the hinge's time.
    assert!((0.05..0.5).contains(&pv.duration), "{} s", pv.duration);
}

#[test]
fn a_tumbling_box_never_sinks_and_only_loses_energy() {
    let (s, d) = table(0.6, 0.05);
    let q = UnitQuaternion::from_scaled_axis(Vec3::new(0.3, 0.2, 0.0));
    let mut start = BodyState {
        x: Vec3::zeros(),
        q,
        v: Vec3::new(0.3, 0.0, -0.05),
        w: Vec3::new(2.0, -1.0, 3.0),
    };
    start.x.z = -lowest(&start);
    let pv = stepped(&s, &d, start, 0.5).expect("the box is stepped");
    let energy = |tau: f64| pv.energy(&d, &Vec3::new(0.0, 0.0, -G), tau);
    let e0 = energy(0.0);
    let n = 2000;
    for k in 0..=n {
        let tau = pv.duration * k as f64 / n as f64;
        let st = pv.at(tau);
        assert!(
            lowest(&st) > -1e-9,
            "{:e} m into the table at {tau} s",
            lowest(&st)
        );
        // Gravity's work over a step is taken a step late (the velocity
        // is updated at its start): at most `m g |v| h` ahead.
        let slack = d.mass * G * st.v.norm() * STEP;
        assert!(energy(tau) <= e0 + slack, "energy rises at {tau} s");
    }
    assert!(
        energy(pv.duration) < e0,
        "{} J at the end, {e0} J at the start",
        energy(pv.duration)
    );
}
