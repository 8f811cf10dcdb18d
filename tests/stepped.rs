//! A body chattering on two obstacles is stepped (`sim::pivot::stepped`):
//! a plank leaning from a frictionless floor onto the top edge of a block
//! stands where friction at the edge can hold it (`tan θ ≤ μ`) and slides
//! down to lie on the floor where it cannot, in a few dozen events and
//! without entering either obstacle.

use nudge::controls::Controls;
use nudge::geometry::Geometry;
use nudge::math::Vec3;
use nudge::scene::Scene;
use nudge::sim::{Side, SimOptions, Trajectory, simulate};
use nudge::testkit;

/// The plank (1 m × 20 cm × 2 cm) at `pitch` (rad) from the floor, its
/// lower end on a frictionless floor, its underside through the top edge
/// of a 20 cm block whose friction with it is `mu`; raised by `drop` (m).
fn plank(pitch: f64, mu: f64, drop: f64) -> Scene {
    let mut s = testkit::on_ground(1.5, 0.0);
    let mut block = testkit::obstacle(
        "block",
        Geometry::cuboid(Vec3::new(0.1, 0.5, 0.1)).unwrap(),
        Vec3::new(0.0, 0.0, 0.1),
    );
    block.friction = mu;
    block.restitution = 0.3;
    s.obstacles.push(block);
    let (along, up) = (
        Vec3::new(pitch.cos(), 0.0, pitch.sin()),
        Vec3::new(-pitch.sin(), 0.0, pitch.cos()),
    );
    // The underside's lower edge on the floor, the underside through the
    // block's edge at x = −0.1, z = 0.2.
    let edge = Vec3::new(-0.1, 0.0, 0.2);
    let foot = edge - along * (0.2 / pitch.sin());
    let mut b = testkit::body(
        "plank",
        Geometry::cuboid(Vec3::new(0.5, 0.1, 0.01)).unwrap(),
        foot + along * 0.5 + up * 0.01 + Vec3::z() * drop,
    );
    b.orientation = Vec3::new(0.0, -pitch, 0.0);
    b.friction = mu;
    b.restitution = 0.3;
    s.bodies.push(b);
    s
}

fn run(s: &Scene) -> Trajectory {
    simulate(s, &Controls::new(s), &SimOptions::without_tangents())
        .unwrap_or_else(|e| panic!("{e}"))
}

fn stepped(tr: &Trajectory) -> usize {
    tr.tracks[0]
        .segments
        .iter()
        .filter(|seg| seg.pivot.as_ref().is_some_and(|p| p.stepped().is_some()))
        .count()
}

#[test]
fn a_plank_leaning_on_a_block_stands_where_friction_holds_it() {
    // tan 20° = 0.36 < 1; dropped 1 cm, it bounces and chatters first.
    let s = plank(20f64.to_radians(), 1.0, 0.01);
    let tr = run(&s);
    assert!(stepped(&tr) > 0, "never stepped: {:?}", tr.signature());
    assert!(tr.events.len() < 30, "{} events", tr.events.len());
    let last = tr.tracks[0].segments.last().unwrap();
    assert!(last.rest, "the plank does not rest");
    // Leaning where it was dropped: at its pitch, 1 cm lower.
    let end = tr.state(0, s.duration, Side::Post);
    let pitch = (end.q * Vec3::x()).z.asin().to_degrees();
    let fell = s.bodies[0].position.z - end.x.z;
    assert!(
        (pitch - 20.0).abs() < 0.5 && (fell - 0.01).abs() < 2e-3,
        "at {pitch}° and {fell} m lower"
    );
    assert!(testkit::lowest_gap(&s, &tr, 1500) > -1.1e-9);
}

#[test]
fn a_plank_leaning_on_a_slippery_block_slides_down_to_the_floor() {
    // tan 20° = 0.36 > 0.2: the edge cannot hold it.
    let s = plank(20f64.to_radians(), 0.2, 1e-4);
    let tr = run(&s);
    assert!(stepped(&tr) > 0, "never stepped: {:?}", tr.signature());
    assert!(tr.events.len() < 100, "{} events", tr.events.len());
    let end = tr.state(0, s.duration, Side::Post);
    let tilt = (end.q * Vec3::z()).dot(&Vec3::z()).acos();
    assert!(
        (end.x.z - 0.01).abs() < 1e-3 && tilt < 1e-2,
        "ends at z = {} tilted {tilt} rad",
        end.x.z
    );
    assert!(
        end.x.x < s.bodies[0].position.x,
        "it slid away from the block"
    );
    assert!(testkit::lowest_gap(&s, &tr, 1500) > -1.1e-9);
}
