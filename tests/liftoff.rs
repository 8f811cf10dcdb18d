//! Jacobians through resting contact between bodies: a ball that comes to
//! rest on a box (an island with the ground) and is struck off it from
//! below keeps its tangent through freezing, resting and lifting off; the
//! tangent matches central differences on the columns whose perturbation
//! keeps the event sequence (docs/design.md §4, "Jacobians" in
//! src/sim/run/islands.rs).

use nudge::controls::Controls;
use nudge::geometry::Geometry;
use nudge::math::Vec3;
use nudge::scene::{Block, Scene};
use nudge::sim::{Party, Side, SimOptions, Trajectory, simulate};
use nudge::tangent::{FiniteDifference, Scheme};
use nudge::testkit;

const G: f64 = 9.81;
/// Box half side, resting ball and striker radii, m.
const H: f64 = 0.1;
const R: f64 = 0.05;
const RS: f64 = 0.04;
/// When the striker arrives, s.
const T_HIT: f64 = 0.08;

/// A box on the ground with a ball dropped onto its top near its left
/// edge (it rests there from about 0.03 s on), struck at `T_HIT` by a
/// lighter ball rising from the left along the line of centres, 25° up:
/// the resting ball lifts off over the box and lands on the ground at
/// about 0.4 s, the striker bounces back. The free controls are the striker's position and velocity
/// and the resting ball's position.
fn struck_ball() -> Scene {
    let mut s = testkit::scene(0.5);
    s.obstacles.push(testkit::ground());
    let cube = Geometry::cuboid(Vec3::repeat(H)).expect("cube");
    let mut block = testkit::body("box", cube, Vec3::new(0.0, 0.0, H + 1e-3));
    block.restitution = 0.3;
    let top = 2.0 * H + 1e-3 + R;
    let mut ball = testkit::body(
        "ball",
        Geometry::sphere(R).expect("ball"),
        Vec3::new(-0.085, 0.0, top + 2e-3),
    );
    ball.restitution = 0.3;
    ball.free = vec![Block::Position];
    // Where the striker touches the resting ball at T_HIT, 25° below its
    // centre on the left, moving at 4 m/s along the line of centres.
    let up = 25f64.to_radians();
    let dir = Vec3::new(up.cos(), 0.0, up.sin());
    let at_hit = Vec3::new(-0.085, 0.0, top) - dir * (R + RS);
    let v_hit = dir * 4.0;
    let g = Vec3::new(0.0, 0.0, -G);
    let v0 = v_hit - g * T_HIT;
    let x0 = at_hit - v0 * T_HIT - g * (0.5 * T_HIT * T_HIT);
    let mut striker = testkit::body("striker", Geometry::sphere(RS).expect("ball"), x0);
    striker.velocity = v0;
    striker.restitution = 0.9;
    striker.free = vec![Block::Position, Block::Velocity];
    s.bodies = vec![block, ball, striker];
    s.pairs = vec![[0, 1], [0, 2], [1, 2]];
    s
}

fn run(s: &Scene) -> Trajectory {
    simulate(s, &Controls::new(s), &SimOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn a_ball_rests_on_a_box_and_the_strike_lifts_it_off() {
    let s = struck_ball();
    let tr = run(&s);
    let hit = tr
        .events
        .iter()
        .find(|e| e.b == Party::Body(2))
        .unwrap_or_else(|| panic!("the striker misses"));
    assert_eq!(hit.a, 1, "the striker hits the resting ball first");
    assert!((hit.t - T_HIT).abs() < 0.01, "hit at {}", hit.t);
    assert!(tr.resting(1, hit.t, Side::Pre), "the ball rests before");
    assert!(tr.resting(0, hit.t, Side::Pre), "the box rests before");
    let after = tr.state(1, hit.t, Side::Post);
    assert!(after.v.z > 0.5, "the ball lifts off: {:?}", after.v);
    // Every Jacobian is kept: through the ball's freezing on the box, its
    // rest and the strike.
    assert!(tr.tangent_error.is_none(), "{:?}", tr.tangent_error);
    for b in 0..3 {
        assert!(tr.jacobian(b, 0.5, Side::Post).is_ok(), "body {b}");
    }
}

/// Over the columns whose event sequence up to `t` is unchanged and whose
/// central difference quotients (steps 1e-6 down to 1.5e-8) resolve it,
/// the tangent's worst disagreement with the closest quotient, relative to
/// the column; and how many columns that was.
fn disagreement(s: &Scene, tr: &Trajectory, body: usize, t: f64) -> (f64, usize) {
    let controls = Controls::new(s);
    let jt = tr.jacobian(body, t, Side::Post).expect("tangent");
    let runs: Vec<FiniteDifference> = [1e-6, 2.5e-7, 6.25e-8, 1.5e-8]
        .iter()
        .map(|h| {
            FiniteDifference::with_steps(s, &controls, Scheme::Central, Some(*h)).expect("runs")
        })
        .collect();
    testkit::resolved_agreement(&runs, &jt, body, t).unwrap_or((0.0, 0))
}

#[test]
fn the_jacobian_through_rest_and_lift_off_matches_central_differences() {
    let mut s = struck_ball();
    s.accuracy.root_tol = 1e-14;
    let tr = run(&s);
    let m = Controls::new(&s).m();
    // Resting on the box before the strike; in flight after it; and the
    // striker after the strike.
    for (body, t) in [(1, 0.07), (1, 0.2), (1, 0.35), (2, 0.3)] {
        let (err, compared) = disagreement(&s, &tr, body, t);
        assert!(
            compared >= m - 3,
            "body {body} at {t} s: only {compared} of {m} columns keep the events"
        );
        assert!(err < 1e-6, "body {body} at {t} s: relative error {err:.2e}");
    }
}
