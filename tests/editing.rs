//! Differential editing through the one editing core (`Core::apply`).

use nudge::controls::Controls;
use nudge::edit::Editor;
use nudge::edit::{Core, Edit, Expression, Note, Side, Vertical};
use nudge::geometry::Geometry;
use nudge::math::Vec3;
use nudge::scene::{Block, Effects, Scene, StateQuantity};
use nudge::sim::{SimOptions, simulate};
use nudge::solve::{self, Anchor, Constraint, Diagnostic, Kind, UpdateOptions};
use nudge::testkit::{self, body, ground, obstacle};

/// A ball thrown over the ground, bouncing once or twice; its initial
/// position and velocity are free.
fn ball_scene() -> Scene {
    let mut s = testkit::scene(1.6);
    let mut b = body(
        "ball",
        Geometry::sphere(0.1).unwrap(),
        Vec3::new(0.0, 0.0, 1.0),
    );
    b.velocity = Vec3::new(1.0, 0.0, 1.0);
    b.restitution = 0.8;
    b.free = vec![Block::Position, Block::Velocity];
    s.bodies.push(b);
    s.obstacles.push(ground());
    s
}

fn two_balls() -> Scene {
    let mut s = ball_scene();
    let mut b = body(
        "other",
        Geometry::sphere(0.1).unwrap(),
        Vec3::new(0.0, 2.0, 1.5),
    );
    b.velocity = Vec3::new(0.5, 0.0, 2.0);
    b.free = vec![Block::Position, Block::Velocity];
    s.bodies.push(b);
    s
}

fn residuals(e: &Editor) -> Vec<f64> {
    e.constraints()
        .iter()
        .map(|c| {
            c.evaluate(e.trajectory(), false)
                .map(|(r, _)| r.norm())
                .unwrap_or(f64::INFINITY)
        })
        .collect()
}

fn settle(e: &mut Editor) {
    e.apply(Edit::Settle { budget_ms: 20_000 })
        .expect("settles");
}

fn u(e: &Editor) -> Vec<u64> {
    e.controls()
        .values(e.scene())
        .iter()
        .map(|v| v.to_bits())
        .collect()
}

/// Every constraint kind, set to a target different from the current
/// motion, is driven below 1e-6 by settling.
#[test]
fn each_constraint_kind_converges() {
    // nail: move the position at t = 0.5 by 10 cm and pin it there.
    let mut e = Editor::new(ball_scene(), None).unwrap();
    e.apply(Edit::SelectTime(0.5)).unwrap();
    e.apply(Edit::Nudge {
        quantity: StateQuantity::Position,
        delta: Vec3::new(0.1, 0.0, 0.05),
    })
    .unwrap();
    e.apply(Edit::Nail {
        quantities: vec![StateQuantity::Position],
        exact: vec![],
    })
    .unwrap();
    settle(&mut e);
    assert!(residuals(&e)[0] < 1e-6, "nail {:?}", residuals(&e));

    // floating: the position just after the first bounce, time free.
    let mut e = Editor::new(ball_scene(), None).unwrap();
    let t_hit = e.trajectory().events[0].t;
    e.apply(Edit::SelectTime(t_hit)).unwrap();
    e.apply(Edit::Float {
        quantities: vec![StateQuantity::Position],
        exact: vec![],
        side: Some(Side::Post),
    })
    .unwrap();
    // Ask for the bounce to land 20 cm further along x: the same floating
    // constraint with its target moved, solved update by update.
    let mut c = e.constraints()[0].clone();
    if let Kind::State { target, .. } = &mut c.kind {
        target[0] += 0.2;
    }
    let mut s = e.scene().clone();
    s.constraints.clear();
    let tr = e.trajectory().clone();
    let controls = Controls::new(&s);
    let mut cs = vec![c];
    let mut traj = tr;
    for _ in 0..20 {
        let r = solve::update(&s, &controls, &traj, &cs, &UpdateOptions::default()).unwrap();
        assert!(
            r.after <= r.before,
            "residual rose: {} → {}",
            r.before,
            r.after
        );
        controls.write(&mut s, &r.u);
        traj = simulate(&s, &controls, &SimOptions::default()).unwrap();
        if r.after < 1e-9 {
            break;
        }
    }
    let res = solve::residual_norm(&traj, &cs);
    assert!(res < 1e-6, "floating residual {res}");
    cs.clear();

    // expressions.
    let kinds = [
        Expression::EqualSpeed { other: 1 },
        Expression::AngularSpeed { value: 0.0 },
        Expression::PointOnPlane {
            point: Vec3::zeros(),
            normal: Vec3::new(1.0, 0.0, 0.0),
            offset: 0.7,
        },
        Expression::Distance {
            other: 1,
            point: Vec3::zeros(),
            other_point: Vec3::zeros(),
            value: 1.8,
        },
    ];
    for x in kinds {
        let mut e = Editor::new(two_balls(), None).unwrap();
        e.apply(Edit::SelectTime(0.4)).unwrap();
        e.apply(Edit::Expression(x.clone())).unwrap();
        settle(&mut e);
        let r = residuals(&e)[0];
        assert!(r < 1e-6, "{x:?}: residual {r}");
    }
}

#[test]
fn a_drag_moves_the_dragged_quantity_by_the_nudge() {
    let mut e = Editor::new(ball_scene(), None).unwrap();
    e.apply(Edit::SelectTime(0.3)).unwrap();
    let before = e.trajectory().state(0, 0.3, Side::Post).x;
    let delta = Vec3::new(0.02, 0.01, -0.03);
    e.apply(Edit::Nudge {
        quantity: StateQuantity::Position,
        delta,
    })
    .unwrap();
    let after = e.trajectory().state(0, 0.3, Side::Post).x;
    assert!(
        (after - before - delta).norm() < 1e-6,
        "moved {:?}",
        after - before
    );
    assert!(e.dirty());
}

#[test]
fn a_nail_holds_while_another_time_is_dragged() {
    let mut e = Editor::new(ball_scene(), None).unwrap();
    e.apply(Edit::SelectTime(1.4)).unwrap();
    e.apply(Edit::Nail {
        quantities: vec![StateQuantity::Position],
        exact: vec![],
    })
    .unwrap();
    e.apply(Edit::SelectTime(0.2)).unwrap();
    for k in 0..5 {
        e.apply(Edit::Nudge {
            quantity: StateQuantity::Position,
            delta: Vec3::new(0.0, 0.01, 0.01),
        })
        .unwrap();
        let r = residuals(&e)[0];
        assert!(r < 1e-6, "after nudge {k}: nail residual {r}");
    }
}

#[test]
fn duplicate_nails_converge_and_conflicting_nails_give_least_squares() {
    let s = ball_scene();
    let controls = Controls::new(&s);
    let traj = simulate(&s, &controls, &SimOptions::default()).unwrap();
    let x = traj.state(0, 0.5, Side::Post).x;
    let nail = |dx: f64| Constraint {
        body: 0,
        anchor: Anchor::Time(0.5),
        kind: Kind::State {
            quantities: vec![StateQuantity::Position],
            target: vec![x.x + dx, x.y, x.z],
        },
        drag: false,
    };
    // Identical nails: rank-deficient but consistent.
    let dup = vec![nail(0.05), nail(0.05)];
    let r = solve::update(&s, &controls, &traj, &dup, &UpdateOptions::default()).unwrap();
    assert!(
        r.after < 1e-3 * r.before,
        "duplicates converge: {} → {}",
        r.before,
        r.after
    );
    assert!(
        !r.diagnostics
            .iter()
            .any(|d| matches!(d, Diagnostic::Conflicting { .. }))
    );
    // Conflicting nails: the least-squares point is the midpoint.
    let conflict = vec![nail(0.05), nail(-0.05)];
    let r = solve::update(&s, &controls, &traj, &conflict, &UpdateOptions::default()).unwrap();
    assert!(r.u.iter().all(|v| v.is_finite()));
    let conflicting = r.diagnostics.iter().find_map(|d| match d {
        Diagnostic::Conflicting { residual } => Some(*residual),
        _ => None,
    });
    let residual = conflicting.expect("Conflicting diagnostic");
    assert!(
        (residual - 0.1 / 2f64.sqrt()).abs() < 1e-6,
        "unmet part {residual}"
    );
    // Staying at the midpoint is already least squares: no step raises it.
    assert!(r.after <= r.before + 1e-15);
}

#[test]
fn a_drag_with_no_free_controls_says_which_block_to_free() {
    let mut s = ball_scene();
    s.bodies[0].free.clear();
    let mut e = Editor::new(s, None).unwrap();
    let err = e
        .apply(Edit::Nudge {
            quantity: StateQuantity::Position,
            delta: Vec3::new(0.1, 0.0, 0.0),
        })
        .unwrap_err();
    assert!(err.to_string().contains("free a block of ball"), "{err}");
    assert!(!e.dirty());
}

/// Across a facet boundary of a polygonal obstacle (paper §5) the update
/// either pops into the neighbouring smooth component with a lower residual
/// or reports that the edit is blocked — never a wild step.
#[test]
fn a_drag_across_a_facet_boundary_pops_or_blocks() {
    let mut s = testkit::scene(1.0);
    s.effects = Effects {
        gravity: true,
        collisions: true,
        ..Default::default()
    };
    // A roof of two facets meeting at x = 0.
    let roof = Geometry::convex_hull(&[
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(0.0, -1.0, 0.3),
        Vec3::new(0.0, 1.0, 0.3),
    ])
    .unwrap();
    s.obstacles.push(obstacle("roof", roof, Vec3::zeros()));
    let mut p = body(
        "particle",
        Geometry::sphere(0.02).unwrap(),
        Vec3::new(-0.15, 0.0, 1.0),
    );
    p.free = vec![Block::Position];
    s.bodies.push(p);
    let mut e = Editor::new(s, None).unwrap();
    e.apply(Edit::SelectTime(0.9)).unwrap();
    let key0 = e.trajectory().events[0].key.clone();
    let mut outcomes = Vec::new();
    for _ in 0..30 {
        let res_before = e.view().status.residual;
        let o = e
            .apply(Edit::Nudge {
                quantity: StateQuantity::Position,
                delta: Vec3::new(0.05, 0.0, 0.0),
            })
            .unwrap();
        assert!(e.view().status.residual <= res_before + 1e-12);
        outcomes.extend(o.notes);
        if e.trajectory().events.first().map(|ev| ev.key.clone()) != Some(key0.clone()) {
            break;
        }
    }
    let crossed = e.trajectory().events.first().map(|ev| ev.key.clone()) != Some(key0);
    let popped = outcomes
        .iter()
        .any(|d| matches!(d, Note::Solver(Diagnostic::Pop { .. })));
    let blocked = outcomes
        .iter()
        .any(|d| matches!(d, Note::Solver(Diagnostic::Blocked)));
    assert!(
        (crossed && popped) || blocked,
        "crossed {crossed}, diagnostics {outcomes:?}"
    );
}

#[test]
fn undo_restores_u_bit_for_bit_and_redo_reapplies() {
    let mut e = Editor::new(ball_scene(), None).unwrap();
    let u0 = u(&e);
    e.apply(Edit::SelectTime(0.4)).unwrap();
    let mut seen = vec![u(&e)];
    for k in 0..6 {
        let d = 0.01 * (k as f64 + 1.0);
        e.apply(Edit::Nudge {
            quantity: StateQuantity::Position,
            delta: Vec3::new(d, -d, 0.5 * d),
        })
        .unwrap();
        seen.push(u(&e));
    }
    for k in (0..6).rev() {
        e.apply(Edit::Undo).unwrap();
        assert_eq!(u(&e), seen[k], "undo to edit {k}");
    }
    assert_eq!(u(&e), u0);
    assert!(e.apply(Edit::Undo).is_err(), "nothing left to undo");
    e.apply(Edit::Redo).unwrap();
    assert_eq!(u(&e), seen[1]);
}

#[test]
fn save_then_load_reproduces_the_trajectory_bit_for_bit() {
    let tmp = tempfile::Builder::new()
        .prefix("nudge-save-")
        .tempdir()
        .expect("temp dir");
    let dir = tmp.path().to_path_buf();
    let path = dir.join("edited.toml");
    // Saving writes shapes from their source text: start from a loaded file.
    let text = "duration = 1.6\neffects = [\"gravity\", \"collisions\"]\n[[body]]\nname = \"ball\"\nshape = { type = \"sphere\", radius = 0.1 }\ndensity = 1000.0\nposition = [0.0, 0.0, 1.0]\nvelocity = [1.0, 0.0, 1.0]\nrestitution = 0.8\nfree = [\"position\", \"velocity\"]\n[[obstacle]]\nname = \"ground\"\nshape = { type = \"plane\", normal = [0.0, 0.0, 1.0] }\n";
    let scene = nudge::scene::load_str(text, "inline").unwrap();
    let mut e = Editor::new(scene, Some(path.clone())).unwrap();
    e.apply(Edit::SelectTime(0.7)).unwrap();
    e.apply(Edit::Nudge {
        quantity: StateQuantity::Position,
        delta: Vec3::new(0.13, 0.07, 0.02),
    })
    .unwrap();
    e.apply(Edit::Nail {
        quantities: vec![],
        exact: vec![],
    })
    .unwrap();
    let saved = e.save(None, nudge::edit::WriteMode::Normal).unwrap();
    assert_eq!(saved.layout_lost, None, "the text is kept");
    let saved = saved.path;
    assert!(!e.dirty());
    let back = Editor::open(&saved).unwrap();
    assert_eq!(u(&back), u(&e));
    assert_eq!(back.constraints().len(), 1);
    for t in [0.0, 0.3, 0.7, 1.2, 1.6] {
        let a = e.trajectory().state(0, t, Side::Post);
        let b = back.trajectory().state(0, t, Side::Post);
        assert_eq!(a.x.map(f64::to_bits), b.x.map(f64::to_bits), "t={t}");
        assert_eq!(a.v.map(f64::to_bits), b.v.map(f64::to_bits), "t={t}");
    }
}

#[test]
fn non_finite_edits_are_rejected_and_leave_history_untouched() {
    let mut e = Editor::new(ball_scene(), None).unwrap();
    e.apply(Edit::SelectTime(0.4)).unwrap();
    e.apply(Edit::Nudge {
        quantity: StateQuantity::Position,
        delta: Vec3::new(0.01, 0.0, 0.0),
    })
    .unwrap();
    let before = u(&e);
    for bad in [
        Edit::Nudge {
            quantity: StateQuantity::Velocity,
            delta: Vec3::new(f64::NAN, 0.0, 0.0),
        },
        Edit::Nudge {
            quantity: StateQuantity::Position,
            delta: Vec3::new(0.0, f64::INFINITY, 0.0),
        },
        Edit::SelectTime(f64::NAN),
        Edit::SetScale {
            kind: nudge::scene::ScaleKind::Velocity,
            value: f64::NAN,
        },
        Edit::Expression(Expression::AngularSpeed { value: f64::NAN }),
    ] {
        let err = e.apply(bad.clone());
        assert!(err.is_err(), "{bad:?} accepted");
        assert_eq!(u(&e), before, "{bad:?} changed u");
    }
    // One undo goes back past the single accepted nudge, not past a rejected edit.
    e.apply(Edit::Undo).unwrap();
    assert!(e.apply(Edit::Undo).is_err());
    let v = e.view();
    assert!(
        v.controls
            .iter()
            .all(|c| c.value.is_finite() && c.delta.is_finite())
    );
}

/// Typed values (`:nail pos 0.8 0 0.9`, `:float post vel ...`): the
/// constraint holds the quantity at the typed value, settling reaches it,
/// and a value for a quantity the constraint does not hold, or a
/// non-finite one, is refused without changing anything.
#[test]
fn nails_and_floating_constraints_hold_typed_values() {
    let mut e = Editor::new(ball_scene(), None).unwrap();
    e.apply(Edit::SelectTime(0.5)).unwrap();
    let want = Vec3::new(0.8, 0.05, 0.9);
    e.apply(Edit::Nail {
        quantities: vec![StateQuantity::Position, StateQuantity::Velocity],
        exact: vec![(StateQuantity::Position, want)],
    })
    .unwrap();
    let v_before = e.trajectory().state(0, 0.5, Side::Post).v;
    assert!(residuals(&e)[0] > 0.1, "typed away from the motion");
    settle(&mut e);
    let s = e.trajectory().state(0, 0.5, Side::Post);
    assert!((s.x - want).norm() < 1e-9, "at {:?}", s.x);
    assert!((s.v - v_before).norm() < 1e-9, "velocity held at its value");

    // Floating: the velocity just after the first bounce, typed.
    let mut e = Editor::new(ball_scene(), None).unwrap();
    let t_hit = e.trajectory().events[0].t;
    e.apply(Edit::SelectTime(t_hit)).unwrap();
    let post = Vec3::new(1.2, 0.0, 3.0);
    e.apply(Edit::Float {
        quantities: vec![StateQuantity::Velocity],
        exact: vec![(StateQuantity::Velocity, post)],
        side: Some(Side::Post),
    })
    .unwrap();
    settle(&mut e);
    let hit = e.trajectory().events[0].t;
    let s = e.trajectory().state(0, hit, Side::Post);
    assert!((s.v - post).norm() < 1e-8, "{:?} after the bounce", s.v);

    // Refused: nothing changes.
    let before = u(&e);
    let n = e.constraints().len();
    for exact in [
        vec![(StateQuantity::Orientation, Vec3::zeros())],
        vec![(StateQuantity::Position, Vec3::new(f64::NAN, 0.0, 0.0))],
    ] {
        let err = e
            .apply(Edit::Nail {
                quantities: vec![StateQuantity::Position],
                exact,
            })
            .expect_err("refused");
        assert!(
            err.to_string().contains("orientation") || err.to_string().contains("finite"),
            "{err}"
        );
    }
    assert_eq!((u(&e), e.constraints().len()), (before, n));
}

/// Constraint `i`'s rows `C` against central differences of its residual
/// (to 1e-6 relative, per control); returns the residual.
fn rows_match_central_differences(e: &Editor, i: usize) -> nalgebra::DVector<f64> {
    let c = e.constraints()[i].clone();
    let (r0, rows) = c.evaluate(e.trajectory(), true).unwrap();
    let rows = rows.expect("rows");
    let controls = e.controls().clone();
    let u0 = controls.values(e.scene());
    for k in 0..u0.len() {
        let h = 1e-6;
        let at = |d: f64| {
            let mut s = e.scene().clone();
            let mut u = u0.clone();
            u[k] += d;
            controls.write(&mut s, &u);
            let tr = simulate(&s, &controls, &SimOptions::default()).unwrap();
            c.evaluate(&tr, false).unwrap().0
        };
        // r = goal − current, so d(current)/du = −dr/du.
        let fd = -(at(h) - at(-h)) / (2.0 * h);
        let err = (rows.column(k) - &fd).norm() / fd.norm().max(1e-3);
        assert!(err < 1e-6, "constraint {i}, column {k}: {err:.2e}");
    }
    r0
}

/// A lopsided box tumbling with angular velocity `w`, its orientation and
/// spin free, with a `goal` constraint about the vertical at t = 0.5 s.
fn tumbling_box(w: Vec3, goal: Vertical) -> Editor {
    let mut s = testkit::scene(1.0);
    s.effects.gyroscopic = true;
    let mut b = body(
        "box",
        Geometry::cuboid(Vec3::new(0.2, 0.1, 0.05)).unwrap(),
        Vec3::new(0.0, 0.0, 2.0),
    );
    b.orientation = Vec3::new(0.3, -0.2, 0.4);
    b.angular_velocity = w;
    b.free = vec![Block::Orientation, Block::AngularVelocity];
    s.bodies.push(b);
    let mut e = Editor::new(s, None).unwrap();
    e.apply(Edit::SelectTime(0.5)).unwrap();
    e.apply(Edit::Vertical { goal, side: None }).unwrap();
    e
}

/// `:upright`: a tumbling box's z axis is brought straight up at a time,
/// whatever its turn about the vertical (the yaw is left free), and the
/// constraint rows match finite differences.
#[test]
fn an_upright_constraint_brings_the_z_axis_vertical() {
    let mut e = tumbling_box(Vec3::new(0.5, 1.0, 0.2), Vertical::Upright);
    // Rows against central differences before solving.
    let r0 = rows_match_central_differences(&e, 0);
    assert!(r0.norm() > 0.1, "tilted to begin with");
    settle(&mut e);
    let st = e.trajectory().state(0, 0.5, Side::Post);
    let tilt = (st.q * Vec3::z()).z.clamp(-1.0, 1.0).acos();
    assert!(tilt < 1e-6, "tilt {tilt:.2e} rad");
}

/// `:steady`: a tumbling box's angular velocity is turned onto the vertical
/// at a time (it may spin about the vertical, not tumble), the constraint
/// rows match finite differences, and the spin about the vertical is left
/// to the solver.
#[test]
fn a_steady_constraint_leaves_only_spin_about_the_vertical() {
    let mut e = tumbling_box(Vec3::new(0.5, 1.0, 2.0), Vertical::Steady);
    assert_eq!(e.constraints()[0].label(), "steady");
    let r0 = rows_match_central_differences(&e, 0);
    assert!(r0.norm() > 0.5, "tumbling to begin with: {r0}");
    settle(&mut e);
    let w = e.trajectory().state(0, 0.5, Side::Post).w;
    assert!(w.xy().norm() < 1e-8, "still tumbling: ω = {w}");
    assert!(
        w.z.abs() > 0.1,
        "the spin about the vertical was removed too: ω = {w}"
    );
}

/// After undo and redo the status showed the undone accuracy setting, the
/// Δ column kept the sign of the undo, and undoing every edit still left
/// the scene marked unsaved.
#[test]
fn regression_undo_and_redo_left_stale_status_delta_and_dirty_flag() {
    let mut e = Editor::new(ball_scene(), None).unwrap();
    let label = e.view().status.accuracy.clone();
    let mut acc = e.scene().accuracy;
    acc.method = nudge::scene::Method::Rk4 { step: 2e-3 };
    e.apply(Edit::SetAccuracy(acc)).unwrap();
    assert_ne!(e.view().status.accuracy, label);
    e.apply(Edit::Undo).unwrap();
    assert_eq!(e.view().status.accuracy, label, "undo restores the label");
    assert!(!e.dirty(), "back at the opened state");
    e.apply(Edit::SelectTime(0.3)).unwrap();
    e.apply(Edit::Nudge {
        quantity: StateQuantity::Position,
        delta: Vec3::new(0.05, 0.0, 0.0),
    })
    .unwrap();
    let delta = |e: &Editor| {
        e.view()
            .controls
            .iter()
            .find(|c| c.name == "ball.velocity.x")
            .map(|c| c.delta)
            .unwrap_or(0.0)
    };
    let after_nudge = delta(&e);
    assert!(after_nudge > 0.0, "the nudge raised v.x");
    e.apply(Edit::Undo).unwrap();
    assert!(delta(&e) < 0.0 && !e.dirty());
    e.apply(Edit::Redo).unwrap();
    assert!(
        (delta(&e) - after_nudge).abs() < 1e-12,
        "redo shows the nudge's Δ"
    );
    assert!(e.dirty());
    // Refused: a step that would take ten million steps.
    let mut tiny = e.scene().accuracy;
    tiny.method = nudge::scene::Method::Rk4 { step: 1e-9 };
    let err = e.apply(Edit::SetAccuracy(tiny)).expect_err("refused");
    assert!(err.to_string().contains("at least"), "{err}");
}

/// Event controls can be fixed and freed at run time, like body blocks: a
/// fixed event's normal and restitution keep their values while a drag
/// moves the other controls, and freeing them lets the solver use them
/// again.
#[test]
fn fixed_event_controls_keep_their_values_through_a_drag() {
    let mut scene = ball_scene();
    scene.bodies[0].free.clear();
    let mut e = Editor::new(scene, None).unwrap();
    let bounce = e.trajectory().events[0].t;
    // No controls at the bounce yet: a typed error that says how to add them.
    e.apply(Edit::SelectTime(bounce)).unwrap();
    let err = e
        .apply(Edit::SetEventControls {
            event: None,
            free: Some(false),
        })
        .expect_err("no controls to fix");
    assert!(err.to_string().contains("press e"), "{err}");
    e.apply(Edit::AddEventControls {
        normal: true,
        restitution: true,
    })
    .unwrap();
    let event_values = |e: &Editor| -> Vec<u64> {
        let c = e.scene().event_controls[0];
        let [a, b] = c.normal.unwrap();
        [a, b, c.restitution.unwrap()]
            .iter()
            .map(|v| v.to_bits())
            .collect()
    };
    let drag = |e: &mut Editor| {
        e.apply(Edit::SelectTime(bounce + 0.3)).unwrap();
        e.apply(Edit::Nudge {
            quantity: StateQuantity::Position,
            delta: Vec3::new(0.02, 0.0, 0.01),
        })
    };
    // Free: the drag after the bounce moves the surface.
    let v0 = event_values(&e);
    drag(&mut e).unwrap();
    assert_ne!(event_values(&e), v0, "the free surface controls moved");
    // Fixed (toggled): nothing else is free, so the drag is refused and
    // says which block to free; the surface keeps its values bit for bit.
    e.apply(Edit::SelectTime(bounce)).unwrap();
    e.apply(Edit::SetEventControls {
        event: None,
        free: None,
    })
    .unwrap();
    assert!(e.scene().event_controls[0].fixed);
    assert!(e.controls().free.is_empty());
    let v1 = event_values(&e);
    let _ = drag(&mut e);
    assert_eq!(event_values(&e), v1);
    // With the ball's velocity freed, the drag moves the velocity only.
    e.apply(Edit::SetBlock {
        body: 0,
        block: Block::Velocity,
        free: true,
    })
    .unwrap();
    let vel0 = e.scene().bodies[0].velocity;
    drag(&mut e).unwrap();
    assert_eq!(event_values(&e), v1);
    assert_ne!(e.scene().bodies[0].velocity, vel0);
    // Freed by its global index: the surface moves again.
    e.apply(Edit::SetEventControls {
        event: Some(0),
        free: Some(true),
    })
    .unwrap();
    assert!(!e.scene().event_controls[0].fixed);
    drag(&mut e).unwrap();
    assert_ne!(event_values(&e), v1);
}

/// `:nail position 1e308 1e308 1e308` and `:spin 1e308` used to be
/// accepted with a residual of `null` (`r=—` on the status line). A target
/// whose distance overflows is refused and nothing changes.
#[test]
fn a_target_too_far_to_measure_is_refused_and_nothing_changes() {
    use nudge::edit::EditError;
    let mut e = Editor::new(ball_scene(), None).expect("editor");
    e.apply(Edit::SelectTime(0.5)).expect("select a time");
    let constraints = e.constraints().len();
    let values = e.view().controls;
    let far = Vec3::repeat(1e308);
    let refused = [
        Edit::Nail {
            quantities: vec![StateQuantity::Position],
            exact: vec![(StateQuantity::Position, far)],
        },
        Edit::Expression(Expression::AngularSpeed { value: 1e308 }),
    ];
    for edit in refused {
        assert_eq!(
            e.apply(edit.clone()),
            Err(EditError::TargetOutOfRange),
            "{edit:?}"
        );
        assert_eq!(e.constraints().len(), constraints);
        assert_eq!(e.view().controls, values);
        assert!(e.view().status.residual.is_finite());
    }
    // A far but measurable target is taken (and the edit may then block).
    e.apply(Edit::Nail {
        quantities: vec![StateQuantity::Position],
        exact: vec![(StateQuantity::Position, Vec3::repeat(1e100))],
    })
    .expect("a target 1e100 m away is measurable");
    assert_eq!(e.constraints().len(), constraints + 1);
}

/// A nudge whose motion outgrows the stored-motion budget (a box driven to
/// 1e5 rad/s) is refused with the budget's message and changes nothing: it
/// used to stall the editor for 40 s while filling 7 GB.
#[test]
fn a_nudge_beyond_the_memory_budget_is_refused_and_nothing_changes() {
    let text = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/extreme/box-spinning-1.4e5.toml"
    ))
    .expect("fixture")
    .replace("140000.0", "140.0");
    let scene = nudge::scene::load_str(&text, "box.toml").expect("loads");
    let mut e = Editor::new(scene, None).expect("140 rad/s fits");
    let values = e.view().controls;
    let refused = e.apply(Edit::Nudge {
        quantity: StateQuantity::AngularVelocity,
        delta: Vec3::new(0.0, 1e5, 0.0),
    });
    match refused {
        Err(err) => assert!(err.to_string().contains("MiB budget"), "{err}"),
        Ok(o) => panic!("accepted: {o:?}"),
    }
    assert_eq!(e.view().controls, values);
    assert!(e.trajectory().stored_values() <= nudge::sim::MAX_STORED_VALUES);
}

/// Every constraint a scene file can hold loads into the editor and is
/// saved back: nothing the file says is dropped (an unknown kind or a
/// short target used to load and vanish on the next `:w`; now those are
/// load errors, see tests/invalid_scenes/constraint_*.toml).
#[test]
fn every_kind_of_saved_constraint_is_held_and_saved_back() {
    let text = r#"
duration = 1.2
effects = ["gravity", "collisions"]
[[body]]
name = "a"
shape = { type = "sphere", radius = 0.1 }
mass = 1.0
position = [0.0, 0.0, 1.0]
free = ["position", "velocity"]
[[body]]
name = "b"
shape = { type = "box", half_extents = [0.1, 0.1, 0.1] }
mass = 1.0
position = [1.0, 0.0, 1.0]
free = ["position", "velocity"]
[[obstacle]]
name = "floor"
shape = { type = "plane", normal = [0.0, 0.0, 1.0] }
[[constraint]]
kind = "nail"
body = "a"
time = 0.2
quantities = ["position"]
target = [0.0, 0.0, 0.8]
[[constraint]]
kind = "floating"
body = "a"
collision = 0
side = "pre"
quantities = ["velocity"]
target = [0.0, 0.0, -4.0]
[[constraint]]
kind = "equal_speed"
body = "a"
other = "b"
time = 0.1
[[constraint]]
kind = "angular_speed"
body = "b"
time = 0.1
target = [0.0]
[[constraint]]
kind = "upright"
body = "b"
collision = 0
side = "post"
target = [0.0, 0.0, 1.0]
[[constraint]]
kind = "steady"
body = "b"
time = 0.3
target = [0.0, 0.0, 1.0]
[[constraint]]
kind = "point_on_plane"
body = "a"
time = 0.3
target = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
[[constraint]]
kind = "distance"
body = "a"
other = "b"
time = 0.3
target = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]
"#;
    let scene = nudge::scene::load_str(text, "kinds.toml").expect("every kind loads");
    assert_eq!(scene.constraints.len(), 8);
    let e = Editor::new(scene.clone(), None).expect("editor");
    assert_eq!(e.constraints().len(), 8, "every constraint is held");
    let saved = e.scene_to_save();
    assert_eq!(
        saved.constraints, scene.constraints,
        "and saved back as read"
    );
    let again = nudge::scene::load_str(&nudge::scene::to_toml(&saved), "again.toml")
        .expect("the saved scene loads");
    assert_eq!(again.constraints, scene.constraints);
}

/// A nail that holds the state at t=0.5 blocks a drag of the position at
/// t=0.75 (free flight in between: the state at 0.5 decides the one at
/// 0.75). The editor names the nail and the release that lets the drag
/// through; applying it, the same drag moves the ball.
#[test]
fn a_blocked_drag_names_the_nail_and_its_release_lets_the_drag_through() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bounce.toml");
    let mut e = Editor::open(&path).unwrap();
    e.apply(Edit::SelectTime(0.5)).unwrap();
    e.apply(Edit::Nail {
        quantities: vec![],
        exact: vec![],
    })
    .unwrap();
    e.apply(Edit::SelectTime(0.75)).unwrap();
    let x0 = e.view().pose.expect("pose").position;
    let drag = Edit::Nudge {
        quantity: StateQuantity::Position,
        delta: Vec3::new(0.0, 0.0, 0.02),
    };
    let out = e.apply(drag.clone()).unwrap();
    let blockers = out
        .notes
        .iter()
        .find_map(|n| match n {
            Note::BlockedBy(b) => Some(b.clone()),
            _ => None,
        })
        .unwrap_or_else(|| panic!("no blocker named: {:?}", out.notes));
    assert_eq!(blockers.len(), 1, "{blockers:?}");
    let b = &blockers[0];
    assert_eq!((b.row, b.kind, b.body.as_str()), (0, "nail", "ball"));
    assert!(!b.quantities.is_empty(), "{b:?}");
    let text = Note::BlockedBy(blockers.clone()).to_string();
    assert!(text.contains("nail of ball at t=0.500"), "{text}");
    assert!(
        text.contains(&format!(":release 0 {}", b.quantities[0].name())),
        "{text}"
    );
    let stuck = e.view().pose.expect("pose").position;
    assert!(
        (stuck - x0).norm() < 1e-3,
        "the blocked drag moved {}",
        (stuck - x0).norm()
    );
    // The suggested change, then the same drag.
    e.apply(Edit::Release {
        row: 0,
        quantities: vec![b.quantities[0]],
    })
    .unwrap();
    e.apply(drag).unwrap();
    let moved = e.view().pose.expect("pose").position;
    assert!(
        (moved.z - x0.z - 0.02).abs() < 1e-3,
        "after the release the drag moved the ball by {}",
        moved.z - x0.z
    );
    assert!(e.view().constraints[0].residual < 1e-9);
}
