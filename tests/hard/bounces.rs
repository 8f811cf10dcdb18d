//! Bounce series, flat landings, the cradle, thin walls.

use super::*;

/// A ball dropped with restitution 0.5 and 0.9 bounces finitely many times,
/// then rests; it never goes below the floor; every bounce is on the
/// geometric series and the rest time is the series' limit
/// `t₀ (1 + e)/(1 − e)` to 1e-6 s.
#[test]
fn zeno_bouncing_ends_at_rest_at_the_series_limit() {
    for e in [0.5, 0.9] {
        let mut s = load("zeno.toml");
        s.bodies[0].restitution = e;
        let tr = run_ok(&s);
        let (g, h) = (9.81f64, 1.0f64);
        let t0 = (2.0 * h / g).sqrt();
        let limit = t0 * (1.0 + e) / (1.0 - e);
        let rest = tr
            .events
            .iter()
            .position(|ev| ev.rest)
            .expect("comes to rest");
        assert_eq!(rest + 1, tr.events.len(), "nothing after rest");
        // Bounce k at t₀ + 2 t₀ Σ_{i=1..k} eⁱ.
        let mut expected = t0;
        for (k, ev) in tr.events.iter().enumerate() {
            assert!(
                (ev.t - expected).abs() < 1e-9,
                "e={e} bounce {k}: {} vs {expected}",
                ev.t
            );
            expected += 2.0 * t0 * e.powi(k as i32 + 1);
        }
        let rest_time = tr.events[rest].rest_time.expect("a rest time");
        assert!(
            (rest_time - limit).abs() < 1e-6,
            "e={e}: rest at {rest_time}, limit {limit}"
        );
        assert!(tr.events[rest].t <= limit);
        let low = nudge::testkit::lowest_gap(&s, &tr, 20_000);
        assert!(low >= -1e-9, "e={e}: height {low:.3e}");
        let end = tr.state(0, s.duration, Side::Post);
        assert!(end.v == Vec3::zeros() && (end.x.z - 0.1).abs() < 1e-9);
        eprintln!(
            "zeno e={e}: {} bounces, rest at {:.9} s, series limit {limit:.9} s (rest-time error {:.1e}), lowest {low:.1e} m",
            tr.events.len(),
            tr.events[rest].t,
            (rest_time - limit).abs()
        );
    }
}

// ---------------------------------------------------------------------------
// Simultaneous contacts.
// ---------------------------------------------------------------------------

/// A box landing flat touches with four vertices at once: one impulse at
/// their centroid, the same whatever order the hull lists its vertices in;
/// no spin is created, horizontal momentum and the vertical spin are kept,
/// the vertical speed is reversed times e, and energy does not increase.
#[test]
fn a_box_landing_flat_is_one_impulse_whatever_the_vertex_order() {
    let base = load("box-flat.toml");
    let corners: Vec<[f64; 3]> = (0..8)
        .map(|i| {
            [
                if i & 1 == 0 { -0.2 } else { 0.2 },
                if i & 2 == 0 { -0.1 } else { 0.1 },
                if i & 4 == 0 { -0.05 } else { 0.05 },
            ]
        })
        .collect();
    let mut results = Vec::new();
    for order in [
        vec![0, 1, 2, 3, 4, 5, 6, 7],
        vec![7, 6, 5, 4, 3, 2, 1, 0],
        vec![3, 6, 0, 5, 2, 7, 4, 1],
    ] {
        let pts: Vec<String> = order
            .iter()
            .map(|&i| format!("[{}, {}, {}]", corners[i][0], corners[i][1], corners[i][2]))
            .collect();
        let text = std::fs::read_to_string(
            Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/hard/box-flat.toml"),
        )
        .unwrap()
        .replace(
            "shape = { type = \"box\", half_extents = [0.2, 0.1, 0.05] }",
            &format!(
                "shape = {{ type = \"hull\", points = [{}] }}",
                pts.join(", ")
            ),
        );
        let s = nudge::scene::load_str(&text, "box-flat-hull.toml").unwrap();
        results.push(run_ok(&s));
    }
    let tr0 = run_ok(&base);
    let e0 = &tr0.events[0];
    assert_eq!(e0.simultaneous, 4, "{}", e0.key);
    let (pre, post) = (e0.pre[0], e0.post[0]);
    assert!(
        (post.v.z + 0.7 * pre.v.z).abs() < 1e-12,
        "{} vs {}",
        post.v.z,
        pre.v.z
    );
    assert!((post.v.x - pre.v.x).abs() < 1e-12 && post.v.y.abs() < 1e-12);
    assert!(
        (post.w - pre.w).norm() < 1e-12,
        "no spin created, vertical spin kept: {:?}",
        post.w
    );
    assert!(kinetic(&tr0, 0, &post) <= kinetic(&tr0, 0, &pre));
    for tr in &results {
        let e = &tr.events[0];
        assert_eq!(e.simultaneous, 4);
        assert!((e.t - e0.t).abs() < 1e-12);
        assert!(
            (e.post[0].v - post.v).norm() < 1e-12 && (e.post[0].w - post.w).norm() < 1e-12,
            "{:?} {:?}",
            e.post[0].v,
            e.post[0].w
        );
    }
    eprintln!(
        "box flat: {} vertices at t = {:.9} s, spin after {:.1e}, order spread {:.1e}",
        e0.simultaneous,
        e0.t,
        (post.w - pre.w).norm(),
        results
            .iter()
            .map(|t| (t.events[0].post[0].v - post.v).norm())
            .fold(0.0, f64::max)
    );
}

/// A three-ball cradle: the chain of two-body impulses conserves momentum,
/// never adds energy, and gives Newton's cradle (a and b stop, c leaves);
/// mirroring the scene mirrors the result.
#[test]
fn a_three_ball_cradle_conserves_momentum_and_does_not_gain_energy() {
    for e in [1.0, 0.8] {
        for mirror in [false, true] {
            let mut s = load("cradle.toml");
            for b in &mut s.bodies {
                b.restitution = e;
                if mirror {
                    b.position.x = 0.2 - b.position.x;
                    b.velocity.x = -b.velocity.x;
                }
            }
            let tr = run_ok(&s);
            let m: Vec<f64> = tr.dynamics.iter().map(|d| d.mass).collect();
            let at = |t: f64| -> (f64, f64) {
                let st: Vec<_> = (0..3).map(|b| tr.state(b, t, Side::Post)).collect();
                (
                    (0..3).map(|b| m[b] * st[b].v.x).sum(),
                    (0..3).map(|b| kinetic(&tr, b, &st[b])).sum(),
                )
            };
            let (p0, k0) = at(0.0);
            let (p1, k1) = at(s.duration);
            assert!(
                (p1 - p0).abs() < 1e-12 * m[0],
                "e={e}: momentum {p0} → {p1}"
            );
            assert!(k1 <= k0 * (1.0 + 1e-12), "e={e}: energy {k0} → {k1}");
            for ev in &tr.events {
                let (kp, ka) = (
                    kinetic(&tr, ev.a, &ev.pre[0]),
                    kinetic(&tr, ev.a, &ev.post[0]),
                );
                let nudge::sim::Party::Body(j) = ev.b else {
                    panic!("only body pairs")
                };
                let (kpb, kab) = (kinetic(&tr, j, &ev.pre[1]), kinetic(&tr, j, &ev.post[1]));
                assert!(
                    ka + kab <= (kp + kpb) * (1.0 + 1e-12),
                    "e={e}: an impulse added energy"
                );
            }
            let v: Vec<f64> = (0..3)
                .map(|b| tr.state(b, s.duration, Side::Post).v.x * if mirror { -1.0 } else { 1.0 })
                .collect();
            if e == 1.0 {
                // Newton's cradle: one ball leaves with all the momentum.
                let moving: Vec<usize> = (0..3).filter(|&b| v[b].abs() > 1e-9).collect();
                assert_eq!(moving.len(), 1, "e=1 mirror={mirror}: {v:?}");
                assert!((v[moving[0]] - 1.0).abs() < 1e-12, "{v:?}");
            }
            assert!(
                tr.events.len() >= 2 && (tr.events[1].t - tr.events[0].t).abs() < 1e-9,
                "the second impact is simultaneous"
            );
            eprintln!(
                "cradle e={e} mirror={mirror}: {} events, momentum error {:.1e}, energy ratio {:.6}, final v {v:?}",
                tr.events.len(),
                (p1 - p0).abs(),
                k1 / k0
            );
        }
    }
}

// ---------------------------------------------------------------------------
// Tunnelling.
// ---------------------------------------------------------------------------

/// A 1 km/s ball, a fast spinning rod and two balls meeting head-on at
/// 1 km/s closing speed hit at the same times whatever the step (dt, 10 dt,
/// 100 dt) or integrator; the balls' contact times are the closed forms.
#[test]
fn fast_bodies_do_not_tunnel_through_a_thin_wall_or_each_other_at_any_step() {
    use nudge::scene::Method;
    let first = |tr: &Trajectory, b: usize| {
        tr.body_events(b)
            .first()
            .map(|e| e.t)
            .unwrap_or_else(|| panic!("body {b} passed through"))
    };
    let mut times: Vec<[f64; 3]> = Vec::new();
    for method in [
        Method::Rk4 { step: 1e-3 },
        Method::Rk4 { step: 1e-2 },
        Method::Rk4 { step: 1e-1 },
        Method::Adaptive {
            tol: 1e-9,
            max_step: 0.1,
        },
    ] {
        let mut s = load("tunnel.toml");
        s.accuracy.method = method;
        let tr = run_ok(&s);
        times.push([first(&tr, 0), first(&tr, 1), first(&tr, 2)]);
        // Nobody ends past the wall or the other ball.
        assert!(tr.state(0, s.duration, Side::Post).x.x < 0.0);
        assert!(tr.state(1, s.duration, Side::Post).x.x < 0.0);
        assert!(tr.state(2, s.duration, Side::Post).x.x < tr.state(3, s.duration, Side::Post).x.x);
    }
    // The three RK4 steps agree to round-off; the adaptive run's rotation
    // differs at its own tolerance.
    for (i, t) in times.iter().enumerate().skip(1) {
        let tol = if i < 3 { 1e-12 } else { 1e-9 };
        for k in 0..3 {
            assert!((t[k] - times[0][k]).abs() < tol, "body {k}: {times:?}");
        }
    }
    let ball = (1.0 - 0.01 - 0.0005) / 1000.0;
    let pair = (2.0 - 0.01) / 1000.0;
    assert!(
        (times[0][0] - ball).abs() < 1e-12,
        "{} vs {ball}",
        times[0][0]
    );
    assert!(
        (times[0][2] - pair).abs() < 1e-12,
        "{} vs {pair}",
        times[0][2]
    );
    eprintln!(
        "tunnel: first contacts {:?} for dt, 10 dt, 100 dt, adaptive",
        times
    );
}

// ---------------------------------------------------------------------------
// Exponential map, quaternion drift, gyroscopic stiffness.
// ---------------------------------------------------------------------------
