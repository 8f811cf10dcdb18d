//! A ball sent sliding along a floor slows under friction and rolls
//! without slipping (`src/sim/roll.rs`): the switch time, the rolling
//! speed and the tangents against their closed forms, the Jacobian
//! against central differences, back-spin, and energy.

use nudge::controls::Controls;
use nudge::geometry::Geometry;
use nudge::math::Vec3;
use nudge::scene::{Block, Scene};
use nudge::sim::{Side, SimOptions, Trajectory, simulate};
use nudge::testkit::{self, body, ground};

const R: f64 = 0.1;
const G: f64 = 9.81;
/// Pair friction: √(0.5 · 0.5), the test kit's body and ground.
const MU: f64 = 0.5;

/// A solid ball of radius `R` on the ground (or `drop` above it), thrown
/// with `v0` and `w0`; it lands without bouncing (restitution 0).
fn ball(v0: Vec3, w0: Vec3, drop: f64, duration: f64) -> Scene {
    let mut s = testkit::scene(duration);
    s.effects.friction = true;
    let mut b = body(
        "ball",
        Geometry::sphere(R).expect("ball"),
        Vec3::new(0.0, 0.0, R + drop),
    );
    b.velocity = v0;
    b.angular_velocity = w0;
    b.restitution = 0.0;
    s.bodies.push(b);
    s.obstacles.push(ground());
    s
}

fn run(scene: &Scene, tangent: bool) -> Trajectory {
    let controls = Controls::new(scene);
    let opts = if tangent {
        SimOptions::default()
    } else {
        SimOptions::without_tangents()
    };
    simulate(scene, &controls, &opts).expect("simulates")
}

/// The slide's start (an impact) and the switch to rolling.
fn slide_and_switch(tr: &Trajectory) -> (f64, f64) {
    let kinds: Vec<String> = tr.signature();
    assert_eq!(kinds.len(), 2, "{kinds:?}");
    assert!(
        kinds[0].ends_with("|slide") && kinds[1].ends_with("|roll"),
        "{kinds:?}"
    );
    (tr.events[0].t, tr.events[1].t)
}

fn energy(tr: &Trajectory, t: f64) -> f64 {
    let s = tr.state(0, t, Side::Post);
    let d = &tr.dynamics[0];
    0.5 * d.mass * s.v.norm_squared() + 0.5 * s.w.dot(&(d.inertia * s.w)) + d.mass * G * s.x.z
}

/// Energy sampled finely and at every event never rises (beyond round-off).
fn assert_energy_never_rises(tr: &Trajectory) {
    let mut times: Vec<f64> = (0..=400).map(|k| tr.duration * k as f64 / 400.0).collect();
    times.extend(tr.events.iter().map(|e| e.t));
    times.sort_by(f64::total_cmp);
    let e0 = energy(tr, 0.0);
    let mut last = e0;
    for t in times {
        let e = energy(tr, t);
        assert!(e <= last + 1e-12 * e0, "energy rose at t={t}: {last} → {e}");
        last = e;
    }
}

/// Set down with `v0` and no spin: slips for `t* = 2 v₀ / 7 μ g`, rolls
/// at `5 v₀ / 7` with `ω = n × v / r`.
#[test]
fn a_ball_thrown_without_spin_slips_for_2v0_over_7_mu_g_then_rolls_at_five_sevenths() {
    let v0 = 2.0;
    let scene = ball(Vec3::new(v0, 0.0, 0.0), Vec3::zeros(), 0.0, 1.0);
    let tr = run(&scene, false);
    let (_, ts) = slide_and_switch(&tr);
    let t_star = 2.0 * v0 / (7.0 * MU * G);
    let end = tr.state(0, 1.0, Side::Post);
    eprintln!(
        "switch at {ts:.12} s (2 v0/7μg = {t_star:.12}), rolling at {:.12} m/s (5 v0/7 = {:.12})",
        end.v.x,
        5.0 * v0 / 7.0
    );
    assert!((ts - t_star).abs() < 1e-9, "switch {ts} vs {t_star}");
    assert!((end.v - Vec3::new(5.0 * v0 / 7.0, 0.0, 0.0)).norm() < 1e-9);
    assert!((end.w - Vec3::z().cross(&end.v) / R).norm() < 1e-9);
    // The ball does not leave the floor, nor sink.
    assert!((end.x.z - R).abs() < 1e-9);
    // The distance: slipping, then rolling.
    let a = MU * G;
    let x = v0 * t_star - 0.5 * a * t_star * t_star + 5.0 * v0 / 7.0 * (1.0 - t_star);
    assert!((end.x.x - x).abs() < 1e-9, "{} vs {x}", end.x.x);
    assert_energy_never_rises(&tr);
    let report = nudge::report::text(&scene, &Controls::new(&scene), &tr);
    assert!(report.contains("rolls"), "{report}");
}

/// Back-spin lengthens the slip; strong back-spin brings the ball back.
#[test]
fn a_ball_with_back_spin_slows_longer_or_comes_back() {
    let v0 = 2.0;
    for w in [30.0, 80.0] {
        // Back-spin: against rolling (ω = n × v / r points along +y).
        let scene = ball(Vec3::new(v0, 0.0, 0.0), Vec3::new(0.0, -w, 0.0), 0.0, 1.5);
        let tr = run(&scene, false);
        let (_, ts) = slide_and_switch(&tr);
        let t_star = 2.0 * (v0 + R * w) / (7.0 * MU * G);
        let v_roll = (5.0 * v0 - 2.0 * R * w) / 7.0;
        let end = tr.state(0, 1.5, Side::Post);
        eprintln!(
            "back-spin {w} rad/s: switch {ts:.9} s, rolls at {:.9} m/s",
            end.v.x
        );
        assert!((ts - t_star).abs() < 1e-9, "switch {ts} vs {t_star}");
        assert!((end.v - Vec3::new(v_roll, 0.0, 0.0)).norm() < 1e-9);
        assert!((end.w - Vec3::z().cross(&end.v) / R).norm() < 1e-9);
        assert_energy_never_rises(&tr);
    }
}

/// `∂x(T)/∂v₀` against its closed form. A ball set down exactly on the
/// floor touches it grazing (the Jacobian is lost there), so the ball is
/// dropped, without spin; the landing's friction leaves it with start
/// state `(v, ω)` at `t₀`, Jacobian `J₀`. The closed form of the slide
/// from there (`T' = T − t₀`, `t*` its slip time; solid ball):
/// along the throw `∂x/∂v_x = t* + 5/7 (T' − t*)` (the switch moves, but
/// the motion is C¹ there) and `∂x/∂ω_y = 2r/7 (T' − t*)`; across it the
/// path turns, `∂y/∂v_y = 6/7 t* + 5/7 (T' − t*)`,
/// `∂y/∂ω_x = −r (t*/7 + 2/7 (T' − t*))`. With no spin at the start these
/// are `t* + 5/7 (T − t*)` and `6/7 t* + 5/7 (T − t*)`.
#[test]
fn the_tangent_of_the_final_position_matches_its_closed_form() {
    let big_t = 1.0;
    let mut scene = ball(Vec3::new(2.0, 0.0, 0.0), Vec3::zeros(), 0.02, big_t);
    scene.bodies[0].free = vec![Block::Velocity];
    let tr = run(&scene, true);
    let (t0, ts) = slide_and_switch(&tr);
    let s0 = tr.state(0, t0, Side::Post);
    let j0 = tr
        .jacobian(0, t0, Side::Post)
        .expect("jacobian at the landing");
    let a = MU * G;
    let slip = s0.v.x - R * s0.w.y;
    let t_star = slip / (3.5 * a);
    assert!((ts - t0 - t_star).abs() < 1e-9, "{} vs {t_star}", ts - t0);
    let rest = big_t - t0 - t_star;
    let along = t_star + 5.0 / 7.0 * rest;
    let across = 6.0 / 7.0 * t_star + 5.0 / 7.0 * rest;
    let j = tr.jacobian(0, big_t, Side::Post).expect("jacobian");
    for c in 0..3 {
        let x = j0[(0, c)] + along * j0[(6, c)] + 2.0 * R / 7.0 * rest * j0[(10, c)];
        let y =
            j0[(1, c)] + across * j0[(7, c)] - R * (t_star / 7.0 + 2.0 / 7.0 * rest) * j0[(9, c)];
        eprintln!(
            "∂(x, y)/∂v0[{c}]: {:.12} {:.12}, closed form {x:.12} {y:.12}",
            j[(0, c)],
            j[(1, c)]
        );
        assert!((j[(0, c)] - x).abs() < 1e-9 && (j[(1, c)] - y).abs() < 1e-9);
    }
    // Rolling: v = 5/7 of the start's slip-free part, ω = n × v / r.
    for c in 0..3 {
        let dv = 5.0 / 7.0 * j0[(6, c)] + 2.0 * R / 7.0 * j0[(10, c)];
        assert!((j[(6, c)] - dv).abs() < 1e-9);
        assert!((j[(10, c)] - dv / R).abs() < 1e-8);
    }
}

/// A ball dropped with side spin (its axis of rotation turns while it
/// slips: the orientation is integrated) lands, slips and rolls; every
/// column whose perturbation keeps the events (state and mass) matches
/// central differences, at times in both phases and at both events.
#[test]
fn the_jacobian_through_slipping_and_rolling_matches_central_differences() {
    let mut scene = ball(
        Vec3::new(3.0, 0.5, 0.0),
        Vec3::new(4.0, -6.0, 9.0),
        0.02,
        1.0,
    );
    scene.accuracy.root_tol = 1e-14;
    testkit::free_state(&mut scene);
    // The mass moves the spin-up `b = r μ m g_n / I` (the inertia held).
    scene.bodies[0].free.push(Block::Mass);
    let controls = Controls::new(&scene);
    let tr = simulate(&scene, &controls, &SimOptions::default()).expect("simulates");
    let (t0, ts) = slide_and_switch(&tr);
    assert!(tr.tangent_error.is_none(), "{:?}", tr.tangent_error);
    // Both phases, both events and their dt/du, to 1e-6.
    let (worst, comparable) =
        testkit::check_against_central(&scene, &[0.5 * (t0 + ts), 0.5 * (ts + 1.0), 1.0], 1e-6);
    assert!(
        comparable.iter().filter(|c| **c).count() >= 10,
        "{comparable:?}"
    );
    eprintln!(
        "switch at {ts:.6} s; worst relative error {worst:.2e}; comparable {:?}; mass column at the end {:.6}",
        comparable,
        tr.jacobian(0, 1.0, Side::Post)
            .expect("jacobian")
            .column(12)
    );
    assert_energy_never_rises(&tr);
}

/// A ball that lands rolling (its contact point at rest) rolls on from the
/// landing: no switch, no friction work, its speed kept.
#[test]
fn a_ball_landing_while_rolling_rolls_on_unchanged() {
    let v = Vec3::new(2.0, 0.0, 0.0);
    let scene = ball(v, Vec3::z().cross(&v) / R, 0.02, 1.0);
    let tr = run(&scene, true);
    let kinds = tr.signature();
    assert_eq!(kinds.len(), 1, "{kinds:?}");
    assert!(kinds[0].ends_with("|slide"), "{kinds:?}");
    let end = tr.state(0, 1.0, Side::Post);
    assert!((end.v - v).norm() < 1e-9 && (end.w - Vec3::z().cross(&v) / R).norm() < 1e-9);
    assert!(tr.jacobian(0, 1.0, Side::Post).is_ok());
    assert_energy_never_rises(&tr);
}
