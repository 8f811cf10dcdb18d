//! Tests of the differential update (`solve::update`).

use super::*;
use crate::math::Vec3;
use crate::scene::Side;
use crate::scene::StateQuantity;
use crate::solve::{Anchor, Kind};
use crate::testkit;

/// Regression: the relevant-signature prefix compared only the first
/// `relevant` events of a trial, so a step that made a *new* collision
/// appear before the constrained time (here the ball now hits the floor
/// before the dragged time, where the current motion has no event at
/// all) counted as a smooth step: no pop was reported and the motion
/// jumped to another smooth component silently. Such a step must be
/// refused by the step reduction, which then keeps a shorter step
/// inside the current component.
#[test]
fn a_new_collision_before_the_constrained_time_is_a_signature_change() {
    let mut scene = testkit::scene(1.0);
    let ball = crate::geometry::Geometry::sphere(0.1).expect("ball");
    scene
        .bodies
        .push(testkit::body("ball", ball, Vec3::new(0.0, 0.0, 1.0)));
    scene.obstacles.push(testkit::ground());
    testkit::free_state(&mut scene);
    let controls = Controls::new(&scene);
    let traj = simulate(&scene, &controls, &SimOptions::default()).expect("simulates");
    let t = 0.4;
    assert!(
        traj.events.iter().all(|e| e.t > t),
        "no collision before the drag yet"
    );
    let z = traj.state(0, t, crate::sim::Side::Post).x.z;
    // Drag the ball 0.2 m down at t: the full linear step starts it so
    // low that it bounces before t.
    let drag = Constraint {
        body: 0,
        anchor: Anchor::Time(t),
        kind: Kind::State {
            quantities: vec![StateQuantity::Position],
            target: vec![0.0, 0.0, z - 0.2],
        },
        drag: true,
    };
    let res = update(&scene, &controls, &traj, &[drag], &UpdateOptions::default()).expect("update");
    let tr = res.trajectory.expect("moved");
    let bounced = tr.events.iter().any(|e| e.t <= t);
    let popped = res
        .diagnostics
        .iter()
        .any(|d| matches!(d, Diagnostic::Pop { .. }));
    assert!(
        !bounced || popped,
        "a new bounce before t = {t} s was taken as a smooth step: {:?}",
        res.diagnostics
    );
    // A floating constraint's event still anchors the prefix as before.
    let _ = Side::Post;
}

/// The signature that decides whether a step stays in its smooth
/// component holds only what can reach the constrained state: a bounce
/// of a body that never touched the constrained one is left out, a
/// body–body collision brings in the other body's earlier events.
#[test]
fn the_causal_signature_leaves_out_bounces_the_constraint_cannot_see() {
    let mut scene = testkit::scene(1.5);
    let ball = |name: &str, x: f64, z: f64, vx: f64| {
        let mut b = testkit::body(
            name,
            crate::geometry::Geometry::sphere(0.1).expect("ball"),
            Vec3::new(x, 0.0, z),
        );
        b.velocity = Vec3::new(vx, 0.0, 0.0);
        b
    };
    // a falls far from the others; b and c collide in the air at about
    // t = 0.2 s, then both fall to the ground.
    scene.bodies.push(ball("a", 5.0, 0.5, 0.0));
    scene.bodies.push(ball("b", -0.5, 2.0, 2.0));
    scene.bodies.push(ball("c", 0.5, 2.0, -2.0));
    scene.pairs.push([1, 2]);
    scene.obstacles.push(testkit::ground());
    let controls = Controls::new(&scene);
    let traj = simulate(&scene, &controls, &SimOptions::default()).expect("simulates");
    let nail = |body: usize, t: f64| Constraint {
        body,
        anchor: Anchor::Time(t),
        kind: Kind::State {
            quantities: vec![StateQuantity::Position],
            target: vec![0.0; 3],
        },
        drag: false,
    };
    let names = |sig: Vec<String>| -> Vec<String> {
        sig.into_iter()
            .map(|s| s.split('|').take(2).collect::<Vec<_>>().join("|"))
            .collect()
    };
    let hit = traj
        .events
        .iter()
        .find(|e| e.a == 1 && e.b == crate::sim::Party::Body(2));
    let hit = hit.expect("b and c collide").t;
    let a_lands = traj.events.iter().find(|e| e.a == 0).expect("a lands").t;
    assert!(a_lands < 0.5, "a lands at {a_lands}");
    // A nail on b after the collision: the collision counts, a's
    // bounce (never connected to b) does not.
    let sig = names(causal_signature(&traj, &[nail(1, hit + 0.05)]));
    assert_eq!(sig, vec!["1|Body(2)".to_string()], "{sig:?}");
    // A nail on a: only a's own bounce.
    let sig = names(causal_signature(&traj, &[nail(0, 1.0)]));
    assert!(
        sig.iter().all(|s| s.starts_with("0|")) && !sig.is_empty(),
        "{sig:?}"
    );
    // A nail on b before the collision: nothing yet.
    assert!(causal_signature(&traj, &[nail(1, hit - 0.05)]).is_empty());
}

/// Steps never leave the controls' physical ranges: asked for more
/// bounce than restitution 1 gives, the update holds restitution at 1.
#[test]
fn a_step_is_held_at_the_bounds_of_restitution() {
    let mut scene = testkit::scene(1.0);
    let mut b = testkit::body(
        "ball",
        crate::geometry::Geometry::sphere(0.1).expect("ball"),
        Vec3::new(0.0, 0.0, 0.6),
    );
    b.restitution = 0.9;
    scene.bodies.push(b);
    scene.obstacles.push(testkit::ground());
    scene.event_controls.push(crate::scene::EventControl {
        event: 0,
        normal: None,
        restitution: Some(0.9),
        fixed: false,
    });
    let controls = Controls::new(&scene);
    let traj = simulate(&scene, &controls, &SimOptions::default()).expect("simulates");
    let t = traj.events[0].t + 0.2;
    let z = traj.state(0, t, crate::sim::Side::Post).x.z;
    // Twice as high as restitution 1 could take it.
    let nail = Constraint {
        body: 0,
        anchor: Anchor::Time(t),
        kind: Kind::State {
            quantities: vec![StateQuantity::Position],
            target: vec![0.0, 0.0, z + 1.0],
        },
        drag: false,
    };
    let res = update(&scene, &controls, &traj, &[nail], &UpdateOptions::default()).expect("update");
    assert!(
        res.u.iter().all(|e| (0.0..=1.0).contains(e)),
        "restitution {:?}",
        res.u
    );
    assert!(res.after < res.before, "it still got closer");
}
