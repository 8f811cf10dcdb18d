//! Saving keeps the file what it was, seen from the scene's side: a scene
//! written with a byte-order mark and CRLF line endings saves back byte for
//! byte, keeps both through edits, and a read-only scene is refused until
//! forced. (The file-level cases, links, permissions and special files,
//! are `nudge::files`'s unit tests.)
use nudge::files::WriteMode;
use nudge::scene::{SceneError, load, load_str, save};
use std::path::PathBuf;

/// A fresh directory for one test, deleted when dropped.
fn dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("nudge-saving-{name}-"))
        .tempdir()
        .expect("temp dir")
}

/// The shipped scenes, sorted.
fn shipped() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir("scenes")
        .expect("scenes/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    files.sort();
    files
}

/// Every shipped scene, rewritten with a byte-order mark, with CRLF line
/// endings and with both, saves back unedited as the same bytes.
#[test]
fn a_bom_and_crlf_scene_saves_back_byte_for_byte() {
    let tmp = dir("roundtrip");
    let d = tmp.path().to_path_buf();
    // Mesh shapes are found from the scene file's folder.
    std::fs::create_dir_all(d.join("meshes")).expect("a folder");
    for mesh in std::fs::read_dir("scenes/meshes").expect("scenes/meshes") {
        let mesh = mesh.expect("entry").path();
        std::fs::copy(
            &mesh,
            d.join("meshes").join(mesh.file_name().expect("name")),
        )
        .expect("copy");
    }
    for path in shipped() {
        let plain = std::fs::read_to_string(&path).expect("readable");
        let crlf = plain.replace('\n', "\r\n");
        for (how, text) in [
            ("bom", format!("\u{feff}{plain}")),
            ("crlf", crlf.clone()),
            ("bom+crlf", format!("\u{feff}{crlf}")),
        ] {
            let file = d.join(path.file_name().expect("name"));
            std::fs::write(&file, &text).expect("write");
            let scene = load(&file).unwrap_or_else(|e| panic!("{how} {}: {e}", path.display()));
            let unkept = save(&scene, &file, WriteMode::Normal)
                .unwrap_or_else(|e| panic!("{how} {}: {e}", path.display()));
            assert_eq!(unkept, None, "{how} {}: layout kept", path.display());
            let back = std::fs::read(&file).expect("read back");
            assert!(
                back == text.as_bytes(),
                "{how} {}: saved differently:\n{}",
                path.display(),
                String::from_utf8_lossy(&back).escape_debug()
            );
            let again = load(&file).expect("loads back");
            assert_eq!(again.notes, scene.notes, "{how} {}", path.display());
        }
    }
}

/// Multi-line notes in a CRLF file keep their CRs in the TOML string: they
/// load as the same notes as the LF file's, and save back byte for byte
/// (a lone CR, written `\r`, which would overwrite a line on the terminal,
/// is refused).
#[test]
fn multi_line_notes_in_a_crlf_file_load_and_save_back() {
    let tmp = dir("notes");
    let d = tmp.path().to_path_buf();
    let plain = std::fs::read_to_string("scenes/bounce.toml").expect("shipped scene");
    let (head, tail) = plain.split_once("\nnotes = ").expect("bounce has notes");
    let (_, rest) = tail.split_once('\n').expect("notes is one line");
    let lf = format!(
        "{head}\nnotes = \"\"\"\nA ball dropped on a floor.\n\nDrag a bounce apex.\"\"\"\n{rest}"
    );
    let crlf = lf.replace('\n', "\r\n");
    let a = load_str(&lf, "lf.toml").unwrap_or_else(|e| panic!("{e}"));
    let b = load_str(&crlf, "crlf.toml").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(a.notes, "A ball dropped on a floor.\n\nDrag a bounce apex.");
    assert_eq!(b.notes, a.notes);
    let file = d.join("bounce.toml");
    std::fs::write(&file, &crlf).expect("write");
    let scene = load(&file).expect("loads");
    save(&scene, &file, WriteMode::Normal).expect("saved");
    assert!(std::fs::read(&file).expect("read back") == crlf.as_bytes());
    // Written as new text (no source to keep), the notes still load back.
    let fresh = nudge::scene::to_toml(&scene);
    assert_eq!(load_str(&fresh, "new.toml").expect("loads").notes, a.notes);
    let lone = lf.replace("floor.\n\nDrag", "floor.\\rDrag");
    match load_str(&lone, "cr.toml") {
        Err(SceneError::Invalid(m)) => assert!(
            m.contains("notes contains the invisible or control character U+000D"),
            "{m}"
        ),
        Ok(_) => panic!("a lone CR in notes loaded"),
    }
}

/// Saving keeps the file what it was: a scene written with a byte-order
/// mark and CRLF line endings keeps both through an edit and `:w`, and a
/// read-only scene is refused (the message names `:w!`) until forced.
#[test]
fn saving_keeps_the_files_line_endings_bom_and_read_only_flag() {
    use nudge::edit::{Core, Edit, EditError, Editor};
    use std::os::unix::fs::PermissionsExt;
    let tmp = tempfile::Builder::new()
        .prefix("nudge-save-kinds-")
        .tempdir()
        .expect("temp dir");
    let dir = tmp.path();
    let plain = std::fs::read_to_string("scenes/bounce.toml").expect("shipped scene");
    let crlf = format!("\u{feff}{}", plain.replace('\n', "\r\n"));
    let file = dir.join("bounce.toml");
    std::fs::write(&file, &crlf).expect("write");
    let scene = load(&file).expect("a BOM and CRLF load");
    let mut e = Editor::new(scene, Some(file.clone())).expect("editor");
    e.apply(Edit::SelectTime(0.5)).expect("time");
    e.apply(Edit::Nail {
        quantities: vec![nudge::scene::StateQuantity::Position],
        exact: vec![],
    })
    .expect("nail");
    e.save(None, WriteMode::Normal).expect("saved");
    let saved = std::fs::read(&file).expect("read back");
    let text = String::from_utf8(saved).expect("UTF-8");
    assert!(text.starts_with('\u{feff}'), "the BOM is kept");
    assert!(
        !text.replace("\r\n", "").contains('\n'),
        "every line ends in CRLF"
    );
    assert!(text.contains("[[constraint]]\r\nkind = \"nail\""), "{text}");
    let back = load(&file).expect("loads back");
    assert_eq!(back.constraints.len(), 1);

    std::fs::set_permissions(&file, std::fs::Permissions::from_mode(0o444)).expect("chmod");
    e.apply(Edit::RemoveConstraint(0)).expect("delete");
    let refused = e.save(None, WriteMode::Normal);
    assert_eq!(refused, Err(EditError::ReadOnly(file.clone())));
    assert_eq!(
        refused.err().map(|e| e.to_string()),
        Some(format!(
            "{} is read-only: :w! writes it anyway",
            file.display()
        ))
    );
    assert_eq!(load(&file).expect("unchanged").constraints.len(), 1);
    e.save(None, WriteMode::Force).expect("forced");
    assert_eq!(load(&file).expect("written").constraints.len(), 0);
    let mode = std::fs::metadata(&file).expect("stat").permissions().mode() & 0o777;
    assert_eq!(mode, 0o444, "still read-only");
    assert!(!e.dirty());
}

/// `:w` to a directory, FIFO or device is refused with a message that
/// names what the path is and offers a file name; nothing is replaced.
#[test]
fn saving_over_a_directory_fifo_or_device_is_refused() {
    use nudge::edit::{Core, EditError, Editor};
    let tmp = dir("special");
    let d = tmp.path().to_path_buf();
    let fifo = d.join("pipe.toml");
    let made = std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .expect("mkfifo (coreutils) is needed for this test");
    assert!(made.success());
    let scene = load(std::path::Path::new("scenes/bounce.toml")).expect("shipped scene");
    let mut e = Editor::new(scene, None).expect("editor");
    for (path, kind) in [
        (fifo.clone(), "a FIFO (named pipe)"),
        (d.clone(), "a directory"),
        (PathBuf::from("/dev/null"), "a device"),
    ] {
        let got = e.save(Some(&path), WriteMode::Force);
        assert_eq!(
            got,
            Err(EditError::NotRegular {
                path: path.clone(),
                kind,
                suggest: "bounce.toml".into()
            })
        );
        assert_eq!(
            got.err().map(|e| e.to_string()),
            Some(format!(
                "could not save: {} is {kind}, not a file: give a file, e.g. :w bounce.toml",
                path.display()
            ))
        );
    }
    use std::os::unix::fs::FileTypeExt;
    assert!(
        std::fs::metadata(&fifo)
            .expect("stat")
            .file_type()
            .is_fifo()
    );
    assert!(
        std::fs::metadata("/dev/null")
            .expect("stat")
            .file_type()
            .is_char_device()
    );
}

/// Through the runner: `:w` (or `:wq`) on a read-only scene says so and
/// leaves it; `:w!` (or `:wq!`) writes it, and it stays read-only.
#[test]
fn the_editor_refuses_a_read_only_scene_until_w_bang() {
    use std::os::unix::fs::PermissionsExt;
    let tmp = dir("bang");
    let d = tmp.path().to_path_buf();
    let file = d.join("bounce.toml");
    let original = std::fs::read_to_string("scenes/bounce.toml").expect("shipped scene");
    std::fs::write(&file, &original).expect("write");
    std::fs::set_permissions(&file, std::fs::Permissions::from_mode(0o444)).expect("chmod");
    let run = |keys: &str| {
        let script = d.join("keys.txt");
        std::fs::write(&script, keys).expect("keys");
        let screen = d.join("screen.txt");
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_nudge"))
            .args(["run", "--size", "120x30"])
            .arg(&file)
            .arg("--keys")
            .arg(&script)
            .arg("--screen")
            .arg(&screen)
            .output()
            .expect("runs nudge");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        std::fs::read_to_string(&screen).expect("screen")
    };
    let screen = run("V l :w<CR>\n");
    assert!(
        screen.contains(&format!(
            "{} is read-only: :w! writes it anyway",
            file.display()
        )),
        "{screen}"
    );
    assert_eq!(std::fs::read_to_string(&file).expect("read"), original);
    let screen = run("V l :w!<CR>\n");
    assert!(
        screen.contains(&format!("wrote {}", file.display())),
        "{screen}"
    );
    assert_ne!(std::fs::read_to_string(&file).expect("read"), original);
    let mode = std::fs::metadata(&file).expect("stat").permissions().mode() & 0o777;
    assert_eq!(mode, 0o444, "still read-only");
    // The same for :wq and :wq!.
    std::fs::set_permissions(&file, std::fs::Permissions::from_mode(0o644)).expect("chmod");
    std::fs::write(&file, &original).expect("write");
    std::fs::set_permissions(&file, std::fs::Permissions::from_mode(0o444)).expect("chmod");
    let screen = run("V l :wq<CR>\n");
    assert!(
        screen.contains("is read-only: :w! writes it anyway"),
        "{screen}"
    );
    assert_eq!(std::fs::read_to_string(&file).expect("read"), original);
    run("V l :wq!<CR>\n");
    assert_ne!(std::fs::read_to_string(&file).expect("read"), original);
}

/// A save that fails for want of space (here a file size limit of 512
/// bytes, below the scene's size) leaves a file with one name as it was:
/// the text goes to a temporary file first. A hard-linked file is
/// rewritten in place, so it may be left incomplete, and the message says
/// so.
#[test]
fn a_failed_save_leaves_the_file_or_says_it_may_be_incomplete() {
    let tmp = dir("full");
    let d = tmp.path().to_path_buf();
    let original = std::fs::read_to_string("scenes/bounce.toml").expect("shipped scene");
    assert!(original.len() > 512);
    std::fs::write(d.join("keys.txt"), "V l :w<CR>\n").expect("keys");
    // The size limit applies to files, not to the pipe the screen goes
    // to; SIGXFSZ is ignored so that the write fails with EFBIG instead.
    let run = |name: &str| {
        let out = std::process::Command::new("sh")
            .current_dir(&d)
            .arg("-c")
            .arg(r#"trap "" XFSZ; ulimit -f 1; exec "$0" run --size 400x30 "$1" --keys keys.txt --screen /dev/stdout"#)
            .arg(env!("CARGO_BIN_EXE_nudge"))
            .arg(name)
            .output()
            .expect("runs nudge under sh");
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).expect("UTF-8 screen")
    };
    std::fs::write(d.join("one.toml"), &original).expect("write");
    let screen = run("one.toml");
    assert!(
        screen.contains("could not save: one.toml: File too large (os error 27)"),
        "{screen}"
    );
    assert_eq!(
        std::fs::read_to_string(d.join("one.toml")).expect("read"),
        original
    );
    let leftovers: Vec<_> = std::fs::read_dir(&d)
        .expect("dir")
        .map(|e| e.expect("entry").file_name())
        .filter(|n| n.to_string_lossy().ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");

    std::fs::write(d.join("two.toml"), &original).expect("write");
    std::fs::hard_link(d.join("two.toml"), d.join("other.toml")).expect("link");
    let screen = run("two.toml");
    assert!(
        screen.contains(
            "could not save: two.toml: File too large (os error 27), part way through rewriting it in place (it has other hard links): it may be incomplete; save again once that is fixed"
        ),
        "{screen}"
    );
}

/// `:w other.toml` writes the scene with its file's byte-order mark and
/// line endings, edited or not (over an existing file, that file's own).
#[test]
fn saving_elsewhere_keeps_the_scene_files_bom_and_line_endings() {
    use nudge::edit::{Core, Edit, Editor};
    let tmp = dir("saveas");
    let d = tmp.path().to_path_buf();
    let plain = std::fs::read_to_string("scenes/bounce.toml").expect("shipped scene");
    let styled = format!("\u{feff}{}", plain.replace('\n', "\r\n"));
    let file = d.join("bounce.toml");
    std::fs::write(&file, &styled).expect("write");
    let mut e = Editor::new(load(&file).expect("loads"), Some(file.clone())).expect("editor");
    let unedited = d.join("unedited.toml");
    e.save(Some(&unedited), WriteMode::Normal).expect("saved");
    assert!(std::fs::read(&unedited).expect("read") == styled.as_bytes());
    e.apply(Edit::SelectTime(0.5)).expect("time");
    e.apply(Edit::Nail {
        quantities: vec![nudge::scene::StateQuantity::Position],
        exact: vec![],
    })
    .expect("nail");
    let edited = d.join("edited.toml");
    e.save(Some(&edited), WriteMode::Normal).expect("saved");
    let text = std::fs::read_to_string(&edited).expect("read");
    assert!(text.starts_with('\u{feff}'), "the BOM is kept");
    assert!(!text.replace("\r\n", "").contains('\n'), "CRLF throughout");
    assert!(text.contains("[[constraint]]\r\nkind = \"nail\""), "{text}");
    let lf = d.join("lf.toml");
    std::fs::write(&lf, "# an LF file\n").expect("write");
    e.save(Some(&lf), WriteMode::Normal).expect("saved");
    let text = std::fs::read_to_string(&lf).expect("read");
    assert!(
        !text.starts_with('\u{feff}') && !text.contains('\r'),
        "its own style"
    );
    assert_eq!(load(&lf).expect("loads").constraints.len(), 1);
}
