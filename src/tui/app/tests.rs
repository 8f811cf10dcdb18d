//! Tests of the App: keys and mouse to edits, popups, messages.

use super::*;
use crate::script::parse_keys;
use crate::tui::fixtures::{self, FakeCore};

fn session(script: &str) -> (App, FakeCore) {
    let mut core = fixtures::core();
    let mut app = fixtures::app(&core.view(), 80, 24);
    // A script may end inside a command line (to look at the typed text):
    // parse it closed by <Esc> and leave the <Esc> out.
    let keys = match parse_keys(script, "test") {
        Ok(keys) => keys,
        Err(_) => {
            let mut keys = parse_keys(&format!("{script}<Esc>"), "test").expect("keys parse");
            keys.pop();
            keys
        }
    };
    for key in keys {
        app.handle_key(&mut core, key);
        app.flush(&mut core);
    }
    (app, core)
}

fn only_edit(core: &FakeCore) -> &Edit {
    match core.log.as_slice() {
        [e] => e,
        other => panic!("expected one edit, got {other:?}"),
    }
}

fn nudge_delta(core: &FakeCore) -> Vec3 {
    match only_edit(core) {
        Edit::Nudge { delta, .. } => *delta,
        other => panic!("{other:?}"),
    }
}

#[test]
fn counts_start_with_5_to_9_and_continue_with_any_digit() {
    let (app, core) = session("50l");
    assert!((nudge_delta(&core) - Vec3::x() * 50.0 * app.step()).norm() < 1e-12);
    let (app, core) = session("1");
    assert!(core.log.is_empty() && app.count.is_none());
    assert_eq!(app.camera.kind, ViewKind::Front);
}

#[test]
fn escape_abandons_a_count_without_quitting() {
    let (app, core) = session("7<Esc>l");
    assert!(!app.quit);
    assert!((nudge_delta(&core) - Vec3::x() * app.step()).norm() < 1e-12);
}

#[test]
fn big_nudges_follow_the_camera() {
    let (app, core) = session("2K");
    assert_eq!(app.camera.kind, ViewKind::Side);
    assert!((nudge_delta(&core) - Vec3::z() * 10.0 * app.step()).norm() < 1e-12);
    let (app, core) = session("3<S-Left>");
    assert!((nudge_delta(&core) + Vec3::x() * 10.0 * app.step()).norm() < 1e-12);
}

#[test]
fn orientation_nudges_turn_about_the_line_of_sight() {
    // Front view: the line of sight is +y, so `l` (clockwise as seen)
    // is a positive turn about +y.
    let (app, core) = session("Ol");
    let d = nudge_delta(&core);
    assert!((d - Vec3::y() * app.step()).norm() < 1e-12, "{d:?}");
    assert!(matches!(
        only_edit(&core),
        Edit::Nudge {
            quantity: StateQuantity::Orientation,
            ..
        }
    ));
}

#[test]
fn time_events_and_bodies() {
    let (_, core) = session("]");
    assert_eq!(only_edit(&core), &Edit::SelectTime(0.8 + 0.02));
    let (_, core) = session("}");
    assert_eq!(only_edit(&core), &Edit::SelectEvent(0));
    let (app, core) = session("{");
    assert!(core.log.is_empty());
    assert_eq!(
        app.message.map(|m| m.text),
        Some("no earlier collision event".to_string())
    );
    let (_, core) = session("<S-Tab>");
    assert_eq!(only_edit(&core), &Edit::SelectBody(1));
}

#[test]
fn block_prefix_toggles_from_what_the_view_shows() {
    // ball.velocity.* rows are free in the fixture: `b v` fixes them.
    let (app, core) = session("bv");
    assert_eq!(
        only_edit(&core),
        &Edit::SetBlock {
            body: 0,
            block: Block::Velocity,
            free: false
        }
    );
    assert_eq!(app.input, Input::Normal);
    let (_, core) = session("bm");
    assert_eq!(
        only_edit(&core),
        &Edit::SetBlock {
            body: 0,
            block: Block::Mass,
            free: true
        }
    );
    let (app, core) = session("bq");
    assert!(core.log.is_empty() && app.input == Input::Normal && app.message.is_some());
}

#[test]
fn float_leaves_the_side_to_the_core_unless_typed() {
    let (_, core) = session("f");
    assert_eq!(
        only_edit(&core),
        &Edit::Float {
            quantities: StateQuantity::ALL.to_vec(),
            exact: vec![],
            side: None
        }
    );
    let (_, core) = session(":float<Space>post<Space>pos<CR>");
    assert_eq!(
        only_edit(&core),
        &Edit::Float {
            quantities: vec![StateQuantity::Position],
            exact: vec![],
            side: Some(Side::Post)
        }
    );
}

#[test]
fn accuracy_commands_keep_the_other_settings() {
    let (_, core) = session(":set<Space>tol<Space>1e-9<CR>");
    let expected = Accuracy {
        method: Method::Adaptive {
            tol: 1e-9,
            max_step: 1e-2,
        },
        root_tol: 1e-12,
    };
    assert_eq!(only_edit(&core), &Edit::SetAccuracy(expected));
    let (_, core) = session(":set<Space>method<Space>rk4<CR>");
    let expected = Accuracy {
        method: Method::Rk4 { step: 1e-3 },
        root_tol: 1e-12,
    };
    assert_eq!(only_edit(&core), &Edit::SetAccuracy(expected));
}

#[test]
fn delete_needs_a_constraint_and_keeps_the_selection_in_range() {
    let (app, core) = session("cx");
    assert_eq!(only_edit(&core), &Edit::RemoveConstraint(0));
    assert_eq!(app.selected_constraint, 0);
    let (app, core) = session("xx");
    assert_eq!(core.log.len(), 1);
    assert_eq!(
        app.message.map(|m| m.text),
        Some("no constraint to delete".to_string())
    );
}

#[test]
fn quitting_with_unsaved_edits_asks_and_can_save() {
    let (app, core) = session("l q");
    assert_eq!(app.input, Input::Prompt);
    assert!(!app.quit && core.saved.is_empty());
    let (app, core) = session("l q w");
    assert!(app.quit);
    assert_eq!(core.saved, vec![None]);
    let (app, core) = session(":w<Space>out.toml<CR>");
    assert!(!app.quit);
    assert_eq!(core.saved, vec![Some(std::path::PathBuf::from("out.toml"))]);
}

#[test]
fn command_line_editing() {
    let (app, _) = session(":se<BS><BS><BS>");
    assert_eq!(app.input, Input::Normal);
    let (app, _) = session(":set<C-u>ab");
    assert_eq!(app.input, Input::Command("ab".into()));
    let (app, core) = session(":body<Space>box<CR>");
    assert_eq!(only_edit(&core), &Edit::SelectBody(1));
    assert!(app.message.is_none());
    let (app, core) = session(":free<Space>crate<Space>mass<CR>");
    assert!(core.log.is_empty());
    assert_eq!(
        app.message.map(|m| m.text),
        Some("no body crate; bodies: ball, box".to_string())
    );
}

#[test]
fn step_ladder() {
    assert_eq!(ladder(0.046), 0.02);
    assert_eq!(ladder(0.1), 0.1);
    assert_eq!(ladder(f64::NAN), 1.0);
    let mut v = 1.0;
    let mut seen = Vec::new();
    for _ in 0..3 {
        v = ladder_up(v);
        seen.push(v);
    }
    assert_eq!(seen, [2.0, 5.0, 10.0]);
    assert!((ladder_down(0.1) - 0.05).abs() < 1e-15);
    assert!(ladder_up(1e9) <= 1e9 && ladder_down(1e-9) >= 1e-9);
}

#[test]
fn zoom_and_pan_stop_following_the_scene_until_reset() {
    let (app, _) = session("z");
    assert!(!app.auto_fit);
    let (app, _) = session("<C-Left>0");
    assert!(app.auto_fit);
    let (app, _) = session("4<lt>^");
    assert!(matches!(app.camera.kind, ViewKind::Orbit { .. }));
}

/// The cell where world point `p` is drawn, and the world size of a cell.
fn cell_of(app: &App, p: &Vec3) -> ((u16, u16), (f64, f64)) {
    let canvas = layout::canvas_inner(app.area);
    let (xb, yb) = app.camera.bounds(canvas.width, canvas.height);
    let (u, v) = app.camera.project(p).expect("finite");
    let cw = (xb[1] - xb[0]) / f64::from(canvas.width);
    let ch = (yb[1] - yb[0]) / f64::from(canvas.height);
    let col = canvas.x + ((u - xb[0]) / cw) as u16;
    let row = canvas.y + ((yb[1] - v) / ch) as u16;
    ((col, row), (cw, ch))
}

fn mouse(kind: MouseKind, (col, row): (u16, u16)) -> Mouse {
    Mouse { kind, col, row }
}

#[test]
fn a_click_on_a_trace_selects_that_body_at_that_time() {
    let mut core = fixtures::core();
    let mut app = fixtures::app(&core.view(), 80, 24);
    let path = core.view().paths[1].clone();
    let k = path.points.len() / 2;
    let (cell, _) = cell_of(&app, &path.points[k]);
    app.handle_mouse(&mut core, mouse(MouseKind::Press, cell));
    assert_eq!(core.view.selected, 1, "{:?}", core.log);
    let t = core.view.time;
    // The nearest sample to the cell's centre: within a cell of the point.
    let near = path
        .times
        .iter()
        .zip(&path.points)
        .filter(|(_, p)| cell_of(&app, p).0 == cell)
        .any(|(tp, _)| *tp == t);
    assert!(near, "picked t={t}, expected a time drawn in {cell:?}");
    // A click far from every trace says so and selects nothing.
    let mut core = fixtures::core();
    app.handle_mouse(&mut core, mouse(MouseKind::Press, (1, 1)));
    assert!(core.log.is_empty());
    assert!(
        app.message
            .as_ref()
            .is_some_and(|m| m.text.contains("no trace here"))
    );
}

#[test]
fn a_drag_nudges_like_the_keys_and_follows_the_pointer() {
    let mut core = fixtures::core();
    let mut app = fixtures::app(&core.view(), 80, 24);
    let p = core.view().paths[0].points[3];
    let (cell, (cw, ch)) = cell_of(&app, &p);
    app.handle_mouse(&mut core, mouse(MouseKind::Press, cell));
    app.handle_mouse(&mut core, mouse(MouseKind::Drag, (cell.0 + 2, cell.1)));
    app.handle_mouse(&mut core, mouse(MouseKind::Drag, (cell.0 + 4, cell.1 - 1)));
    app.handle_mouse(
        &mut core,
        mouse(MouseKind::Release, (cell.0 + 4, cell.1 - 1)),
    );
    let nudges: Vec<Vec3> = core
        .log
        .iter()
        .filter_map(|e| match e {
            Edit::Nudge { delta, .. } => Some(*delta),
            _ => None,
        })
        .collect();
    // One accumulated edit, four cells right and one up.
    assert_eq!(nudges.len(), 1, "{:?}", core.log);
    let want = Vec3::new(4.0 * cw, 0.0, ch);
    assert!((nudges[0] - want).norm() < 1e-12, "{} vs {want}", nudges[0]);
    // The same move from the keys: `:set nudge` to one cell, then 5l.
    let (_, keys) = session(&format!(":set nudge {cw}<CR> 5l"));
    match keys.log.as_slice() {
        [Edit::Nudge { delta, .. }] => {
            assert!(
                (delta - Vec3::new(5.0 * cw, 0.0, 0.0)).norm() < 1e-12,
                "{delta}"
            )
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_wheel_zooms_and_mouse_off_ignores_the_mouse() {
    let mut core = fixtures::core();
    let mut app = fixtures::app(&core.view(), 80, 24);
    let h = app.camera.half_height;
    app.handle_mouse(&mut core, mouse(MouseKind::ScrollUp, (10, 10)));
    assert!(app.camera.half_height < h);
    app.run_command(&mut core, "set mouse off");
    assert!(!app.mouse);
    let before = app.clone();
    app.handle_mouse(&mut core, mouse(MouseKind::Press, (10, 10)));
    app.handle_mouse(&mut core, mouse(MouseKind::Drag, (14, 10)));
    assert_eq!(app, before);
    assert!(core.log.is_empty());
}

#[test]
fn messages_are_kept_and_shown_in_full() {
    let (mut app, mut core) = session("<F12> :fly<CR> ]");
    let log: Vec<&str> = app.log().iter().map(|m| m.text.as_str()).collect();
    assert!(
        log.iter().any(|m| m.contains("<F12> does nothing")),
        "{log:?}"
    );
    assert!(
        log.iter().any(|m| m.contains(":fly: unknown command")),
        "{log:?}"
    );
    app.run_command(&mut core, "messages");
    assert_eq!(
        app.input,
        Input::Popup {
            kind: PopupKind::Messages,
            scroll: 0
        }
    );
}
