//! `:accuracy` end to end through the headless runner: the settings around
//! the current one are measured (stub clock), Enter picks one as an
//! undoable edit that re-simulates the motion and survives `:w`.

use nudge::edit::{Core, Editor, WriteMode};
use nudge::scene::{Accuracy, Method};
use nudge::script::{parse_keys, run_script};

fn run(editor: &mut Editor, keys: &str) -> String {
    let keys = parse_keys(keys, "inline").expect("keys parse");
    run_script(editor, &keys, (80, 24)).screen
}

fn bounce() -> Editor {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bounce.toml");
    Editor::open(&path).expect("scene opens")
}

#[test]
fn picking_a_setting_is_an_undoable_edit_that_is_saved() {
    let mut editor = bounce();
    let before = editor.view().accuracy;
    assert_eq!(before.method, Method::Rk4 { step: 1e-3 });
    // The popup opens on the current setting; j chooses the next (tighter).
    let screen = run(&mut editor, ":accuracy<Enter> j <Enter>");
    let tighter = Accuracy {
        method: Method::Rk4 { step: 5e-4 },
        ..before
    };
    assert_eq!(editor.view().accuracy, tighter, "{screen}");
    assert_eq!(editor.scene().accuracy, tighter);
    assert!(screen.contains("accuracy: now rk4 h=5e-4"), "{screen}");
    assert!(editor.dirty());

    run(&mut editor, "u");
    assert_eq!(editor.view().accuracy, before);
    run(&mut editor, "<C-r>");
    assert_eq!(editor.view().accuracy, tighter);

    let tmp = tempfile::Builder::new()
        .prefix("nudge-accuracy-")
        .tempdir()
        .expect("temp dir");
    let dir = tmp.path().to_path_buf();
    let path = dir.join("bounce.toml");
    editor.save(Some(&path), WriteMode::Normal).expect("saves");
    let reopened = Editor::open(&path).expect("reopens");
    assert_eq!(reopened.scene().accuracy, tighter);
}

#[test]
fn escape_in_the_popup_keeps_the_setting() {
    let mut editor = bounce();
    let before = editor.view().accuracy;
    let screen = run(&mut editor, ":accuracy<Enter> j <Esc>");
    assert_eq!(editor.view().accuracy, before, "{screen}");
    assert!(!editor.dirty());
}
