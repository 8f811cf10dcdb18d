//! Skids on a face of a hull (docs/design.md §4, `sim::pivot::skid`): as
//! on a half-space while the ends stay on the face, and ending where an
//! end slides off it.

use nudge::controls::Controls;
use nudge::geometry::Geometry;
use nudge::math::Vec3;
use nudge::scene::Scene;
use nudge::sim::{PivotEnd, Side, SimOptions, Trajectory, simulate};
use nudge::testkit;

fn run(s: &Scene) -> Trajectory {
    simulate(s, &Controls::new(s), &SimOptions::without_tangents())
        .unwrap_or_else(|e| panic!("{e}"))
}

/// A 30 × 20 × 10 cm box tipped 0.35 rad about x onto its long edge,
/// dropped 0.1 mm onto a slippery floor (friction 0.05, restitution 0.2),
/// sliding along x at `vx` m/s.
fn tipped_box(vx: f64) -> Scene {
    let mut s = testkit::scene(1.0);
    s.effects.friction = true;
    s.effects.gyroscopic = true;
    let mut floor = testkit::ground();
    floor.friction = 0.05;
    s.obstacles.push(floor);
    let half = Vec3::new(0.15, 0.1, 0.05);
    let tilt = 0.35_f64;
    let low = 0.1 * tilt.sin() + 0.05 * tilt.cos();
    let mut b = testkit::body(
        "box",
        Geometry::cuboid(half).unwrap(),
        Vec3::new(0.0, 0.0, low + 1e-4),
    );
    b.orientation = Vec3::new(tilt, 0.0, 0.0);
    b.velocity = Vec3::new(vx, 0.0, 0.0);
    b.restitution = 0.2;
    b.friction = 0.05;
    s.bodies.push(b);
    s
}

/// The same box on a slab (a hull) whose top face is the floor's plane,
/// reaching `edge` m along +x from the origin and 2 m every other way.
fn on_slab(vx: f64, edge: f64) -> Scene {
    let mut s = tipped_box(vx);
    let half = Vec3::new(0.5 * (edge + 2.0), 2.0, 0.1);
    let centre = Vec3::new(edge - half.x, 0.0, -half.z);
    let mut slab = testkit::obstacle("slab", Geometry::cuboid(half).unwrap(), centre);
    slab.friction = 0.05;
    s.obstacles = vec![slab];
    s
}

fn skids(tr: &Trajectory) -> Vec<(f64, &nudge::sim::Pivot)> {
    tr.tracks[0]
        .segments
        .iter()
        .filter_map(|seg| seg.pivot.as_deref().map(|p| (seg.t0, p)))
        .filter(|(_, p)| p.skids())
        .collect()
}

/// On a slab far wider than the box's travel the box skids exactly as on
/// the floor: the same events at the same times, and the same end state
/// to round-off.
#[test]
fn a_skid_on_a_wide_face_is_the_skid_on_a_half_space() {
    let floor = run(&tipped_box(0.3));
    let slab = run(&on_slab(0.3, 2.0));
    assert!(
        !skids(&floor).is_empty(),
        "no skid on the floor: {:?}",
        floor.signature()
    );
    assert_eq!(
        skids(&floor).len(),
        skids(&slab).len(),
        "{:?}",
        slab.signature()
    );
    assert_eq!(floor.events.len(), slab.events.len());
    for (a, b) in floor.events.iter().zip(&slab.events) {
        assert!(
            (a.t - b.t).abs() < 1e-12,
            "event at {} on the floor, {} on the slab",
            a.t,
            b.t
        );
    }
    let (a, b) = (
        floor.state(0, 1.0, Side::Post),
        slab.state(0, 1.0, Side::Post),
    );
    assert!((a.x - b.x).norm() < 1e-12, "ends {:?} apart", a.x - b.x);
}

/// With the slab's edge 2 cm ahead of the skidding line's corner, the skid
/// ends where that corner slides off the face, on the edge (x = 0.02).
#[test]
fn a_skid_ends_where_its_end_slides_off_the_face() {
    let floor = run(&tipped_box(0.3));
    let (_, pv) = skids(&floor)[0];
    // The skid's line runs along x: its front corner is the farthest.
    let front = pv.point.x.max(pv.point.x + pv.axis.x * pv.length);
    let edge = front + 0.02;
    let tr = run(&on_slab(0.3, edge));
    let (t1, off) = *skids(&tr)
        .first()
        .unwrap_or_else(|| panic!("no skid: {:?}", tr.signature()));
    assert_eq!(off.end, PivotEnd::OffFace, "{:?}", tr.signature());
    // The line's ends, followed in the body from the skid's start.
    let s1 = tr.state(0, t1, Side::Post);
    let ends = [off.point, off.point + off.axis * off.length].map(|e| s1.q.inverse() * (e - s1.x));
    let end = tr.state(0, t1 + off.duration, Side::Pre);
    let lead = ends
        .iter()
        .map(|v| end.point(v).x)
        .fold(f64::NEG_INFINITY, f64::max);
    assert!(
        (lead - edge).abs() < 1e-9,
        "the front end at x = {lead}, the edge at {edge}"
    );
}
