//! A box lying on a face of a box obstacle (a table) slides on it in
//! closed form, as on a half-space (`sim::rest`, rule 2), until its centre
//! of mass reaches the face's edge (`sim::rest::face`): the stopping
//! distance and the time it reaches the edge against their closed forms,
//! the Jacobian through the slide and its end against central differences,
//! and a part of the obstacle beside the face still struck.

use nudge::controls::Controls;
use nudge::geometry::Geometry;
use nudge::math::Vec3;
use nudge::scene::{Block, Scene};
use nudge::sim::{Side, SimOptions, Trajectory, simulate};
use nudge::testkit::{self, body, ground, obstacle};

const G: f64 = 9.81;
/// The table's top face: z = 0.5, |x|, |y| ≤ 0.5.
const TOP: f64 = 0.5;
/// The box's half height.
const H: f64 = 0.05;

/// A 20 × 20 × 10 cm box dropped flat from `drop` above the table with
/// horizontal velocity `v0`; `mu`: the friction of both (0: none).
fn box_on_table(v0: Vec3, drop: f64, mu: f64, duration: f64) -> Scene {
    let mut s = testkit::scene(duration);
    s.effects.friction = mu > 0.0;
    let cuboid = |h: Vec3| Geometry::cuboid(h).expect("cuboid");
    let mut b = body(
        "box",
        cuboid(Vec3::new(0.1, 0.1, H)),
        Vec3::new(0.0, 0.0, TOP + H + drop),
    );
    b.velocity = v0;
    b.restitution = 0.0;
    b.friction = mu;
    s.bodies.push(b);
    let mut table = obstacle(
        "table",
        cuboid(Vec3::new(0.5, 0.5, 0.05)),
        Vec3::new(0.0, 0.0, TOP - 0.05),
    );
    table.friction = mu;
    table.restitution = 0.0;
    s.obstacles.push(table);
    s.obstacles.push(ground());
    s
}

fn run(scene: &Scene, tangent: bool) -> Trajectory {
    let opts = if tangent {
        SimOptions::default()
    } else {
        SimOptions::without_tangents()
    };
    simulate(scene, &Controls::new(scene), &opts).expect("simulates")
}

/// The landing that starts the slide, its time and the state after it.
fn slide_start(tr: &Trajectory) -> (f64, nudge::sim::BodyState) {
    let e = tr
        .events
        .iter()
        .find(|e| e.slide.is_some_and(|s| s.face.is_some()))
        .unwrap_or_else(|| panic!("no slide on the table's face: {:?}", tr.signature()));
    (e.t, tr.state(0, e.t, Side::Post))
}

/// With friction the box stops `v²/2μg` from where the slide starts, in
/// the landing's few events, and stays on the table (it used to chatter in
/// some 200 micro-collisions and stop short).
#[test]
fn a_box_sliding_on_a_table_stops_at_v_squared_over_two_mu_g() {
    let mu = 0.5;
    let tr = run(
        &box_on_table(Vec3::new(1.0, 0.0, 0.0), 1e-4, mu, 1.0),
        false,
    );
    assert!(tr.events.len() <= 4, "{:?}", tr.signature());
    let (_, s) = slide_start(&tr);
    let end = tr.state(0, 1.0, Side::Post);
    let travel = s.v.norm_squared() / (2.0 * mu * G);
    let moved = end.x - s.x;
    eprintln!("slid {:.12} m; v²/2μg = {travel:.12} m", moved.norm());
    assert!((moved.norm() - travel).abs() < 1e-9, "{moved:?}");
    assert!(moved.normalize().dot(&s.v.normalize()) > 1.0 - 1e-12);
    assert!((end.x.z - (TOP + H)).abs() < 1e-9, "{:?}", end.x);
    assert_eq!((end.v.norm(), end.w.norm()), (0.0, 0.0));
}

/// Without friction the slide ends when the centre of mass reaches the
/// table's edge, at `(0.5 − x₀)/v`; the box then tips over the edge and
/// ends on the ground.
#[test]
fn a_frictionless_slide_ends_where_the_centre_of_mass_reaches_the_edge() {
    let v = 1.0;
    let tr = run(&box_on_table(Vec3::new(v, 0.0, 0.0), 0.01, 0.0, 1.2), false);
    let (t0, s) = slide_start(&tr);
    let edge = t0 + (0.5 - s.x.x) / v;
    let seg = &tr.tracks[0].segments;
    let k = seg
        .iter()
        .position(|g| g.slide.is_some_and(|s| s.face.is_some()))
        .expect("a face slide");
    let off = seg.get(k + 1).expect("the slide ends").t0;
    eprintln!("slide ends at {off:.12} s; (0.5 − x₀)/v: {edge:.12} s");
    assert!((off - edge).abs() < 1e-9);
    let s_off = tr.state(0, off, Side::Post);
    assert!((s_off.x.x - 0.5).abs() < 1e-7 && (s_off.x.z - (TOP + H)).abs() < 1e-12);
    let end = tr.state(0, 1.2, Side::Post);
    assert!(end.x.z < 0.2, "not on the ground: {:?}", end.x);
}

/// The Jacobian through the landing, the slide and the slide's end (the
/// saltation of the switch from sliding to free flight) against central
/// differences, in the instants before the box strikes the edge again.
#[test]
fn the_jacobian_through_a_face_slide_and_its_end_matches_central_differences() {
    let v0 = Vec3::new(1.0, 0.2, 0.0);
    let probe = run(&box_on_table(v0, 0.01, 0.0, 1.2), true);
    let seg = &probe.tracks[0].segments;
    let k = seg
        .iter()
        .position(|g| g.slide.is_some_and(|s| s.face.is_some()))
        .expect("a face slide");
    let (t0, off) = (seg[k].t0, seg[k + 1].t0);
    let next = probe.events.iter().find(|e| e.t > off).map_or(1.2, |e| e.t);
    assert!(next > off + 1e-5, "struck again at once: {next} vs {off}");
    // End the run between the slide's end and the next impact.
    let mut scene = box_on_table(v0, 0.01, 0.0, off + 0.5 * (next - off));
    // Position and velocity: a turned or spinning box lands on a corner
    // first, which is the landing's business, not the slide's.
    scene.bodies[0].free = vec![Block::Position, Block::Velocity];
    let tr = run(&scene, true);
    assert!(tr.tangent_error.is_none(), "{:?}", tr.tangent_error);
    let after = scene.duration;
    let (worst, comparable) =
        testkit::check_against_central(&scene, &[0.5 * (t0 + off), after], 1e-6);
    assert!(comparable.iter().all(|c| *c), "{comparable:?}");
    // The saltation is what moves v_z after the end: `g dτ/du`.
    let j = tr.jacobian(0, after, Side::Post).expect("jacobian");
    assert!(j.row(8).norm() > 1.0, "{j:.4}");
    eprintln!("slide ends at {off:.6} s; worst relative error {worst:.2e}");
}

/// A post standing on the table is a part of the same obstacle: a box
/// sliding on the table's face strikes it.
#[test]
fn a_part_standing_on_the_face_is_struck_by_the_sliding_box() {
    let mut scene = box_on_table(Vec3::new(1.0, 0.0, 0.0), 0.01, 0.0, 1.0);
    let cuboid = |h: Vec3| Geometry::cuboid(h).expect("cuboid");
    let top = cuboid(Vec3::new(0.5, 0.5, 0.05));
    let post = cuboid(Vec3::new(0.02, 0.3, 0.1));
    let table = Geometry::compound(vec![
        (nalgebra::Isometry3::identity(), top),
        (nalgebra::Isometry3::translation(0.35, 0.0, 0.15), post),
    ])
    .expect("compound");
    scene.obstacles[0].geometry = table;
    let tr = run(&scene, false);
    let (t0, s) = slide_start(&tr);
    // The box's leading face meets the post's at x = 0.33.
    let hit = t0 + (0.33 - 0.1 - s.x.x) / s.v.x;
    let e = tr
        .events
        .iter()
        .find(|e| e.t > t0 + 1e-9)
        .expect("struck the post");
    eprintln!("struck at {:.9} s (closed form {hit:.9}): {}", e.t, e.key);
    assert!((e.t - hit).abs() < 1e-6, "{} vs {hit}", e.t);
    assert!(tr.state(0, 1.0, Side::Post).x.x < 0.33);
}

/// A ball set down on the table slips, rolls (`sim::roll`), and rolls on
/// until its centre reaches the table's edge: the end is measured from the
/// switch to rolling, at the rolling speed `5 v₀ / 7`.
#[test]
fn a_ball_rolls_to_the_tables_edge() {
    let (r, v0, mu) = (0.05, 1.0, 0.5);
    let mut scene = box_on_table(Vec3::zeros(), 0.0, mu, 1.2);
    scene.bodies[0] = {
        let mut b = body(
            "ball",
            Geometry::sphere(r).expect("ball"),
            Vec3::new(0.0, 0.0, TOP + r),
        );
        b.velocity = Vec3::new(v0, 0.0, 0.0);
        b.restitution = 0.0;
        b.friction = mu;
        b
    };
    let tr = run(&scene, false);
    let switch = tr.events.iter().find(|e| e.roll).expect("rolls");
    let s = tr.state(0, switch.t, Side::Post);
    assert!((s.v.x - 5.0 * v0 / 7.0).abs() < 1e-9, "{:?}", s.v);
    let edge = switch.t + (0.5 - s.x.x) / s.v.x;
    let off = tr.tracks[0]
        .segments
        .iter()
        .find(|g| g.t0 > switch.t)
        .expect("the rolling slide ends")
        .t0;
    eprintln!("rolls off at {off:.12} s; from the switch: {edge:.12} s");
    assert!((off - edge).abs() < 1e-9);
    assert!(tr.state(0, 1.2, Side::Post).x.z < 0.2, "not on the ground");
}
