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
fn float_picks_the_side_from_the_current_time() {
    let (_, core) = session("f");
    assert_eq!(
        only_edit(&core),
        &Edit::Float {
            quantities: StateQuantity::ALL.to_vec(),
            exact: vec![],
            side: Side::Pre
        }
    );
    let (_, core) = session(":float<Space>post<Space>pos<CR>");
    assert_eq!(
        only_edit(&core),
        &Edit::Float {
            quantities: vec![StateQuantity::Position],
            exact: vec![],
            side: Side::Post
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
