//! Pivoting on an edge instead of chattering on it (docs/design.md §4,
//! `sim::pivot`): a body standing or rocking on an edge turns about it as a
//! hinge and lands on its face in a few events; one whose edge slips skids,
//! on a half-space or a face of a hull.

use nudge::controls::Controls;
use nudge::geometry::Geometry;
use nudge::math::Vec3;
use nudge::scene::Scene;
use nudge::sim::{PivotEnd, Side, SimOptions, TangentError, Trajectory, simulate};
use nudge::testkit;

fn run(s: &Scene, opts: &SimOptions) -> Trajectory {
    simulate(s, &Controls::new(s), opts).unwrap_or_else(|e| panic!("{e}"))
}

/// A 30 × 20 × 10 cm box tipped 0.35 rad about x onto its long edge,
/// dropped 0.1 mm onto a grippy floor (friction 1, restitution 0.2).
fn tipped_box() -> Scene {
    let mut s = testkit::on_ground(2.0, 1.0);
    let half = Vec3::new(0.15, 0.1, 0.05);
    let tilt = 0.35_f64;
    // Lowest edge: the corner line at y = +0.1, z = −0.05 in the body frame.
    let low = 0.1 * tilt.sin() + 0.05 * tilt.cos();
    let mut b = testkit::body(
        "box",
        Geometry::cuboid(half).unwrap(),
        Vec3::new(0.0, 0.0, low + 1e-4),
    );
    b.orientation = Vec3::new(tilt, 0.0, 0.0);
    b.restitution = 0.2;
    b.friction = 1.0;
    s.bodies.push(b);
    s
}

/// The box topples onto its broad face: a pivot about the edge, a landing,
/// rest lying flat — a few events, where micro-collisions took hundreds.
#[test]
fn a_box_tipped_onto_an_edge_pivots_over_and_rests_flat_in_a_few_events() {
    let s = tipped_box();
    let tr = run(&s, &SimOptions::default());
    let pivots = pivots(&tr);
    assert!(!pivots.is_empty(), "no pivot: {:?}", tr.signature());
    assert!(
        pivots.iter().any(|(_, p)| p.end == PivotEnd::Lands),
        "no pivot lands on a face"
    );
    let end = rests_flat_in_a_few_events(&tr, s.duration);
    assert!((end.x.z - 0.05).abs() < 1e-6, "centre at z = {}", end.x.z);
}

/// Asserts that body 0 took at most 30 events and rests at the end lying
/// on its broad face (its z axis vertical); its final state.
fn rests_flat_in_a_few_events(tr: &Trajectory, duration: f64) -> nudge::sim::BodyState {
    let last = tr.tracks[0].segments.last().unwrap();
    assert!(last.rest, "the box does not rest: {:?}", tr.signature());
    lies_flat_in_a_few_events(tr, duration)
}

/// Asserts that body 0 took at most 30 events and lies at the end on its
/// broad face (its z axis vertical), resting or sliding; its final state.
fn lies_flat_in_a_few_events(tr: &Trajectory, duration: f64) -> nudge::sim::BodyState {
    assert!(
        tr.events.len() <= 30,
        "{} events: {:?}",
        tr.events.len(),
        tr.signature()
    );
    let last = tr.tracks[0].segments.last().unwrap();
    assert!(
        last.rest || last.slide.is_some(),
        "neither resting nor sliding: {:?}",
        tr.signature()
    );
    let end = tr.state(0, duration, Side::Post);
    let up = (end.q * Vec3::z()).z.abs();
    assert!(
        up > 1.0 - 1e-9,
        "tilted at the end: body z · world z = {up}"
    );
    end
}

/// The hinge does no work: within a pivot the mechanical energy stays
/// put (RK4 at 0.1 ms), and no pivot starts with more than its impact left.
#[test]
fn energy_never_rises_while_pivoting() {
    let s = tipped_box();
    let tr = run(&s, &SimOptions::default());
    let segs = &tr.tracks[0].segments;
    let mut checked = 0;
    for (k, seg) in segs.iter().enumerate() {
        let Some(pv) = &seg.pivot else { continue };
        let t0 = seg.t0;
        let e0 = testkit::energy(&tr, 0, t0);
        let scale = tr.dynamics[0].mass * 9.81 * 0.1;
        for i in 1..=200 {
            let t = t0 + pv.duration * f64::from(i) / 200.0;
            let t = if k + 1 < segs.len() {
                t.min(segs[k + 1].t0 - 1e-12)
            } else {
                t
            };
            let e = testkit::energy(&tr, 0, t);
            assert!(
                e <= e0 + 1e-9 * scale,
                "energy rose by {:.3e} J at t = {t} in the pivot from {t0}",
                e - e0
            );
            assert!(
                (e - e0).abs() <= 1e-9 * scale,
                "energy drifted by {:.3e} J",
                e - e0
            );
        }
        // The impact that starts the pivot only takes energy away.
        let pre = tr
            .events
            .iter()
            .find(|e| e.t == t0)
            .map(|e| e.pre[0])
            .unwrap();
        let d = &tr.dynamics[0];
        let r = *pre.q.to_rotation_matrix().matrix();
        let ic = r * d.inertia * r.transpose();
        let before = 0.5 * (d.mass * pre.v.norm_squared() + pre.w.dot(&(ic * pre.w)))
            - d.mass * tr.gravity.dot(&pre.x);
        assert!(e0 <= before + 1e-12 * scale, "the pivot start added energy");
        checked += 1;
    }
    assert!(checked > 0, "no pivot to check");
}

/// The pivot's start and end times jump with the controls: the body's
/// Jacobian is flagged lost from the pivot on (the solver samples), and is
/// exact before it.
#[test]
fn the_jacobian_is_lost_from_a_pivot_on_and_kept_before_it() {
    let mut s = tipped_box();
    testkit::free_state(&mut s);
    let tr = run(&s, &SimOptions::default());
    let t_pivot = tr.tracks[0]
        .segments
        .iter()
        .find(|seg| seg.pivot.is_some())
        .map(|seg| seg.t0)
        .unwrap();
    assert!(tr.jacobian(0, 0.5 * t_pivot, Side::Post).is_ok());
    assert!(matches!(
        tr.jacobian(0, t_pivot, Side::Post),
        Err(TangentError::Contact { .. })
    ));
}

/// The edited landing of the scissors-bounce session (the scene its
/// keystrokes save, `tests/sessions/scissors-bounce.keys`): the scissors
/// land on the padded peg on their edge. They chattered there in some 540
/// micro-collisions over 0.45 s; pivoting, they settle in a few events and
/// rest on the peg (or slide on its face to a stop).
#[test]
fn the_scissors_bounce_landing_settles_in_a_few_events() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/rocking/scissors-bounce-edited.toml"
    );
    let s = nudge::scene::load(std::path::Path::new(path)).unwrap_or_else(|e| panic!("{e}"));
    let tr = run(&s, &SimOptions::without_tangents());
    assert!(
        tr.events.len() <= 50,
        "{} events: {:?}",
        tr.events.len(),
        tr.signature()
    );
    assert_eq!(
        tr.events
            .iter()
            .filter(|e| e.b == nudge::sim::Party::Obstacle(0))
            .count(),
        1,
        "one bounce off the floor"
    );
    // They rest, or lie on the peg's face sliding to a stop (`sim::rest`,
    // rule 2).
    let last = tr.tracks[0].segments.last().unwrap();
    let end = tr.state(0, s.duration, Side::Post);
    let stopped = last.slide.is_some() && end.v.norm() == 0.0 && end.w.norm() == 0.0;
    assert!(last.rest || stopped, "the scissors do not rest: {end:?}");
    assert!(
        (0.44..=0.68).contains(&end.x.x) && end.x.y.abs() < 0.08 && (1.31..1.40).contains(&end.x.z),
        "they end at {:?}, not on the low peg",
        end.x
    );
}

/// [`tipped_box`] on a slab that is one part of a compound obstacle, with
/// a 16 mm cube hanging from the same obstacle at `hook` (a shelf's lip,
/// a coatrack's peg): near the space the box sweeps as it topples.
fn tipped_box_beside(hook: Vec3) -> Scene {
    let mut s = tipped_box();
    let slab = Geometry::cuboid(Vec3::new(1.0, 1.0, 0.05)).unwrap();
    let cube = Geometry::cuboid(Vec3::new(0.008, 0.008, 0.008)).unwrap();
    let at = |v: Vec3| nalgebra::Isometry3::translation(v.x, v.y, v.z);
    let shelf = Geometry::compound(vec![
        (at(Vec3::new(0.0, 0.0, -0.05)), slab),
        (at(hook), cube),
    ])
    .unwrap();
    let mut o = testkit::obstacle("shelf", shelf, Vec3::zeros());
    o.friction = 1.0;
    s.obstacles = vec![o];
    s
}

/// The pivoting segments of body 0: (start time, pivot).
fn pivots(tr: &Trajectory) -> Vec<(f64, &nudge::sim::Pivot)> {
    tr.tracks[0]
        .segments
        .iter()
        .filter_map(|seg| seg.pivot.as_deref().map(|p| (seg.t0, p)))
        .collect()
}

/// Another part of the supporting obstacle near the sweep, but out of the
/// box's reach (above the far end of its landing, farther from the edge
/// than any of its corners): the box still pivots, its pair with the
/// obstacle searched against that part only, and lands and rests flat as
/// on a bare floor. (Such a part used to refuse the pivot: the box then
/// chattered on its edge.)
#[test]
fn a_part_beside_the_sweep_but_out_of_reach_leaves_the_pivot_as_it_is() {
    let s = tipped_box_beside(Vec3::new(0.0, 0.11, 0.155));
    let tr = run(&s, &SimOptions::default());
    let pv = pivots(&tr);
    assert!(
        pv.iter().any(|(_, p)| p.beside && p.end == PivotEnd::Lands),
        "no pivot beside the hook lands: {:?}",
        tr.signature()
    );
    assert!(
        tr.events.iter().all(|e| e.feature.part_b == 0),
        "the hook is touched: {:?}",
        tr.signature()
    );
    rests_flat_in_a_few_events(&tr, s.duration);
}

/// A part in the box's way as it topples ends the pivot in an impact on
/// that part, before the pivot would have landed, and the box never
/// passes into it.
#[test]
fn a_part_in_the_way_of_the_pivot_is_struck() {
    let hook = Vec3::new(0.0, 0.13, 0.09);
    let s = tipped_box_beside(hook);
    let tr = run(&s, &SimOptions::without_tangents());
    let (t0, pv) = *pivots(&tr).first().unwrap_or_else(|| {
        panic!("no pivot: {:?}", tr.signature());
    });
    assert!(pv.beside, "the hook is near the sweep");
    let struck = tr
        .events
        .iter()
        .find(|e| e.t > t0 && e.feature.part_b == 1)
        .unwrap_or_else(|| panic!("the hook is never struck: {:?}", tr.signature()));
    assert!(
        struck.t < t0 + pv.duration,
        "struck at {} after the pivot's own end {}",
        struck.t,
        t0 + pv.duration
    );
    let cube = Geometry::cuboid(Vec3::new(0.008, 0.008, 0.008)).unwrap();
    let cube_pose = nalgebra::Isometry3::translation(hook.x, hook.y, hook.z);
    let body = &s.bodies[0].geometry;
    for k in 0..=400 {
        let t = t0 + (struck.t - t0) * f64::from(k) / 400.0;
        let pose = tr.state(0, t, Side::Post).pose();
        let gap = nudge::geometry::part_contacts(body, &pose, &cube, &cube_pose, f64::INFINITY)
            .iter()
            .map(|c| c.distance)
            .fold(f64::INFINITY, f64::min);
        assert!(
            gap > -1e-6,
            "the box is {:.2e} m into the hook at t = {t}",
            -gap
        );
    }
}

/// On a slippery floor (friction 0.05 for both) the hinge cannot hold the
/// edge: the box skids (`sim::pivot::skid`), its edge sliding on the floor
/// while it turns, loses energy only to friction within each skid, and
/// ends lying flat on its broad face, sliding on, in a few events.
/// (Before skids it chattered on the slipping edge in micro-collisions.)
#[test]
fn a_box_tipped_onto_an_edge_of_a_slippery_floor_skids_and_lies_flat() {
    let mut s = tipped_box();
    s.obstacles[0].friction = 0.05;
    s.bodies[0].friction = 0.05;
    let tr = run(&s, &SimOptions::default());
    let skids: Vec<_> = pivots(&tr).into_iter().filter(|(_, p)| p.skids()).collect();
    assert!(!skids.is_empty(), "no skid: {:?}", tr.signature());
    let scale = tr.dynamics[0].mass * 9.81 * 0.1;
    for (t0, pv) in &skids {
        let e0 = testkit::energy(&tr, 0, *t0);
        let mut last = e0;
        for i in 1..=100 {
            let t = t0 + pv.duration * f64::from(i) / 100.0;
            let e = testkit::energy(&tr, 0, t.min(t0 + pv.duration - 1e-12));
            assert!(
                e <= last + 1e-9 * scale,
                "energy rose by {:.3e} J at t = {t} in the skid from {t0}",
                e - last
            );
            last = e;
        }
    }
    let end = lies_flat_in_a_few_events(&tr, s.duration);
    assert!((end.x.z - 0.05).abs() < 1e-6, "centre at z = {}", end.x.z);
}

/// Under the box's edge a 6 cm beam instead of the floor: as the box
/// topples its broad face reaches the beam's top plane 20 cm beyond the
/// beam, where there is nothing to land on. A pivot's landing is found on
/// its contact plane, so that one is refused (the box tips off the beam
/// in impacts against it), and no impact is ever off the beam (by more
/// than a millimetre: an event's point is the body's, within the support
/// band above the surface).
#[test]
fn a_pivot_never_lands_beyond_the_face_it_turns_on() {
    let tr = run(&tipped_box(), &SimOptions::without_tangents());
    let (_, pv) = *pivots(&tr).first().expect("a pivot on the floor");
    assert!(
        pv.axis.cross(&Vec3::x()).norm() < 1e-9,
        "axis {:?}",
        pv.axis
    );
    let half = Vec3::new(0.5, 0.03, 0.05);
    let centre = Vec3::new(0.0, pv.point.y, -half.z);
    let mut s = tipped_box();
    let mut beam = testkit::obstacle("beam", Geometry::cuboid(half).unwrap(), centre);
    beam.friction = 1.0;
    s.obstacles = vec![beam];
    let tr = run(&s, &SimOptions::without_tangents());
    assert!(!tr.events.is_empty(), "the box never touches the beam");
    for e in &tr.events {
        let off = (e.point - centre).abs() - half;
        assert!(
            off.max() < 1e-3,
            "an impact {:.3e} m off the beam at t = {}: {}",
            off.max(),
            e.t,
            e.key
        );
    }
}

/// The tipped box on a slippery floor (friction 0.05) sliding along x at
/// 0.3 m/s; with `slab`, on a slab (a hull) instead, its top face the
/// floor's plane, reaching that far along +x from the origin and 2 m every
/// other way.
fn skidding_box(slab: Option<f64>) -> Scene {
    let mut s = tipped_box();
    s.duration = 1.0;
    s.obstacles[0].friction = 0.05;
    s.bodies[0].friction = 0.05;
    s.bodies[0].velocity = Vec3::new(0.3, 0.0, 0.0);
    if let Some(edge) = slab {
        let half = Vec3::new(0.5 * (edge + 2.0), 2.0, 0.1);
        let centre = Vec3::new(edge - half.x, 0.0, -half.z);
        let mut o = testkit::obstacle("slab", Geometry::cuboid(half).unwrap(), centre);
        o.friction = 0.05;
        s.obstacles = vec![o];
    }
    s
}

fn skids(tr: &Trajectory) -> Vec<(f64, &nudge::sim::Pivot)> {
    pivots(tr).into_iter().filter(|(_, p)| p.skids()).collect()
}

/// On a slab far wider than the box's travel the box skids exactly as on
/// the floor (`sim::pivot::skid` on a face of a hull): the same events at
/// the same times, and the same end state to round-off.
#[test]
fn a_skid_on_a_wide_face_is_the_skid_on_a_half_space() {
    let opts = SimOptions::without_tangents();
    let floor = run(&skidding_box(None), &opts);
    let slab = run(&skidding_box(Some(2.0)), &opts);
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

/// With the slab's edge 2 cm ahead of the skidding line's front end, the
/// skid ends where that end slides off the face, on the edge.
#[test]
fn a_skid_ends_where_its_end_slides_off_the_face() {
    let opts = SimOptions::without_tangents();
    let floor = run(&skidding_box(None), &opts);
    let (_, pv) = skids(&floor)[0];
    // The skid's line runs along x: its front end is the farthest.
    let front = pv.point.x.max(pv.point.x + pv.axis.x * pv.length);
    let edge = front + 0.02;
    let tr = run(&skidding_box(Some(edge)), &opts);
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
