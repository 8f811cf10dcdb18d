//! Bodies resting on bodies: stacks that settle, stand and fall when
//! struck; the island statics against closed forms; balls in a box that
//! settle without a sustained-contact error (docs/design.md §4).

use nudge::controls::Controls;
use nudge::geometry::Geometry;
use nudge::math::Vec3;
use nudge::scene::Scene;
use nudge::sim::island::{IslandBody, IslandContact, contact_forces};
use nudge::sim::{Side, SimOptions, Trajectory, simulate};
use nudge::testkit;

const G: f64 = 9.81;

/// A tower of `n` cubes (half side `h`) on the ground, each `gap` above the
/// one below, restitution `e`.
fn tower(n: usize, h: f64, gap: f64, e: f64, duration: f64) -> Scene {
    let mut s = testkit::scene(duration);
    s.obstacles.push(testkit::ground());
    let cube = Geometry::cuboid(Vec3::repeat(h)).unwrap();
    for k in 0..n {
        let z = h + 2.0 * h * k as f64 + gap * (k + 1) as f64;
        let mut b = testkit::body(&format!("box{k}"), cube.clone(), Vec3::new(0.0, 0.0, z));
        b.restitution = e;
        s.bodies.push(b);
    }
    s.pairs = (0..n)
        .flat_map(|i| (i + 1..n).map(move |j| [i, j]))
        .collect();
    s
}

fn run(s: &Scene) -> Trajectory {
    simulate(s, &Controls::new(s), &SimOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// When body `i`'s last segment started, if it rests.
fn rests_from(tr: &Trajectory, i: usize) -> Option<f64> {
    let seg = tr.tracks[i].segments.last()?;
    seg.rest.then_some(seg.t0)
}

#[test]
fn a_box_on_a_box_rests_for_ten_seconds_without_drift_or_events() {
    let s = tower(2, 0.1, 1e-3, 0.5, 10.0);
    let tr = run(&s);
    let settled = (0..2)
        .map(|i| rests_from(&tr, i).unwrap_or_else(|| panic!("box{i} does not rest")))
        .fold(0.0, f64::max);
    assert!(settled < 1.0, "settled at {settled} s");
    let after = tr.events.iter().filter(|e| e.t > settled).count();
    assert_eq!(after, 0, "events after rest");
    for i in 0..2 {
        let a = tr.state(i, settled, Side::Post);
        let b = tr.state(i, 10.0, Side::Post);
        let drift = (a.x - b.x).norm();
        let turn = a.q.angle_to(&b.q);
        assert!(
            drift <= 1e-9 && turn <= 1e-9,
            "box{i}: {drift} m, {turn} rad"
        );
        let z = 0.1 + 0.2 * i as f64;
        assert!((b.x.z - z).abs() < 1e-3, "box{i} at z = {}", b.x.z);
    }
    assert!(tr.counters.islands.get() > 0);
}

#[test]
fn a_tower_of_five_settles_and_stands() {
    let s = tower(5, 0.1, 2e-3, 0.3, 3.0);
    let tr = run(&s);
    for i in 0..5 {
        let t = rests_from(&tr, i).unwrap_or_else(|| panic!("box{i} does not rest"));
        assert!(t < 2.0, "box{i} rests at {t} s");
        let x = tr.state(i, 3.0, Side::Post).x;
        let z = 0.1 + 0.2 * i as f64;
        assert!(
            x.xy().norm() < 1e-6 && (x.z - z).abs() < 1e-3,
            "box{i} at {x:?}"
        );
    }
    let last = tr.events.last().map_or(0.0, |e| e.t);
    assert!(last < 2.0, "last event at {last} s");
}

/// The tower of five struck at box `level` by a ball.
fn struck_tower(level: usize) -> Scene {
    let mut s = tower(5, 0.1, 2e-3, 0.3, 3.0);
    // A ball (a quarter of a box's mass, restitution 1) thrown at the top
    // box, level with its centre when it arrives
    // at t = 0.5 s (the tower rests from t ≈ 0.05 s).
    let (r, speed, t_hit) = (0.08, 4.0, 0.5);
    let z4 = 0.1 + 0.2 * level as f64;
    let mut ball = testkit::body(
        "ball",
        Geometry::sphere(r).unwrap(),
        Vec3::new(-0.1 - r - speed * t_hit, 0.0, z4),
    );
    ball.velocity = Vec3::new(speed, 0.0, 0.5 * G * t_hit);
    s.bodies[level].restitution = 0.8;
    s.bodies.push(ball);
    s.pairs = (0..6)
        .flat_map(|i| (i + 1..6).map(move |j| [i, j]))
        .collect();
    s
}

#[test]
fn a_tower_struck_by_a_sphere_falls() {
    let s = struck_tower(4);
    let tr = run(&s);
    let hit = tr
        .events
        .iter()
        .find(|e| e.a == 4 && e.b == nudge::sim::Party::Body(5))
        .unwrap_or_else(|| panic!("the ball misses"));
    assert!((hit.t - 0.5).abs() < 0.01, "hit at {}", hit.t);
    // Settled before the hit; the top box flies off, the boxes at the
    // bottom stand where they were.
    for i in 0..5 {
        assert!(
            tr.resting(i, hit.t, Side::Pre),
            "box{i} not resting at the hit"
        );
    }
    let moved =
        |i: usize| (tr.state(i, 3.0, Side::Post).x - tr.state(i, hit.t, Side::Pre).x).norm();
    assert!(moved(4) > 0.5, "the top box moved {} m", moved(4));
    assert!(tr.state(4, 3.0, Side::Post).x.z < 0.5, "the top box fell");
    for i in 0..3 {
        assert!(moved(i) < 1e-3, "box{i} moved {} m", moved(i));
    }
}

/// A sphere in the hollow between two spheres, all of radius `r` and mass
/// `m`, the lower centres `2d` apart at height `r`: the contact bodies and
/// contacts (the upper sphere is body 0).
fn hollow(r: f64, d: f64, lower_free: bool, mu: f64) -> (Vec<IslandBody>, Vec<IslandContact>) {
    let h = (4.0 * r * r - d * d).sqrt();
    let top = Vec3::new(0.0, 0.0, r + h);
    let mut bodies = vec![IslandBody {
        com: top,
        mass: 1.0,
    }];
    let mut contacts = Vec::new();
    for side in [-1.0, 1.0] {
        let c = Vec3::new(side * d, 0.0, r);
        let n = (top - c).normalize();
        let b = if lower_free {
            bodies.push(IslandBody { com: c, mass: 1.0 });
            let k = bodies.len() - 1;
            contacts.push(IslandContact {
                a: k,
                b: None,
                point: Vec3::new(side * d, 0.0, 0.0),
                normal: Vec3::z(),
                friction: mu,
            });
            Some(k)
        } else {
            None
        };
        contacts.push(IslandContact {
            a: 0,
            b,
            point: c + n * r,
            normal: n,
            friction: mu,
        });
    }
    (bodies, contacts)
}

#[test]
fn a_sphere_between_two_fixed_spheres_is_held_by_the_closed_form_forces() {
    // Frictionless: each contact pushes along its normal with
    // N = m g / (2 cos θ), θ the normal's angle from the vertical.
    let (r, d) = (0.05, 0.06);
    let (bodies, contacts) = hollow(r, d, false, 0.0);
    let f = contact_forces(&bodies, &contacts, &Vec3::new(0.0, 0.0, -G), r).unwrap();
    let cos = (4.0 * r * r - d * d).sqrt() / (2.0 * r);
    for (c, f) in contacts.iter().zip(&f) {
        let want = c.normal * (G / (2.0 * cos));
        assert!((f - want).norm() <= 1e-9 * G, "{f:?} vs {want:?}");
    }
}

#[test]
fn a_sphere_between_two_free_spheres_on_a_floor_is_held_by_the_closed_form_forces() {
    // With friction μ at every contact the forces are determinate: on the
    // upper sphere each lower one pushes N = m g / 2 along the normal and
    // T = (m g / 2) tan(θ/2) across it (the lower spheres' torque balance:
    // T equals the floor's friction; their horizontal balance:
    // N sin θ = T (1 + cos θ)); the floor carries N₀ = 3 m g / 2 and a
    // friction T inwards under each.
    let (r, d) = (0.05, 0.06);
    let (bodies, contacts) = hollow(r, d, true, 1.0);
    let f = contact_forces(&bodies, &contacts, &Vec3::new(0.0, 0.0, -G), r).unwrap();
    let sin = d / (2.0 * r);
    let cos = (1.0 - sin * sin).sqrt();
    let tan_half = sin / (1.0 + cos);
    let w = G;
    for (c, f) in contacts.iter().zip(&f) {
        let want = if c.b.is_none() {
            // Friction points inwards (towards x = 0).
            Vec3::new(-c.point.x.signum() * 0.5 * w * tan_half, 0.0, 1.5 * w)
        } else {
            // Tangent in the plane, upwards-inwards on the upper sphere.
            let n = c.normal;
            let t = Vec3::new(n.z * -n.x.signum(), 0.0, n.x.abs());
            n * (0.5 * w) + t * (0.5 * w * tan_half)
        };
        assert!((f - want).norm() <= 1e-9 * w, "{f:?} vs {want:?}");
    }
    // Without friction the lower spheres roll apart: not held.
    let (bodies, contacts) = hollow(r, d, true, 0.0);
    assert!(contact_forces(&bodies, &contacts, &Vec3::new(0.0, 0.0, -G), r).is_none());
}

/// Total mechanical energy of the scene's bodies at `t`.
fn energy(s: &Scene, tr: &Trajectory, t: f64) -> f64 {
    s.bodies
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let st = tr.state(i, t, Side::Post);
            let wb = st.q.inverse() * st.w;
            0.5 * b.mass * st.v.norm_squared()
                + 0.5 * wb.component_mul(&b.inertia).dot(&wb)
                + b.mass * G * st.x.z
        })
        .sum()
}

/// N = 1 to 256 balls in a box at restitution 0.5 and 0.8 run to the end. The energy
/// bound tested: the total mechanical energy at every event and every
/// 10 ms never exceeds its start by more than `½ m v_r²` per
/// micro-collision so far (the floor a micro-collision adds at most;
/// `v_r = max(rest_speed, √(2 g · 3e-5 · r))`), plus 1e-9 of the start.
/// Every impact between two moving bodies conserves momentum to 1e-9.
/// Long enough for the bounces to die out (the balls start up to 1 m
/// high, thrown up at up to 2 m/s); on the frictionless floor the balls
/// then slide on between the walls, as the physics says.
const HORIZON: f64 = 6.0;

#[test]
fn balls_in_a_box_settle_without_error_and_within_the_energy_budget() {
    let r = testkit::BALL_RADIUS;
    for e in [0.5, 0.8] {
        for n in [1, 4, 16, 64, 256] {
            let s = testkit::balls_in_box(n, HORIZON, 0, 0x5ca1_ab1e, e).unwrap();
            let tr = simulate(&s, &Controls::new(&s), &SimOptions::without_tangents())
                .unwrap_or_else(|err| panic!("N = {n}, e = {e}: {err}"));
            let m = s.bodies[0].mass;
            let v_r = s.rest_speed.max((2.0 * G * 3e-5 * r).sqrt());
            let e0 = energy(&s, &tr, 0.0);
            // Just after every event (energy changes only at impulses) and
            // every 10 ms; the micro-collisions so far, counted as we go.
            let mut times: Vec<(f64, usize)> = tr
                .events
                .iter()
                .enumerate()
                .map(|(k, ev)| (ev.t, k + 1))
                .collect();
            times.extend((0..=(100.0 * HORIZON) as usize).map(|k| (k as f64 * 0.01, 0)));
            times.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            let mut worst: f64 = f64::NEG_INFINITY;
            let (mut seen, mut micro) = (0, 0);
            for (t, _) in times {
                while seen < tr.events.len() && tr.events[seen].t <= t {
                    micro += usize::from(tr.events[seen].micro);
                    seen += 1;
                }
                let allowance = micro as f64 * 0.5 * m * v_r * v_r + 1e-9 * e0.abs();
                let excess = energy(&s, &tr, t) - e0 - allowance;
                worst = worst.max(excess);
                assert!(
                    excess <= 0.0,
                    "N = {n}, e = {e}: energy up by {excess} J past the allowance at t = {t}"
                );
            }
            for ev in &tr.events {
                let nudge::sim::Party::Body(j) = ev.b else {
                    continue;
                };
                let moving =
                    |i: usize| !tr.resting(i, ev.t, Side::Pre) && !tr.resting(i, ev.t, Side::Post);
                if moving(ev.a) && moving(j) {
                    let p = |k: usize| ev.pre[k].v + ev.pre[1 - k].v;
                    let q = |k: usize| ev.post[k].v + ev.post[1 - k].v;
                    assert!(
                        (p(0) - q(0)).norm() <= 1e-9 * (1.0 + p(0).norm()),
                        "N = {n}, e = {e}: momentum at event {}",
                        ev.index
                    );
                }
            }
            let resting = (0..n)
                .filter(|&i| tr.resting(i, HORIZON, Side::Post))
                .count();
            eprintln!(
                "N = {n}, e = {e}: {} events ({} micro), {} islands, {resting} resting at the end, worst excess {worst:.2e} J",
                tr.events.len(),
                tr.events.iter().filter(|ev| ev.micro).count(),
                tr.counters.islands.get()
            );
        }
    }
}

/// Eight balls dropped in two layers into a box that fits two by two: the
/// upper ones land on the lower ones (balls on balls, frictionless, held
/// by the walls). At e = 0.5 all eight rest within 4 s; at e = 0.8 some
/// upper balls still hop in their hollows (micro-collisions off frozen
/// balls, frictionless), within the energy allowance and without error.
#[test]
fn balls_dropped_in_a_narrow_box_pile_up_and_rest() {
    let r = testkit::BALL_RADIUS;
    let half = 2.0 * r + 0.01;
    for e in [0.5, 0.8] {
        let mut s = testkit::scene(4.0);
        s.obstacles.push(testkit::ground());
        for (name, normal) in [
            ("wall+x", -Vec3::x()),
            ("wall-x", Vec3::x()),
            ("wall+y", -Vec3::y()),
            ("wall-y", Vec3::y()),
        ] {
            let g = Geometry::half_space(normal).unwrap();
            s.obstacles.push(testkit::obstacle(name, g, -normal * half));
        }
        let sphere = Geometry::sphere(r).unwrap();
        let mut rng = nudge::math::Rng(7);
        for k in 0..8 {
            let (sx, sy) = (
                if k % 2 == 0 { -1.0 } else { 1.0 },
                if (k / 2) % 2 == 0 { -1.0 } else { 1.0 },
            );
            let layer = (k / 4) as f64;
            let p = Vec3::new(
                sx * (r + 0.004) + rng.range(-0.002, 0.002),
                sy * (r + 0.004) + rng.range(-0.002, 0.002),
                r + 0.02 + layer * 0.15,
            );
            let mut b = testkit::body(&format!("ball{k}"), sphere.clone(), p);
            b.restitution = e;
            s.bodies.push(b);
        }
        s.pairs = (0..8)
            .flat_map(|i| (i + 1..8).map(move |j| [i, j]))
            .collect();
        let tr = simulate(&s, &Controls::new(&s), &SimOptions::without_tangents())
            .unwrap_or_else(|err| panic!("e = {e}: {err}"));
        let m = s.bodies[0].mass;
        let v_r = s.rest_speed.max((2.0 * G * 3e-5 * r).sqrt());
        let e0 = energy(&s, &tr, 0.0);
        for ev in &tr.events {
            let micro = tr.events.iter().filter(|x| x.t <= ev.t && x.micro).count();
            let allowance = micro as f64 * 0.5 * m * v_r * v_r + 1e-9 * e0.abs();
            let excess = energy(&s, &tr, ev.t) - e0 - allowance;
            assert!(
                excess <= 0.0,
                "e = {e}: energy up by {excess} J at t = {}",
                ev.t
            );
        }
        let resting = (0..8).filter(|&i| tr.resting(i, 4.0, Side::Post)).count();
        let top = (0..8)
            .map(|i| tr.state(i, 4.0, Side::Post).x.z)
            .fold(0.0, f64::max);
        assert!(top < 0.2, "e = {e}: a ball at z = {top}");
        if e == 0.5 {
            assert_eq!(resting, 8, "e = {e}");
            assert!(tr.counters.islands.get() > 0);
        }
        eprintln!(
            "narrow box e = {e}: {} events ({} micro), {} islands, {resting} resting, top at {top}",
            tr.events.len(),
            tr.events.iter().filter(|x| x.micro).count(),
            tr.counters.islands.get()
        );
    }
}

/// What micro-collisions may add: after each event (in time order), the
/// allowance so far, `½ m v_r²` for each micro-collision, `m` the heavier
/// party and `v_r` the larger rest speed of the two
/// (`v_r = max(rest_speed, √(2 g · 3e-5 · reach))`).
fn micro_allowances(s: &Scene, tr: &Trajectory) -> Vec<(f64, f64)> {
    let v_r = |i: usize| {
        s.rest_speed
            .max((2.0 * G * 3e-5 * s.bodies[i].geometry.reach()).sqrt())
    };
    let mut sum = 0.0;
    tr.events
        .iter()
        .map(|ev| {
            if ev.micro {
                let (m, v) = match ev.b {
                    nudge::sim::Party::Body(j) => (
                        s.bodies[ev.a].mass.max(s.bodies[j].mass),
                        v_r(ev.a).max(v_r(j)),
                    ),
                    nudge::sim::Party::Obstacle(_) => (s.bodies[ev.a].mass, v_r(ev.a)),
                };
                sum += 0.5 * m * v * v;
            }
            (ev.t, sum)
        })
        .collect()
}

/// Two moving bodies in sustained contact (run/sustained.rs): the run
/// ends, the energy never rises past the micro-collision allowance (at
/// every event and every 10 ms), the `still` bodies are still at the end,
/// and no two bodies overlap by more than the event skin (1e-9 m here).
fn check_settles(s: &Scene, still: std::ops::Range<usize>, what: &str) -> Trajectory {
    let tr = simulate(s, &Controls::new(s), &SimOptions::without_tangents())
        .unwrap_or_else(|err| panic!("{what}: {err}"));
    let end = s.duration;
    let e0 = energy(s, &tr, 0.0);
    let allowances = micro_allowances(s, &tr);
    let mut times: Vec<f64> = tr.events.iter().map(|ev| ev.t).collect();
    times.extend((0..=(100.0 * end) as usize).map(|k| k as f64 * 0.01));
    for t in times {
        let k = allowances.partition_point(|(te, _)| *te <= t);
        let allowance = if k == 0 { 0.0 } else { allowances[k - 1].1 };
        let excess = energy(s, &tr, t) - e0 - allowance - 1e-9 * e0.abs();
        assert!(excess <= 0.0, "{what}: energy up by {excess} J at t = {t}");
    }
    let n = s.bodies.len();
    for i in still {
        let st = tr.state(i, end, Side::Post);
        assert!(
            st.v.norm() < 1e-9 && st.w.norm() < 1e-9,
            "{what}: {} still moves at {} m/s, {} rad/s",
            s.bodies[i].name,
            st.v.norm(),
            st.w.norm()
        );
    }
    let skin = (10.0 * s.accuracy.root_tol).max(1e-9);
    for i in 0..n {
        for j in i + 1..n {
            let (a, b) = (tr.state(i, end, Side::Post), tr.state(j, end, Side::Post));
            let (ga, gb) = (&s.bodies[i].geometry, &s.bodies[j].geometry);
            if let Some(c) = nudge::geometry::contact(ga, &a.pose(), gb, &b.pose(), 0.0) {
                assert!(
                    c.distance >= -skin * (1.0 + 1e-6),
                    "{what}: {} and {} overlap by {} m",
                    s.bodies[i].name,
                    s.bodies[j].name,
                    -c.distance
                );
            }
        }
    }
    eprintln!(
        "{what}: {} events ({} micro), last at {:.3} s, {} islands",
        tr.events.len(),
        tr.events.iter().filter(|ev| ev.micro).count(),
        tr.events.last().map_or(0.0, |ev| ev.t),
        tr.counters.islands.get()
    );
    tr
}

/// Struck below its top box, the boxes above the hit are knocked off
/// together, one riding another: the search stalled between them
/// (`EventSearchStalled`: box3–box4 at t = 0.50 s struck at box2, at
/// 0.63 s struck at box3). Frictionless they topple and slide on; with
/// friction and a ball twice a box's mass (struck at box1 it stalled
/// between box0 and box1) every box comes to rest by 6 s (the ball rolls
/// on: a rolling ball's friction is not modelled). Struck at box1, box0
/// settling flat on the floor under box3 pushed its top 6.6 µm into it
/// until settling checked the bodies it collides with.
#[test]
fn a_tower_struck_below_its_top_topples_and_comes_to_rest() {
    let toppled = |s: &Scene, tr: &Trajectory, level: usize| {
        for i in level + 1..5 {
            let moved = (tr.state(i, s.duration, Side::Post).x - s.bodies[i].position).norm();
            assert!(moved > 0.1, "level {level}: box{i} moved {moved} m");
        }
    };
    for level in [2, 3] {
        let s = struck_tower(level);
        let tr = check_settles(&s, 0..0, &format!("frictionless, struck at box{level}"));
        toppled(&s, &tr, level);
    }
    for level in [1, 2] {
        let mut s = struck_tower(level);
        s.duration = 6.0;
        s.effects.friction = true;
        let ball = s.bodies.len() - 1;
        s.bodies[ball].mass *= 8.0;
        s.bodies[ball].inertia *= 8.0;
        let tr = check_settles(&s, 0..5, &format!("struck at box{level}"));
        toppled(&s, &tr, level);
    }
}

/// A box lying on another, both thrown sideways together: falling side by
/// side they neither close nor clear (the search stalled at t = 0); they
/// land, the upper one slides on the lower, and both rest.
#[test]
fn two_stacked_boxes_thrown_together_land_and_come_to_rest() {
    let mut s = tower(2, 0.1, 0.0, 0.3, 3.0);
    s.effects.friction = true;
    for b in &mut s.bodies {
        b.position.z += 0.5;
        b.velocity = Vec3::new(2.0, 0.0, 0.0);
    }
    let tr = check_settles(&s, 0..2, "thrown together");
    let between = tr.events.iter().filter(|ev| ev.a == 0).count();
    assert!(between > 0);
    let x = tr.state(1, 3.0, Side::Post).x;
    assert!(x.x > 0.3, "box1 at {x:?}");
}

/// The effect is gated: without collisions no island is ever built.
#[test]
fn without_collisions_no_island_is_built() {
    let mut s = tower(2, 0.1, 1e-3, 0.5, 1.0);
    s.effects.collisions = false;
    let tr = run(&s);
    assert!(tr.events.is_empty());
    assert_eq!(tr.counters.islands.get(), 0);
    assert!(tr.state(1, 1.0, Side::Post).x.z < 0.0, "falls through");
}
