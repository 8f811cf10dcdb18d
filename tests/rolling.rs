//! A single body in sustained contact with obstacles: resting flat.

use nudge::controls::Controls;
use nudge::geometry::Geometry;
use nudge::math::Vec3;
use nudge::sim::{Side, SimOptions, simulate};
use nudge::testkit::{self, body, ground};

fn run(scene: &nudge::scene::Scene) -> nudge::sim::Trajectory {
    let controls = Controls::new(scene);
    simulate(scene, &controls, &SimOptions::without_tangents()).expect("simulates")
}

/// Height of the centre and tilt of the body's z axis at the end.
fn height_and_tilt(tr: &nudge::sim::Trajectory, t: f64) -> (f64, f64) {
    let s = tr.state(0, t, Side::Post);
    let up = s.q * Vec3::z();
    (s.x.z, up.z.abs().clamp(-1.0, 1.0).acos())
}

fn corner_box() -> nudge::scene::Scene {
    let mut s = testkit::scene(3.0);
    let mut b = body(
        "box",
        Geometry::cuboid(Vec3::new(0.2, 0.1, 0.05)).expect("box"),
        Vec3::new(0.0, 0.0, 0.6),
    );
    b.orientation = Vec3::new(0.5, 0.4, 0.1);
    b.restitution = 0.5;
    s.bodies.push(b);
    s.obstacles.push(ground());
    s
}

fn spinning_sheet() -> nudge::scene::Scene {
    let mut s = testkit::scene(3.0);
    let mut b = body(
        "sheet",
        Geometry::cuboid(Vec3::new(0.1, 0.07, 1e-6)).expect("sheet"),
        Vec3::new(0.0, 0.0, 0.3),
    );
    b.orientation = Vec3::new(0.2, -0.1, 0.0);
    b.angular_velocity = Vec3::new(0.0, 0.0, 6.0);
    b.restitution = 0.5;
    s.bodies.push(b);
    s.obstacles.push(ground());
    s
}

#[test]
fn a_box_dropped_on_a_corner_and_a_spinning_sheet_rest_flat() {
    for (scene, half) in [(corner_box(), 0.05), (spinning_sheet(), 1e-6)] {
        let tr = run(&scene);
        let last = tr.events.last().expect("events");
        let (h, tilt) = height_and_tilt(&tr, scene.duration);
        eprintln!(
            "{}: {} events, rest {} at {:.4} s, height - half {:.3e} m, tilt {:.3e} rad",
            scene.bodies[0].name,
            tr.events.len(),
            last.rest,
            last.t,
            h - half,
            tilt
        );
        let end = tr.state(0, scene.duration, Side::Post);
        assert!(last.rest || last.slide.is_some(), "it rests or slides");
        assert!(end.v.norm() < 1e-9 && (end.w - end.w.z * Vec3::z()).norm() < 1e-9);
        assert!((h - half).abs() <= 1e-9, "height off by {:.3e} m", h - half);
        assert!(tilt <= 1e-9, "tilt {tilt:.3e} rad");
    }
}

/// With friction the corner-dropped box comes to rest (frozen, not
/// sliding) and is put flat too.
#[test]
fn a_box_dropped_on_a_corner_rests_flat_with_friction() {
    let mut scene = corner_box();
    scene.effects.friction = true;
    let tr = run(&scene);
    let (h, tilt) = height_and_tilt(&tr, scene.duration);
    let last = tr.events.last().expect("events");
    eprintln!(
        "box with friction: {} events, rest {} slide {} at {:.4} s, height - half {:.3e} m, tilt {:.3e} rad",
        tr.events.len(),
        last.rest,
        last.slide.is_some(),
        last.t,
        h - 0.05,
        tilt
    );
    assert!(last.rest || last.slide.is_some());
    assert!((h - 0.05).abs() <= 1e-9 && tilt <= 1e-9);
}

/// A box landing flat and sliding on (frictionless) is settled flat: its
/// final height no longer depends on the throw, its in-plane position
/// does, and the projected tangent says both (central differences).
#[test]
fn the_settled_tangent_matches_central_differences() {
    let mut s = testkit::scene(1.5);
    let mut b = body(
        "box",
        Geometry::cuboid(Vec3::new(0.2, 0.1, 0.05)).expect("box"),
        Vec3::new(0.0, 0.0, 0.15),
    );
    b.velocity = Vec3::new(0.8, 0.3, 0.0);
    b.restitution = 0.0;
    b.free = vec![nudge::scene::Block::Velocity];
    s.bodies.push(b);
    s.obstacles.push(ground());
    let controls = Controls::new(&s);
    let tr = simulate(&s, &controls, &SimOptions::default()).expect("simulates");
    let last = tr.events.last().expect("events");
    eprintln!("{} events, slide {}", tr.events.len(), last.slide.is_some());
    assert!(last.rest || last.slide.is_some());
    let t = s.duration;
    let j = tr.jacobian(0, t, Side::Post).expect("a Jacobian");
    let keys = |tr: &nudge::sim::Trajectory| {
        tr.events
            .iter()
            .map(|e| (e.rest, e.slide.is_some()))
            .collect::<Vec<_>>()
    };
    let col = controls
        .body_column(0, nudge::scene::Block::Velocity)
        .expect("free velocity");
    let h = 1e-6;
    for k in 0..2 {
        let moved = |d: f64| {
            let mut s2 = s.clone();
            s2.bodies[0].velocity[k] += d;
            let tr2 = run(&s2);
            assert_eq!(keys(&tr2), keys(&tr), "the event sequence is kept");
            tr2.state(0, t, Side::Post).x
        };
        let fd = (moved(h) - moved(-h)) / (2.0 * h);
        let an = j.fixed_view::<3, 1>(0, col + k).into_owned();
        eprintln!("dx/dv{k}: tangent {an:?}, central {fd:?}");
        assert!((an - fd).norm() <= 1e-5 * (1.0 + fd.norm()), "column {k}");
        assert_eq!(an.z, 0.0, "the height does not move");
    }
}
