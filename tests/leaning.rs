//! Leaning on two surfaces with different normals (docs/design.md §4,
//! `sim::pivot::lean`): a body touching a floor and a wall at one corner
//! each turns about the line through both as a hinge, instead of
//! chattering in micro-collisions between them.

use nudge::controls::Controls;
use nudge::geometry::Geometry;
use nudge::math::Vec3;
use nudge::scene::Scene;
use nudge::sim::{PivotEnd, Side, SimOptions, TangentError, Trajectory, simulate};
use nudge::testkit;

fn run(s: &Scene, opts: &SimOptions) -> Trajectory {
    simulate(s, &Controls::new(s), opts).unwrap_or_else(|e| panic!("{e}"))
}

/// An 80 × 4 × 4 cm rod, pitched 1.05 rad up from the floor, rolled 0.3
/// rad about its length and turned `yaw` about the vertical, dropped 0.1 mm
/// into the corner of one obstacle: a floor slab (top at z = 0) and a wall
/// (face at x = 0.3), both with friction 1. Its lowest corner is over the
/// floor and its farthest corner touches the wall. Simulated for 1.5 s.
fn rod_in_corner(yaw: f64) -> Scene {
    let mut s = leaning_rod(yaw, 1.05, 1.0);
    s.duration = 1.5;
    s
}

/// [`rod_in_corner`] pitched `pitch` rad up, with friction `mu` on the rod
/// and on both surfaces.
fn leaning_rod(yaw: f64, pitch: f64, mu: f64) -> Scene {
    let mut s = testkit::on_ground(1.0, 1.0);
    let at = |v: Vec3| nalgebra::Isometry3::translation(v.x, v.y, v.z);
    let corner = Geometry::compound(vec![
        (
            at(Vec3::new(-0.5, 0.0, -0.05)),
            Geometry::cuboid(Vec3::new(1.0, 1.0, 0.05)).unwrap(),
        ),
        (
            at(Vec3::new(0.35, 0.0, 1.0)),
            Geometry::cuboid(Vec3::new(0.05, 1.0, 1.0)).unwrap(),
        ),
    ])
    .unwrap();
    let mut o = testkit::obstacle("corner", corner, Vec3::zeros());
    o.friction = mu;
    s.obstacles = vec![o];
    let half = Vec3::new(0.4, 0.02, 0.02);
    let turn = |axis: Vec3, angle: f64| {
        nalgebra::UnitQuaternion::from_axis_angle(&nalgebra::Unit::new_normalize(axis), angle)
    };
    let q = turn(Vec3::z(), yaw) * turn(Vec3::y(), -pitch) * turn(Vec3::x(), 0.3);
    let corners: Vec<Vec3> = (0..8)
        .map(|k| {
            let sign = |bit: usize| if k >> bit & 1 == 1 { 1.0 } else { -1.0 };
            q * Vec3::new(sign(0) * half.x, sign(1) * half.y, sign(2) * half.z)
        })
        .collect();
    let low = corners.iter().map(|c| c.z).fold(f64::INFINITY, f64::min);
    let far = corners
        .iter()
        .map(|c| c.x)
        .fold(f64::NEG_INFINITY, f64::max);
    let mut b = testkit::body(
        "rod",
        Geometry::cuboid(half).unwrap(),
        Vec3::new(0.3 - far, 0.0, 1e-4 - low),
    );
    b.orientation = q.scaled_axis();
    b.restitution = 0.2;
    b.friction = mu;
    s.bodies.push(b);
    s
}

/// The leaning segments of body 0: (start time, pivot).
fn leans(tr: &Trajectory) -> Vec<(f64, &nudge::sim::Pivot)> {
    tr.tracks[0]
        .segments
        .iter()
        .filter_map(|seg| seg.pivot.as_deref().map(|p| (seg.t0, p)))
        .filter(|(_, p)| p.lean.is_some())
        .collect()
}

/// The rod rolls about the line from its floor corner to its wall corner,
/// landing on the floor and on the wall in turn, and comes to rest leaning
/// in the corner: 25 events, and 98 with the turn about the vertical,
/// where micro-collisions between the two surfaces took 436. How long the
/// turned rod rocks is sensitive to round-off: with its impacts found
/// 1e-8 s apart (GJK's distances against exact ones) it rested after 66
/// events at 0.89 s, or after 98 at 1.25 s; hence 1.5 s and the bound of
/// 150. Turned the other way (yaw −0.25) a lean lands on the wall; turned
/// by 0.2 the rod chatters on both surfaces after its first lean and is
/// stepped into the corner (`sim::pivot::stepped`) before one does.
#[test]
fn a_rod_leaning_into_a_corner_rolls_about_its_supports_and_rests() {
    for yaw in [0.0, 0.2] {
        let s = rod_in_corner(yaw);
        let tr = run(&s, &SimOptions::default());
        let leans = leans(&tr);
        assert!(
            !leans.is_empty(),
            "yaw {yaw}: no lean: {:?}",
            tr.signature()
        );
        assert!(
            leans.iter().all(|(_, p)| p.end == PivotEnd::Lands),
            "yaw {yaw}: a lean that does not land"
        );
        assert!(
            tr.events.len() < 150,
            "yaw {yaw}: {} events: {:?}",
            tr.events.len(),
            tr.signature()
        );
        let last = tr.tracks[0].segments.last().unwrap();
        assert!(last.rest, "yaw {yaw}: the rod does not rest");
        // Resting on the floor and against the wall: the centre where the
        // rod, still pitched up, leans into the corner.
        let end = tr.state(0, s.duration, Side::Post);
        assert!(
            (0.35..0.36).contains(&end.x.z) && (0.08..0.09).contains(&end.x.x),
            "yaw {yaw}: ends at {:?}",
            end.x
        );
    }
    let turned = leans(&run(&rod_in_corner(-0.25), &SimOptions::default()))
        .iter()
        .filter(|(_, p)| p.lands_on_lean)
        .count();
    assert!(turned > 0, "no lean lands on the wall");
}

/// Neither surface is entered: the rod's gap to the obstacle, sampled
/// every millisecond and at every event, is never below the event
/// tolerance. (Landing flat on its end while against the wall, the rod
/// reached 1.5e-8 m into the floor: the event search's fixed plane, from a
/// contact normal tilted by 1e-6 rad, let a corner sink below the floor.)
#[test]
fn a_leaning_rod_never_enters_the_floor_or_the_wall() {
    let s = rod_in_corner(0.2);
    let low = testkit::lowest_gap(&s, &run(&s, &SimOptions::default()), 1000);
    // The event skin (1e-9 m: a pair just struck may sink that far before
    // it is struck again) and a little more. 5e-8 s after the rod's end
    // edge strikes the wall, the contact query reports the pair 5e-10 m
    // apart while one end of the edge is 1.7e-9 m inside: the search takes
    // such a contact at its deepest approaching corner
    // (`sim::events::sinking`); trusting the query it let the end reach
    // 2.4e-9 m in.
    assert!(
        low > -1.5e-9,
        "the rod reaches {low:.3e} m into the obstacle"
    );
}

/// Rods leaning at 45 pitches, yaws and frictions: every run finishes,
/// none enters the floor or the wall by more than the skin and a little,
/// and every lean ends in a finite state. (The deepest reaches 1.1e-9 m.
/// After a patch impact on the wall a corner still sank at 3.5 cm/s where
/// the contact query's witness rose, and the search found it only 3e-8 s
/// later, 2.4e-9 m in, until it took the deepest approaching corner
/// instead, `sim::events::sinking`; the tilted search plane had let
/// 1.5e-8 m through.)
#[test]
fn leaning_rods_across_pitches_yaws_and_frictions_stay_out_of_the_corner() {
    let mut leaned = 0;
    for pitch in [0.8, 1.05, 1.3] {
        for yaw in [-0.5, -0.25, 0.0, 0.25, 0.5] {
            for mu in [0.3, 0.6, 1.2] {
                let s = leaning_rod(yaw, pitch, mu);
                let tr = simulate(&s, &Controls::new(&s), &SimOptions::without_tangents())
                    .unwrap_or_else(|e| panic!("pitch {pitch} yaw {yaw} mu {mu}: {e}"));
                let low = testkit::lowest_gap(&s, &tr, 1000);
                assert!(
                    low > -1.5e-9,
                    "pitch {pitch} yaw {yaw} mu {mu}: the rod reaches {low:.3e} m in"
                );
                for (t0, pv) in leans(&tr) {
                    let end = tr.state(0, t0 + pv.duration, Side::Pre);
                    assert!(
                        end.x.iter().chain(end.v.iter()).all(|v| v.is_finite()),
                        "pitch {pitch} yaw {yaw} mu {mu}: lean from {t0} ends at {end:?}"
                    );
                    leaned += 1;
                }
            }
        }
    }
    assert!(leaned > 0);
}

/// The hinge does no work: while the rod leans, its mechanical energy
/// does not rise; and its Jacobian is lost from the first lean on, as
/// through any pivot.
#[test]
fn energy_never_rises_while_leaning_and_the_jacobian_is_flagged_lost() {
    let s = rod_in_corner(0.2);
    let tr = run(&s, &SimOptions::default());
    let scale = tr.dynamics[0].mass * 9.81 * 0.4;
    let mut checked = 0;
    for (t0, pv) in leans(&tr) {
        let e0 = testkit::energy(&tr, 0, t0);
        for i in 1..200 {
            let t = t0 + pv.duration * f64::from(i) / 200.0;
            let e = testkit::energy(&tr, 0, t);
            assert!(
                (e - e0).abs() <= 1e-9 * scale,
                "energy changed by {:.3e} J at t = {t} in the lean from {t0}",
                e - e0
            );
            checked += 1;
        }
    }
    assert!(checked > 0);
    let mut free = s.clone();
    testkit::free_state(&mut free);
    let with = run(&free, &SimOptions::default());
    let first = leans(&with)[0].0;
    assert!(with.jacobian(0, 0.5 * first, Side::Post).is_ok());
    assert!(matches!(
        with.jacobian(0, first, Side::Post),
        Err(TangentError::Contact { .. })
    ));
}
