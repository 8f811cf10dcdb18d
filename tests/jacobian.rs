//! Tangent Jacobians against central finite differences (DESIGN §5).

use nudge::controls::Controls;
use nudge::geometry::Geometry;
use nudge::math::Vec3;
use nudge::scene::{Block, Effects, EventControl, Scene};
use nudge::sim::{SimOptions, StateSide, simulate};
use nudge::tangent::{FiniteDifference, Scheme, max_relative_error};
use nudge::testkit::{self, body, body_with_inertia, ground, obstacle};

/// Compare tangent and central-difference Jacobians of every body at the
/// given times and just before/after every event; returns the worst
/// relative error over comparable columns.
fn check(scene: &Scene, times: &[f64], tol: f64) -> f64 {
    // Event times are differenced over steps of ~1e-5: refine roots far
    // below that so the quotient's noise (root_tol / (|v_n| h)) stays small.
    let mut scene = scene.clone();
    scene.accuracy.root_tol = 1e-14;
    let scene = &scene;
    let controls = Controls::new(scene);
    let tr = simulate(scene, &controls, &SimOptions::default()).expect("simulates");
    assert!(tr.tangent_error.is_none(), "{:?}", tr.tangent_error);
    let fd = FiniteDifference::new(scene, &controls, Scheme::Central).expect("perturbed runs");
    assert!(
        fd.comparable.iter().any(|c| *c),
        "some column must keep the signature"
    );
    let mut worst: f64 = 0.0;
    for b in 0..scene.bodies.len() {
        for &t in times {
            let jt = tr.jacobian(b, t, StateSide::After).expect("jacobian");
            let jf = fd.at(b, t, StateSide::After);
            let err = max_relative_error(&jt, &jf, &fd.comparable, 1e-3);
            assert!(
                err < tol,
                "body {b} t={t}: relative error {err:.2e}\ntangent {jt:.6}\nfd {jf:.6}"
            );
            worst = worst.max(err);
        }
    }
    for (k, ev) in tr.events.iter().enumerate() {
        // Floating quantities: the state at each run's own event time.
        for side in [StateSide::Before, StateSide::After] {
            let fl = fd.at_event(k, ev.a, side).expect("same events");
            let s = match side {
                StateSide::Before => ev.pre[0],
                StateSide::After => ev.post[0],
            };
            let f = tr.flow(ev.a, &s, ev.rest && side == StateSide::After);
            let dt = ev.dt_du.as_ref().expect("dt/du");
            let jt = tr.jacobian(ev.a, ev.t, side).expect("jacobian") + &f * dt.transpose();
            let err = max_relative_error(&jt, &fl, &fd.comparable, 1e-3);
            assert!(
                err < tol,
                "event {k} {side:?}: relative error {err:.2e}\ntangent {jt:.6}\nfd {fl:.6}"
            );
            worst = worst.max(err);
        }
        let dtf = fd.event_time(k).expect("event times");
        let dtt = ev.dt_du.as_ref().expect("dt/du");
        for c in 0..dtf.len() {
            if fd.comparable[c] {
                let e = (dtt[c] - dtf[c]).abs() / dtf[c].abs().max(1e-3);
                assert!(
                    e < tol,
                    "event {k} dt/du column {c}: {} vs {}",
                    dtt[c],
                    dtf[c]
                );
            }
        }
    }
    worst
}

fn free_all(s: &mut Scene) {
    testkit::free_state(s);
}

#[test]
fn bouncing_ball_jacobian_through_bounces() {
    let mut s = testkit::scene(1.5);
    let mut b = body(
        "ball",
        Geometry::sphere(0.1).unwrap(),
        Vec3::new(0.0, 0.0, 1.0),
    );
    b.velocity = Vec3::new(0.5, 0.2, 1.0);
    b.restitution = 0.7;
    s.bodies.push(b);
    s.obstacles.push(ground());
    free_all(&mut s);
    check(&s, &[0.2, 0.7, 1.2, 1.5], 1e-6);
}

#[test]
fn tumbling_box_on_a_tilted_plane_couples_rotation_and_translation() {
    let mut s = testkit::scene(0.9);
    s.effects = Effects {
        gravity: true,
        collisions: true,
        gyroscopic: true,
        ..Default::default()
    };
    let mut b = body(
        "box",
        Geometry::cuboid(Vec3::new(0.3, 0.2, 0.1)).unwrap(),
        Vec3::new(0.0, 0.0, 1.0),
    );
    b.orientation = Vec3::new(0.3, 0.5, 0.1);
    b.angular_velocity = Vec3::new(1.0, 2.0, 0.5);
    b.velocity = Vec3::new(0.3, 0.0, 0.5);
    b.restitution = 0.6;
    b.free = vec![
        Block::Position,
        Block::Orientation,
        Block::Velocity,
        Block::AngularVelocity,
        Block::Mass,
        Block::Inertia,
    ];
    s.bodies.push(b);
    let mut plane = obstacle(
        "ramp",
        Geometry::half_space(Vec3::new(0.2, 0.1, 1.0)).unwrap(),
        Vec3::zeros(),
    );
    plane.restitution = 1.0;
    s.obstacles.push(plane);
    check(&s, &[0.3, 0.6, 0.9], 1e-6);
}

#[test]
fn adaptive_integrator_jacobian_matches_too() {
    let mut s = testkit::scene(1.0);
    s.effects = Effects {
        gravity: true,
        collisions: true,
        gyroscopic: true,
        ..Default::default()
    };
    testkit::adaptive(&mut s, 1e-12);
    let mut b = body_with_inertia(
        "box",
        Geometry::cuboid(Vec3::new(0.3, 0.2, 0.1)).unwrap(),
        Vec3::new(0.0, 0.0, 0.8),
        2.0,
        Vec3::new(0.1, 0.2, 0.25),
    );
    b.angular_velocity = Vec3::new(3.0, 0.2, 0.5);
    b.orientation = Vec3::new(0.1, 0.2, 0.3);
    s.bodies.push(b);
    s.obstacles.push(ground());
    free_all(&mut s);
    check(&s, &[0.25, 0.7, 1.0], 1e-6);
}

#[test]
fn two_bodies_colliding_in_the_air() {
    let mut s = testkit::scene(0.8);
    s.effects = Effects {
        gravity: true,
        collisions: true,
        gyroscopic: true,
        ..Default::default()
    };
    let mut a = body(
        "egg",
        Geometry::ellipsoid(Vec3::new(0.1, 0.1, 0.14), 6, 1.3).unwrap(),
        Vec3::new(-1.0, 0.03, 1.0),
    );
    let mut b = body(
        "cube",
        Geometry::cuboid(Vec3::new(0.1, 0.12, 0.08)).unwrap(),
        Vec3::new(1.0, 0.0, 1.05),
    );
    a.velocity = Vec3::new(3.0, 0.0, 1.0);
    a.angular_velocity = Vec3::new(0.5, 1.0, 2.0);
    a.orientation = Vec3::new(0.2, 0.1, 0.0);
    b.velocity = Vec3::new(-2.0, 0.0, 1.0);
    b.angular_velocity = Vec3::new(-1.0, 0.3, 0.2);
    a.restitution = 0.9;
    s.bodies.push(a);
    s.bodies.push(b);
    s.pairs.push([0, 1]);
    free_all(&mut s);
    let controls = Controls::new(&s);
    let tr = simulate(&s, &controls, &SimOptions::default()).unwrap();
    assert!(
        tr.events
            .iter()
            .any(|e| matches!(e.b, nudge::sim::Party::Body(1))),
        "they collide"
    );
    check(&s, &[0.5, 0.8], 1e-6);
}

/// Paper §3.2: a particle bouncing off a parabola, with the normal
/// deviation and restitution of the bounce as controls.
#[test]
fn particle_on_a_parabola_with_surface_controls() {
    let mut s = testkit::scene(1.2);
    let mut p = body(
        "particle",
        Geometry::sphere(0.02).unwrap(),
        Vec3::new(-0.6, 0.0, 1.0),
    );
    p.velocity = Vec3::new(1.0, 0.0, 0.0);
    s.bodies.push(p);
    s.obstacles.push(obstacle(
        "hill",
        Geometry::parabola(1.0, 1.5).unwrap(),
        Vec3::zeros(),
    ));
    s.bodies[0].free = vec![Block::Position, Block::Velocity];
    s.event_controls.push(EventControl {
        event: 0,
        normal: Some([0.05, -0.02]),
        restitution: Some(0.9),
    });
    check(&s, &[0.9, 1.2], 1e-6);
}

#[test]
fn drag_and_mass_controls() {
    let mut s = testkit::scene(1.0);
    s.effects.drag = true;
    let mut b = body(
        "ball",
        Geometry::sphere(0.1).unwrap(),
        Vec3::new(0.0, 0.0, 1.0),
    );
    b.drag = 0.8;
    b.velocity = Vec3::new(1.0, 0.0, 2.0);
    b.restitution = 0.8;
    b.free = vec![Block::Position, Block::Velocity, Block::Mass];
    s.bodies.push(b);
    s.obstacles.push(ground());
    check(&s, &[0.4, 1.0], 1e-6);
}
