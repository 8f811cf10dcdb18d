//! The headless runner end to end: key scripts through the real key map,
//! App and widgets on a `TestBackend`, against a fake core with a fixed
//! synthetic view. Whole-screen snapshots live in `tests/snapshots/`.

use nudge::edit::{Core, Edit, EditError, Outcome, Saved};
use nudge::math::Vec3;
use nudge::script::{Key, KeyScriptError, parse_keys, run_script};
use nudge::tui::KEYMAP;
use nudge::view::{ConstraintRow, ControlRow, EventMark, Path, Status, View};
use proptest::prelude::*;
use std::path::{Path as FsPath, PathBuf};

/// A fake editing core: a ball on a parabolic path bouncing off a box and
/// the ground, a crate sliding slowly, six controls and two constraints. Nudges shift the
/// selected body's path; nails add constraint rows. With `poison`, every
/// number the view carries is NaN or infinite.
struct FakeCore {
    view: View,
    log: Vec<Edit>,
    dirty: bool,
    poison: bool,
}

fn outline(c: Vec3, r: f64) -> Vec<(Vec3, Vec3)> {
    let p = [
        Vec3::new(c.x - r, c.y, c.z - r),
        Vec3::new(c.x + r, c.y, c.z - r),
        Vec3::new(c.x + r, c.y, c.z + r),
        Vec3::new(c.x - r, c.y, c.z + r),
    ];
    (0..4).map(|i| (p[i], p[(i + 1) % 4])).collect()
}

/// Where the ball is at time `t`: thrown from (−2, 0, 0.5) at (3, 0, 4.5)
/// m/s, bouncing (restitution 0.7) on the top of the box (z = 0.5 for
/// 0 ≤ x ≤ 1) and then on the ground (z = −0.5). Returns the position and
/// the bounces so far as `(t, point)`.
fn ball_at(t: f64) -> (Vec3, Vec<(f64, Vec3)>) {
    const G: f64 = 9.81;
    let (mut t0, mut p0, mut vz) = (0.0, Vec3::new(-2.0, 0.0, 0.5), 4.5);
    let mut hits = Vec::new();
    loop {
        // Time to fall to height `floor`: z0 + vz s − G s²/2 = floor.
        let fall = |floor: f64| (vz + (vz * vz + 2.0 * G * (p0.z - floor)).max(0.0).sqrt()) / G;
        let at = |s: f64| Vec3::new(p0.x + 3.0 * s, 0.0, p0.z + vz * s - 0.5 * G * s * s);
        let on_box = fall(0.5);
        let s = if p0.z >= 0.5 - 1e-9 && (0.0..=1.0).contains(&at(on_box).x) {
            on_box
        } else {
            fall(-0.5)
        };
        if t <= t0 + s || hits.len() >= 3 {
            return (at(t - t0), hits);
        }
        let hit = at(s);
        hits.push((t0 + s, hit));
        vz = -0.7 * (vz - G * s);
        t0 += s;
        p0 = hit;
    }
}

impl FakeCore {
    fn new() -> FakeCore {
        let ball: Vec<Vec3> = (0..=80).map(|i| ball_at(f64::from(i) * 0.025).0).collect();
        let (now, _) = ball_at(0.6);
        let (_, hits) = ball_at(2.0);
        let crate_path: Vec<Vec3> = (0..=10)
            .map(|i| Vec3::new(4.0 + 0.02 * f64::from(i), 0.0, -0.25))
            .collect();
        let control = |name: &str, value: f64, delta: f64, free: bool, scale: f64| ControlRow {
            name: name.into(),
            value,
            delta,
            free,
            scale,
        };
        let view = View {
            scene: "toss".into(),
            notes: String::new(),
            duration: 2.0,
            time: 0.6,
            bodies: vec!["ball".into(), "crate".into()],
            selected: 0,
            paths: vec![
                Path {
                    body: 0,
                    times: (0..ball.len()).map(|k| k as f64 * 0.05).collect(),
                    points: ball,
                },
                Path {
                    body: 1,
                    times: (0..crate_path.len()).map(|k| k as f64 * 0.05).collect(),
                    points: crate_path,
                },
            ],
            obstacles: [
                outline(Vec3::new(0.5, 0.0, 0.0), 0.5),
                vec![(Vec3::new(-2.5, 0.0, -0.5), Vec3::new(5.5, 0.0, -0.5))],
            ]
            .concat(),
            selected_outline: outline(now, 0.1),
            ghost: Vec::new(),
            pose: None,
            targets: Vec::new(),
            body_outlines: outline(Vec3::new(4.1, 0.0, -0.25), 0.25),
            events: hits
                .iter()
                .enumerate()
                .map(|(index, (t, point))| EventMark {
                    index,
                    t: *t,
                    point: *point,
                    a: "ball".into(),
                    b: if index == 0 {
                        "box".into()
                    } else {
                        "ground".into()
                    },
                    grazing: index == 2,
                    ..EventMark::default()
                })
                .collect(),
            controls: vec![
                control("ball.position.x", -2.0, 0.0, true, 1.0),
                control("ball.position.z", 0.5, 0.0125, true, 1.0),
                control("ball.velocity.x", 1.25, -0.003, true, 2.0),
                control("ball.velocity.z", 3.0, 0.0, true, 2.0),
                control("crate.mass", 4.0, 0.0, false, 1.0),
                control("hit0.restitution", 0.7, 0.0, true, 10.0),
            ],
            constraints: vec![
                ConstraintRow {
                    kind: "nail".into(),
                    body: "ball".into(),
                    at: "t=2.000".into(),
                    residual: 3.2e-9,
                    gap: Some(3.2e-9),
                },
                ConstraintRow {
                    kind: "floating".into(),
                    body: "ball".into(),
                    at: "hit#0 post".into(),
                    residual: 0.0,
                    gap: None,
                },
            ],
            status: Status {
                update_ms: 4.2,
                residual: 3.2e-9,
                step: 0.5,
                pops: 1,
                blocks: 2,
                accuracy: "rk4 h=1e-3".into(),
                message: None,
                busy: None,
                integration_error: None,
            },
            dirty: false,
            accuracy: Default::default(),
        };
        FakeCore {
            view,
            log: Vec::new(),
            dirty: false,
            poison: false,
        }
    }

    fn poisoned() -> FakeCore {
        FakeCore {
            poison: true,
            ..FakeCore::new()
        }
    }
}

impl Core for FakeCore {
    fn apply(&mut self, edit: Edit) -> Result<Outcome, EditError> {
        let v = &mut self.view;
        match &edit {
            Edit::SelectBody(i) if *i < v.bodies.len() => v.selected = *i,
            Edit::SelectTime(t) if t.is_finite() => v.time = t.clamp(0.0, v.duration),
            Edit::SelectEvent(k) if *k < v.events.len() => v.time = v.events[*k].t,
            Edit::Nudge { delta, .. } => {
                v.ghost = v.paths.clone();
                let body = v.selected;
                for p in v.paths.iter_mut().filter(|p| p.body == body) {
                    p.points.iter_mut().for_each(|q| *q += delta);
                }
                v.controls[0].delta = delta.x;
                v.controls[0].value += delta.x;
            }
            Edit::Nail { .. } => v.constraints.push(ConstraintRow {
                kind: "nail".into(),
                body: v.bodies[v.selected].clone(),
                gap: None,
                at: format!("t={:.3}", v.time),
                residual: 0.0,
            }),
            Edit::RemoveConstraint(k) if *k < v.constraints.len() => {
                v.constraints.remove(*k);
            }
            Edit::Undo => return Err(EditError::Invalid("nothing to undo".into())),
            Edit::SelectBody(_)
            | Edit::SelectTime(_)
            | Edit::SelectEvent(_)
            | Edit::RemoveConstraint(_) => {
                return Err(EditError::Invalid(format!("refused {edit:?}")));
            }
            _ => {}
        }
        self.dirty = true;
        self.log.push(edit);
        Ok(Outcome {
            updates: 1,
            ..Outcome::default()
        })
    }

    fn view(&self) -> View {
        let mut v = View {
            dirty: self.dirty,
            ..self.view.clone()
        };
        if self.poison {
            v.time = f64::NAN;
            v.duration = f64::INFINITY;
            v.status.update_ms = f64::NAN;
            v.status.residual = f64::INFINITY;
            v.status.step = f64::NEG_INFINITY;
            for c in &mut v.controls {
                (c.value, c.delta, c.scale) = (f64::NAN, f64::INFINITY, f64::NAN);
            }
            for c in &mut v.constraints {
                c.residual = f64::NAN;
                c.at = format!("t={}", f64::INFINITY);
            }
            v.status.accuracy = format!("rk4 h={}", f64::NAN);
            for e in &mut v.events {
                e.t = f64::NAN;
                e.point = Vec3::new(f64::INFINITY, 0.0, 0.0);
            }
            v.paths[0].points.push(Vec3::new(f64::NAN, 0.0, f64::NAN));
        }
        v
    }

    fn save(
        &mut self,
        path: Option<&FsPath>,
        _: nudge::edit::WriteMode,
    ) -> Result<Saved, EditError> {
        self.dirty = false;
        Ok(Saved {
            path: path.map_or_else(|| PathBuf::from("toss.toml"), FsPath::to_path_buf),
            layout_lost: None,
        })
    }

    fn dirty(&self) -> bool {
        self.dirty
    }

    fn report(&self) -> serde_json::Value {
        serde_json::json!({ "edits": self.log.len() })
    }
}

fn keys(script: &str) -> Vec<Key> {
    match parse_keys(script, "test.keys") {
        Ok(k) => k,
        Err(e) => panic!("{e}"),
    }
}

#[test]
fn screen_80x24() {
    let r = run_script::<Key>(&mut FakeCore::new(), &[], (80, 24));
    insta::assert_snapshot!("screen_80x24", r.screen);
}

#[test]
fn screen_too_small() {
    let r = run_script::<Key>(&mut FakeCore::new(), &[], (50, 12));
    assert!(r.screen.contains("terminal too small"), "{}", r.screen);
    insta::assert_snapshot!("screen_too_small", r.screen);
}

#[test]
fn screen_help_popup() {
    let r = run_script(&mut FakeCore::new(), &keys("?"), (80, 24));
    insta::assert_snapshot!("screen_help_80x24", r.screen);
}

#[test]
fn session_nudges_nails_and_moves_in_time() {
    let mut core = FakeCore::new();
    let r = run_script(
        &mut core,
        &keys("# drag up, nail, next event\nK 5l a } V"),
        (80, 24),
    );
    assert!(!r.quit);
    let kinds: Vec<String> = core
        .log
        .iter()
        .map(|e| {
            format!("{e:?}")
                .split([' ', '('])
                .next()
                .unwrap_or("")
                .to_string()
        })
        .collect();
    assert_eq!(kinds, ["Nudge", "Nudge", "Nail", "SelectEvent"]);
    assert_eq!(r.edits, 4);
    assert_eq!(r.update_ms.len(), 4);
    assert_eq!(r.render_ms.len(), 7);
    assert!(
        r.update_latency()
            .is_some_and(|l| l.median <= l.p95 && l.p95 <= l.max)
    );
    insta::assert_snapshot!("screen_after_session", r.screen);
}

#[test]
fn nan_in_a_command_is_a_message_not_a_change() {
    let mut core = FakeCore::new();
    for cmd in [
        ":set tol nan",
        ":set step inf",
        ":t NaN",
        ":set scale velocity -inf",
        ":settle 1e400",
    ] {
        let script = format!("{}<CR>", cmd.replace(' ', "<Space>"));
        let r = run_script(&mut core, &keys(&script), (80, 24));
        let last = r.screen.lines().last().unwrap_or_default();
        assert!(
            last.contains(&cmd[1..]) && last.contains("expected"),
            "{cmd}: {last}"
        );
        assert!(!r.quit);
    }
    assert!(core.log.is_empty(), "{:?}", core.log);
}

#[test]
fn unknown_key_names_point_at_the_place() {
    let err = parse_keys("l l\n  <Esc>\n:w<Space>x<Lft>", "keys.txt").expect_err("bad name");
    assert!(
        err.to_string()
            .starts_with("keys.txt:3:11: unknown key <Lft>; known names: Left,"),
        "{err}"
    );
    assert!(matches!(
        err,
        KeyScriptError::UnknownKey {
            line: 3,
            col: 11,
            ..
        }
    ));
}

#[test]
fn quitting_clean_and_dirty() {
    let r = run_script(&mut FakeCore::new(), &keys("q l"), (80, 24));
    assert!(r.quit && r.edits == 0);
    let r = run_script(&mut FakeCore::new(), &keys("l q n :q<CR>"), (80, 24));
    assert!(!r.quit);
    assert!(
        r.screen
            .ends_with("unsaved edits: :w saves, :q! discards them"),
        "{}",
        r.screen
    );
    let r = run_script(&mut FakeCore::new(), &keys("l q y l l"), (80, 24));
    assert!(r.quit && r.edits == 1);
    // Esc never quits: not with unsaved edits, not without, not twice.
    for script in [
        "<Esc>",
        "l <Esc> <Esc> y",
        "5 <Esc> <Esc>",
        ": <Esc> <Esc>",
        "? <Esc> <Esc>",
    ] {
        let r = run_script(&mut FakeCore::new(), &keys(script), (80, 24));
        assert!(!r.quit, "{script} quit");
    }
}

/// Words that must never appear as numbers on screen.
fn non_finite_words(text: &str) -> Vec<&str> {
    text.split(|c: char| !c.is_alphanumeric())
        .filter(|w| {
            ["nan", "inf", "infinity"]
                .iter()
                .any(|bad| w.eq_ignore_ascii_case(bad))
        })
        .collect()
}

fn key_strategy() -> impl Strategy<Value = Key> {
    let mapped: Vec<Key> = KEYMAP.iter().map(|b| b.key).collect();
    prop_oneof![
        4 => prop::sample::select(mapped),
        1 => any::<char>().prop_map(Key::char),
        1 => prop::sample::select(vec!['0', '1', '2', '9', ':', '<', 'e', 'x']).prop_map(Key::char),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    /// Random sessions never panic and never show NaN or inf, even when the
    /// core's view is full of them. The last row is left out of the check:
    /// it echoes what was typed (`:set tol inf` is a legitimate message).
    #[test]
    fn random_keys_never_panic_nor_show_non_finite_numbers(
        keys in prop::collection::vec(key_strategy(), 0..60),
        size in prop::sample::select(vec![(80u16, 24u16), (60, 16), (59, 16), (120, 40), (20, 5), (1, 1), (0, 0)]),
        poison in any::<bool>(),
    ) {
        let mut core = if poison { FakeCore::poisoned() } else { FakeCore::new() };
        let r = run_script(&mut core, &keys, size);
        let rows: Vec<&str> = r.screen.lines().collect();
        let checked = rows[..rows.len().saturating_sub(1)].join("\n");
        prop_assert!(non_finite_words(&checked).is_empty(), "{}", r.screen);
        prop_assert!(r.update_ms.iter().chain(&r.render_ms).all(|v| v.is_finite() && *v >= 0.0));
    }
}

/// The cell of the first braille dot on `row` of the canvas, if any.
fn trace_cell(screen: &str, row: usize) -> Option<(u16, u16)> {
    let line = screen.lines().nth(row)?;
    let col = line
        .chars()
        .take(50)
        .position(|c| ('\u{2801}'..='\u{28ff}').contains(&c))?;
    Some((col as u16, row as u16))
}

/// A mouse drag in a key script moves the selected body as the keys do:
/// one nudge to the right (no vertical part), twice as far for twice the
/// cells, in the same direction as `l`.
#[test]
fn a_scripted_mouse_drag_nudges_like_the_keys() {
    let first = run_script::<Key>(&mut FakeCore::new(), &[], (80, 24)).screen;
    let (c, r) = (1..20)
        .find_map(|row| trace_cell(&first, row))
        .expect("a trace on the canvas");
    let drag = |cells: u16| {
        let script = format!(
            "<LeftMouse:{c},{r}> <LeftDrag:{},{r}> <LeftRelease:{},{r}>",
            c + cells,
            c + cells
        );
        let steps = nudge::script::parse_script(&script, "drag.keys").expect("parses");
        let mut core = FakeCore::new();
        run_script(&mut core, &steps, (80, 24));
        let nudges: Vec<Vec3> = core
            .log
            .iter()
            .filter_map(|e| match e {
                Edit::Nudge { delta, .. } => Some(*delta),
                _ => None,
            })
            .collect();
        assert_eq!(nudges.len(), 1, "{:?}", core.log);
        nudges[0]
    };
    let (two, four) = (drag(2), drag(4));
    assert!(two.x > 0.0 && two.y == 0.0 && two.z == 0.0, "{two}");
    assert!((four - 2.0 * two).norm() < 1e-12, "{four} vs {two}");
    let mut core = FakeCore::new();
    run_script(&mut core, &keys("l"), (80, 24));
    match core.log.as_slice() {
        [Edit::Nudge { delta, .. }] => assert!(delta.x > 0.0 && delta.z == 0.0),
        other => panic!("{other:?}"),
    }
}
