//! Pivoting with a part hanging over the edge of the face turned on
//! (docs/design.md §4, `sim::pivot::overhang`): a body lying across a
//! table's edge, one part on the top face and another beyond the edge
//! below the top's plane, turns about its support line as a hinge, with
//! the hanging part searched against the table instead of landing on the
//! top's plane.

use nalgebra::{Isometry3, Unit, UnitQuaternion};
use nudge::controls::Controls;
use nudge::geometry::Geometry;
use nudge::math::Vec3;
use nudge::scene::Scene;
use nudge::sim::{Pivot, PivotEnd, Side, SimOptions, Trajectory, simulate};
use nudge::testkit;

/// The table's top face is at this height, m; its edge at x = `EDGE`.
const TOP: f64 = 0.5;
const EDGE: f64 = 0.3;

/// A plate A (30 × 10 × 2 cm) with its centre at x = 0.1 m, lying on a
/// table (a 60 × 60 × 50 cm box with friction 1, on a floor) and pitched
/// `tilt` rad so that its end at x = −0.05 m is lowest, 1 µm above the top;
/// and a block B (10 × 10 × 2 cm) fixed to it at `(dx, 0, dz)` from A's
/// centre, beyond the table's edge and below the top's plane.
fn across_the_edge(dx: f64, dz: f64, tilt: f64) -> Scene {
    let mut s = testkit::on_ground(0.6, 1.0);
    let mut table = testkit::obstacle(
        "table",
        Geometry::cuboid(Vec3::new(0.3, 0.3, 0.25)).unwrap(),
        Vec3::new(0.0, 0.0, 0.25),
    );
    table.friction = 1.0;
    table.restitution = 0.2;
    s.obstacles.push(table);
    let a_half = Vec3::new(0.15, 0.05, 0.01);
    let shape = Geometry::compound(vec![
        (Isometry3::identity(), Geometry::cuboid(a_half).unwrap()),
        (
            Isometry3::translation(dx, 0.0, dz),
            Geometry::cuboid(Vec3::new(0.05, 0.05, 0.01)).unwrap(),
        ),
    ])
    .unwrap();
    let com = shape.mass_properties(1000.0).unwrap().com;
    let q = UnitQuaternion::from_axis_angle(&Unit::new_normalize(Vec3::y()), -tilt);
    // A's centre at x = 0.1 m and its lowest corner 1 µm above the top.
    let corner = Vec3::new(-a_half.x, 0.0, -a_half.z);
    let mut x = Vec3::new(0.1, 0.0, 0.0) + q * com;
    x.z += TOP + 1e-6 - (x.z + (q * (corner - com)).z);
    let mut b = testkit::body("plate", shape, x);
    b.orientation = q.scaled_axis();
    b.restitution = 0.2;
    b.friction = 1.0;
    s.bodies.push(b);
    s
}

fn run(s: &Scene) -> Trajectory {
    simulate(s, &Controls::new(s), &SimOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// The hinges of body 0 (start time, pivot).
fn hinges(tr: &Trajectory) -> Vec<(f64, &Pivot)> {
    tr.tracks[0]
        .segments
        .iter()
        .filter_map(|seg| seg.pivot.as_deref().map(|p| (seg.t0, p)))
        .collect()
}

/// The plate lands on its end edge and rolls down onto its face as a
/// hinge, the block hanging 2 cm below the top's plane beyond the edge:
/// it lands, energy is kept while it turns, it never enters the table,
/// and it comes to a stop lying on the top in a handful of events. (With
/// the block below the plane the hinge was refused, the plate rocking
/// down in micro-collisions at the end edge.)
#[test]
fn a_plate_with_a_block_hanging_over_the_edge_rolls_onto_its_face_as_a_hinge() {
    let s = across_the_edge(0.3, -0.03, 0.03);
    let tr = run(&s);
    let hinges = hinges(&tr);
    let (t0, first) = hinges.first().copied().unwrap_or_else(|| {
        panic!("no hinge: {:?}", tr.signature());
    });
    assert_eq!(first.overhang, vec![1], "the block is not the overhang");
    assert_eq!(first.end, PivotEnd::Lands);
    let scale = tr.dynamics[0].mass * 9.81 * 0.3;
    let e0 = testkit::energy(&tr, 0, t0);
    for i in 1..100 {
        let t = t0 + first.duration * f64::from(i) / 100.0;
        let e = testkit::energy(&tr, 0, t);
        assert!(
            (e - e0).abs() <= 1e-9 * scale,
            "energy changed by {:.3e} J at t = {t}",
            e - e0
        );
    }
    let low = testkit::lowest_gap(&s, &tr, 600);
    assert!(
        low > -1.5e-9,
        "the plate reaches {low:.3e} m into the table"
    );
    assert!(
        tr.events.len() <= 20,
        "{} events: {:?}",
        tr.events.len(),
        tr.signature()
    );
    // It ends lying on the top (sliding on it, stopped by friction).
    let last = tr.tracks[0].segments.last().unwrap();
    assert!(
        last.rest || last.slide.is_some_and(|sl| sl.obstacle == 1),
        "it does not end lying on the table"
    );
    let end = tr.state(0, s.duration, Side::Post);
    assert!(end.v.norm() + end.w.norm() < 1e-9, "still moving: {end:?}");
    // The block still hangs beyond the edge, below the top.
    let block = end.point(&(Vec3::new(0.3, 0.0, -0.03) - Vec3::new(0.075, 0.0, -0.0075)));
    assert!(
        block.x > EDGE && block.z < TOP,
        "the block ends at {block:?}"
    );
}

/// The hanging part is searched against the table while the plate turns:
/// a block hanging 10 cm down, 2 mm from the table's side, swings into
/// the side as the plate rolls down, and that contact ends the hinge in an
/// impact of the block, with no part entering the table.
#[test]
fn a_hanging_block_that_swings_into_the_tables_side_ends_the_hinge() {
    let s = across_the_edge(0.2494, -0.1, 0.03);
    // The block starts 1–3 mm from the side.
    let b = &s.bodies[0];
    let pose = Isometry3::from_parts(
        b.position.into(),
        UnitQuaternion::from_scaled_axis(b.orientation),
    );
    let parts = nudge::geometry::part_contacts(
        &b.geometry,
        &pose,
        &s.obstacles[1].geometry,
        &s.obstacles[1].pose,
        1.0,
    );
    let side = parts.iter().find(|c| c.part_a == 1).map(|c| c.distance);
    assert!(
        side.is_some_and(|d| (1e-3..3e-3).contains(&d)),
        "block to side: {side:?}"
    );
    let tr = run(&s);
    let hinges = hinges(&tr);
    let (t0, first) = hinges.first().copied().unwrap_or_else(|| {
        panic!("no hinge: {:?}", tr.signature());
    });
    assert_eq!(first.overhang, vec![1]);
    let end = t0 + first.duration;
    let hit = tr
        .events
        .iter()
        .find(|e| e.t > t0 && e.t <= end + 1e-12)
        .unwrap_or_else(|| panic!("no impact ends the hinge: {:?}", tr.signature()));
    assert!(hit.key.starts_with("1:"), "the hinge ends at {}", hit.key);
    let low = testkit::lowest_gap(&s, &tr, 600);
    assert!(
        low > -1.5e-9,
        "the plate reaches {low:.3e} m into the table"
    );
}
