//! Grazing contacts: flagged before the event-time derivative blows up.

use super::*;

/// Every number a trajectory exposes is finite: states everywhere, and the
/// Jacobian and event derivatives wherever they are available (else a typed
/// error).
fn assert_finite(tr: &Trajectory, what: &str) {
    for b in 0..tr.tracks.len() {
        for k in 0..=50 {
            let t = tr.duration * k as f64 / 50.0;
            assert!(
                tr.state(b, t, Side::Post).is_finite(),
                "{what}: state at {t}"
            );
            match tr.jacobian(b, t, Side::Post) {
                Ok(j) => assert!(j.iter().all(|v| v.is_finite()), "{what}: J at {t}"),
                Err(nudge::sim::TangentError::Grazing { .. }) => {}
                Err(e) => panic!("{what}: {e}"),
            }
        }
    }
    for e in &tr.events {
        assert!(
            e.graze_ratio.is_finite() || e.grazing,
            "{what}: graze ratio at {}",
            e.t
        );
        if let Some(d) = &e.dt_du {
            assert!(d.iter().all(|v| v.is_finite()), "{what}: dt/du");
        }
    }
}

/// Sweep a contact to tangency; returns `(graze ratio, grazing, max |dt_c/du|)`
/// of the first event for each sweep value.
fn graze_sweep(
    base: &Scene,
    values: &[f64],
    place: impl Fn(&mut Scene, f64),
) -> Vec<(f64, Option<(f64, bool, f64)>)> {
    values
        .iter()
        .map(|&x| {
            let mut s = base.clone();
            place(&mut s, x);
            let tr = simulate(&s, &Controls::new(&s), &SimOptions::default())
                .unwrap_or_else(|e| panic!("{x}: {e}"));
            assert_finite(&tr, &format!("{} at {x:e}", s.name));
            let first = tr.events.first().map(|e| {
                let dt = e.dt_du.as_ref().map_or(f64::NAN, |d| d.amax());
                if e.grazing {
                    assert!(e.dt_du.is_none(), "no dt/du at a grazing event");
                    assert!(matches!(
                        tr.tangent_error,
                        Some(nudge::sim::TangentError::Grazing { .. })
                    ));
                    assert!(
                        tr.jacobian(0, e.t, Side::Post).is_err()
                            && (e.t == 0.0 || tr.jacobian(0, 0.5 * e.t, Side::Post).is_ok()),
                        "{x:e}: {:?} {:?} {:?}",
                        tr.tangent_error,
                        tr.jacobian(0, e.t, Side::Post).err(),
                        tr.jacobian(0, 0.5 * e.t, Side::Post).err()
                    );
                }
                (e.graze_ratio, e.grazing, dt)
            });
            (x, first)
        })
        .collect()
}

#[test]
fn grazing_contact_is_flagged_before_the_contact_time_derivative_blows_up() {
    // Against a plane: launch angle θ; dt_c/dz₀ = 1/sin θ exactly.
    let angles = [0.3, 0.1, 1e-2, 2e-3, 1e-3, 1e-4, 1e-6, 1e-8, 1e-12, 0.0];
    let plane = graze_sweep(&load("graze-plane.toml"), &angles, |s, th: f64| {
        s.bodies[0].position = Vec3::new(0.0, 0.0, 0.1 + 0.5 * th.sin());
        s.bodies[0].velocity = Vec3::new(th.cos(), 0.0, -th.sin());
    });
    // Against a box edge: depth δ of the path into the edge.
    let depths = [0.5, 0.1, 1e-2, 1e-4, 1e-6, 1e-8, 1e-10, 1e-14, 0.0];
    let edge = graze_sweep(&load("graze-edge.toml"), &depths, |s, d: f64| {
        let h = 0.1 * (1.0 - d);
        s.bodies[0].position = Vec3::new(0.5 + (0.01 - h * h).max(0.0).sqrt() + 0.5, 0.0, 1.0 + h);
    });
    for (what, sweep) in [("plane", &plane), ("edge", &edge)] {
        let mut flagged = false;
        for (x, first) in sweep.iter() {
            let Some((ratio, grazing, dt)) = *first else {
                // Exact tangency: touching without approaching is no impact.
                assert_eq!(*x, 0.0, "{what} {x:e}: no contact");
                continue;
            };
            if grazing {
                flagged = true;
                assert!(ratio < 1e-3, "{what} {x:e}: flagged at ratio {ratio}");
            } else {
                assert!(
                    !flagged,
                    "{what}: once grazing, closer to tangency stays grazing"
                );
                assert!(
                    dt < 1e6,
                    "{what} {x:e}: |dt_c/du| = {dt:.3e} without a grazing flag"
                );
            }
        }
        assert!(flagged, "{what}: the sweep reaches grazing");
        let worst = sweep
            .iter()
            .filter_map(|(_, f)| f.filter(|f| !f.1).map(|f| f.2))
            .fold(0.0, f64::max);
        let first = sweep
            .iter()
            .find_map(|(x, f)| f.filter(|f| f.1).map(|f| (*x, f.0)));
        eprintln!(
            "grazing {what}: largest unflagged |dt_c/du| {worst:.3e}; first flagged at {first:?} (sweep value, ratio)"
        );
    }
    // Where not grazing, dt_c/dz₀ is the closed form 1/sin θ.
    for (th, first) in &plane {
        if let Some((_, false, _)) = first {
            let mut s = load("graze-plane.toml");
            s.bodies[0].position = Vec3::new(0.0, 0.0, 0.1 + 0.5 * th.sin());
            s.bodies[0].velocity = Vec3::new(th.cos(), 0.0, -th.sin());
            let tr = simulate(&s, &Controls::new(&s), &SimOptions::default()).unwrap();
            let dz = tr.events[0].dt_du.as_ref().unwrap()[2];
            assert!((dz * th.sin() - 1.0).abs() < 1e-6, "θ={th}: dt/dz = {dz}");
        }
    }
}

/// At a grazing contact the solver reports a typed condition and the
/// editor falls back to sampling instead of using the unbounded Jacobian.
/// A grazing contact used to take every body's Jacobians away from its
/// time on: a grazing egg rattling in one bucket blocked a nail on the other
/// egg, which never touched it. Now only the bodies that touch the grazing
/// contact, or later collide with one that did, lose them.
#[test]
fn regression_a_grazing_contact_blocked_the_jacobians_of_bodies_it_never_touched() {
    let mut scene = load("graze-two-balls.toml");
    let opts = SimOptions::default();
    let tr = simulate(&scene, &Controls::new(&scene), &opts).expect("simulates");
    let graze = tr.events.first().expect("the grazer touches the floor");
    assert!(
        graze.grazing,
        "the contact is grazing: ratio {}",
        graze.graze_ratio
    );
    assert!(tr.jacobian(0, 0.9, Side::Post).is_err());
    // The bystander's Jacobian after the graze: its own position and
    // velocity columns are exactly [I, tI; 0, I] (free flight), the
    // grazer's columns zero.
    let j = tr
        .jacobian(1, 0.9, Side::Post)
        .unwrap_or_else(|e| panic!("the bystander keeps its Jacobian: {e}"));
    let mut want = nalgebra::DMatrix::<f64>::zeros(12, 12);
    for k in 0..3 {
        want[(k, 6 + k)] = 1.0;
        want[(k, 9 + k)] = 0.9;
        want[(6 + k, 9 + k)] = 1.0;
    }
    let err = (&j - &want).amax();
    assert!(err < 1e-12, "bystander Jacobian off by {err:e}\n{j}");

    // Struck by the grazer after the graze, the bystander loses them from
    // that collision on, not before.
    scene.bodies[1].position = Vec3::new(0.8, 0.0, 0.15);
    scene.bodies[1].velocity = Vec3::zeros();
    scene.pairs.push([0, 1]);
    let tr = simulate(&scene, &Controls::new(&scene), &opts).expect("simulates");
    let hit = tr
        .events
        .iter()
        .find(|e| e.b == nudge::sim::Party::Body(1))
        .expect("the grazer strikes the bystander");
    assert!(hit.t > graze.t, "{} after {}", hit.t, graze.t);
    assert!(tr.jacobian(1, 0.5 * (graze.t + hit.t), Side::Post).is_ok());
    assert!(tr.jacobian(1, hit.t, Side::Post).is_err());
    assert!(tr.jacobian(1, 0.95, Side::Post).is_err());
}

#[test]
fn grazing_contact_makes_the_solver_and_editor_fall_back_to_sampling() {
    use nudge::edit::{Core, Edit, Editor};
    use nudge::scene::StateQuantity;
    use nudge::solve::{Anchor, Constraint, Diagnostic, Kind, UpdateOptions, update};
    let mut s = load("graze-plane.toml");
    let th: f64 = 1e-4;
    s.bodies[0].position = Vec3::new(0.0, 0.0, 0.1 + 0.5 * th.sin());
    s.bodies[0].velocity = Vec3::new(th.cos(), 0.0, -th.sin());
    let controls = Controls::new(&s);
    let tr = simulate(&s, &controls, &SimOptions::default()).unwrap();
    assert!(tr.events[0].grazing);
    let x = tr.state(0, 0.8, Side::Post).x;
    let drag = Constraint {
        body: 0,
        anchor: Anchor::Time(0.8),
        kind: Kind::State {
            quantities: vec![StateQuantity::Position],
            target: vec![x.x + 0.01, x.y, x.z],
        },
        drag: true,
    };
    let r = update(&s, &controls, &tr, &[drag], &UpdateOptions::default())
        .expect("an update, not an error");
    assert!(
        r.diagnostics
            .iter()
            .any(|d| matches!(d, Diagnostic::Grazing(m) if m.contains("grazing"))),
        "{:?}",
        r.diagnostics
    );
    assert!(r.u.iter().all(|v| v.is_finite()) && r.after <= r.before);
    // The editor: a nudge after the grazing contact samples and says why.
    let mut e = Editor::new(s, None).unwrap();
    e.apply(Edit::SelectTime(0.8)).unwrap();
    let out = e
        .apply(Edit::Nudge {
            quantity: StateQuantity::Position,
            delta: Vec3::new(0.01, 0.0, 0.0),
        })
        .expect("the nudge is applied or blocked, not refused");
    assert!(
        out.notes.iter().any(|d| matches!(
            d,
            nudge::edit::Note::Solver(nudge::solve::Diagnostic::Grazing(_))
        )),
        "{:?}",
        out.notes
    );
    assert!(e.controls().values(e.scene()).iter().all(|v| v.is_finite()));
}

// ---------------------------------------------------------------------------
// Zeno bouncing.
// ---------------------------------------------------------------------------
