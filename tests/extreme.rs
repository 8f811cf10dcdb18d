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

/// `mkfifo f; nudge check f` used to block forever in `open`; a key script
/// that is a FIFO did the same to `nudge run`. Both are refused unopened.
#[test]
fn a_fifo_is_refused_not_waited_on() {
    let dir = std::env::temp_dir().join(format!("nudge-extreme-fifo-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let fifo = dir.join("f.toml");
    let _ = std::fs::remove_file(&fifo);
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
    std::fs::remove_dir_all(&dir).unwrap();
}
