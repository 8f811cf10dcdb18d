//! Extreme but finite numbers in a scene: every one ends in a typed,
//! located error or a finite result, never a panic or a hang. The
//! reproducing scenes are in `tests/fixtures/extreme/`.

use std::path::Path;
use std::process::Command;

/// `nudge check FILE`: its exit status and its standard error.
fn check(file: &str) -> (Option<i32>, String) {
    let path = Path::new("tests/fixtures/extreme").join(file);
    let out = Command::new(env!("CARGO_BIN_EXE_nudge"))
        .arg("check")
        .arg(&path)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .expect("run nudge");
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A sphere spinning at 1e308 rad/s near the parabola used to panic (exit
/// 101, `min > max, or either was NaN` in the parabola's closest-point
/// search): `|ω|` overflows, every rotation through it is NaN, and the
/// contact query saw a pose of NaNs. Now the start is refused at t = 0.
#[test]
fn a_spin_of_1e308_near_the_parabola_is_an_error_not_a_panic() {
    let (code, err) = check("parabola-spin-1e308.toml");
    assert_eq!(code, Some(1), "{err}");
    assert_eq!(
        err.trim_end(),
        "nudge: tests/fixtures/extreme/parabola-spin-1e308.toml: body \"ball\" left the finite \
         numbers at t = 0.000000 s; check its mass, inertia and speeds for extreme values"
    );
}

/// A density of 1e-308 with drag near the parabola used to panic the same
/// way once drag had driven the state out of the finite numbers.
#[test]
fn a_density_of_1e_308_with_drag_near_the_parabola_is_an_error_not_a_panic() {
    let (code, err) = check("parabola-density-1e-308.toml");
    assert_eq!(code, Some(1), "{err}");
    assert!(
        err.starts_with(
            "nudge: tests/fixtures/extreme/parabola-density-1e-308.toml: body \"ball\" left the finite numbers at t = "
        ),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}

/// A box spinning at 1.4e5 rad/s takes tens of thousands of adaptive
/// steps per second, each holding its tangents: `check` of an egg this fast
/// used to take 5.9 GB. The run stops at the stored motion's budget
/// (256 MiB) with an error naming the body.
#[test]
fn a_motion_beyond_the_memory_budget_is_an_error_not_gigabytes() {
    let (code, err) = check("box-spinning-1.4e5.toml");
    assert_eq!(code, Some(1), "{err}");
    let (head, tail) = err
        .split_once(" by t = ")
        .unwrap_or_else(|| panic!("no time in {err}"));
    assert_eq!(
        head,
        "nudge: tests/fixtures/extreme/box-spinning-1.4e5.toml: the motion of \"box\" outgrew \
         its 256 MiB budget"
    );
    assert!(
        tail.trim_end()
            .ends_with(" s: slow its spin, free fewer controls or loosen the accuracy"),
        "{err}"
    );
}

/// The budget is kept by the run itself: a motion that fits stores at most
/// the budget, and the same scene spinning slower fits.
#[test]
fn the_stored_motion_stays_within_its_budget() {
    use nudge::controls::Controls;
    use nudge::sim::{MAX_STORED_VALUES, SimOptions, simulate};
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures/extreme/box-spinning-1.4e5.toml"),
    )
    .expect("fixture");
    for (spin, fits) in [("140000.0", false), ("140.0", true)] {
        let text = text.replace("140000.0", spin);
        let scene = nudge::scene::load_str(&text, "box.toml").expect("loads");
        let controls = Controls::new(&scene);
        match simulate(&scene, &controls, &SimOptions::default()) {
            Ok(traj) => {
                assert!(fits, "{spin} rad/s fitted");
                let stored = traj.stored_values();
                assert!(stored > 0 && stored <= MAX_STORED_VALUES, "{stored}");
            }
            Err(e) => assert!(!fits, "{spin} rad/s: {e}"),
        }
    }
}

/// `mkfifo f; nudge check f` used to block forever in `open`; a key script
/// that is a FIFO did the same to `nudge run`. Both are refused unopened.
#[test]
fn a_fifo_is_refused_not_waited_on() {
    let tmp = tempfile::Builder::new()
        .prefix("nudge-extreme-fifo-")
        .tempdir()
        .expect("temp dir");
    let dir = tmp.path().to_path_buf();
    let fifo = dir.join("f.toml");
    assert!(
        Command::new("mkfifo")
            .arg(&fifo)
            .status()
            .unwrap()
            .success()
    );
    let nudge = |args: &[&std::ffi::OsStr]| {
        Command::new(env!("CARGO_BIN_EXE_nudge"))
            .args(args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .expect("run nudge")
    };
    let out = nudge(&["check".as_ref(), fifo.as_os_str()]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("is a FIFO (named pipe), not a regular file"),
        "{err}"
    );
    let out = nudge(&[
        "run".as_ref(),
        "scenes/bounce.toml".as_ref(),
        "--keys".as_ref(),
        fifo.as_os_str(),
    ]);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("reading the key script") && err.contains("is a FIFO (named pipe)"),
        "{err}"
    );
}
