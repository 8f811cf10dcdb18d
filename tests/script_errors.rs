//! `nudge run` and a key script with a mistake in it: a command line that
//! does not parse stops the replay at its line and column with a non-zero
//! exit, so a typo cannot silently run the rest of a session at the wrong
//! time; `--keep-going` replays the rest and still fails.

use std::path::Path;
use std::process::Command;

fn run(script: &str, extra: &[&str]) -> (std::process::Output, serde_json::Value) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let tmp = tempfile::Builder::new()
        .prefix("nudge-script-errors-")
        .tempdir()
        .expect("temp dir");
    let dir = tmp.path();
    let keys = dir.join("typo.keys");
    std::fs::write(&keys, script).expect("script written");
    let out = Command::new(env!("CARGO_BIN_EXE_nudge"))
        .current_dir(dir)
        .arg("run")
        .arg(root.join("scenes/bounce.toml"))
        .arg("--keys")
        .arg(&keys)
        .args(["--report", "report.json"])
        .args(extra)
        .output()
        .expect("runs nudge");
    let report = std::fs::read_to_string(dir.join("report.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok())
        .unwrap_or(serde_json::Value::Null);
    (out, report)
}

#[test]
fn a_misspelt_command_stops_the_replay_at_its_place() {
    let script = "# drag, then jump in time with a typo\nlll\n  :tiem 0.7<Enter> lll\n";
    let (out, report) = run(script, &[]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("typo.keys:3:") && err.contains(":tiem: unknown command"),
        "{err}"
    );
    assert!(err.contains("--keep-going"), "{err}");
    // The keys after the typo were not replayed: one nudge, not two.
    assert_eq!(report["edits"].as_u64(), Some(3), "{report}");

    let (out, report) = run(script, &["--keep-going"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("typo.keys:3:") && err.contains("did not parse"),
        "{err}"
    );
    assert!(report["edits"].as_u64() > Some(3), "{report}");
}

#[test]
fn a_command_typed_with_spaces_runs_and_a_bad_number_is_located() {
    let (out, report) = run(":t 0.7<Enter>\n:nail pos<Enter>\n", &[]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        report["constraints"].as_array().map(Vec::len),
        Some(1),
        "{report}"
    );
    let (out, _) = run("l\n:set tol nan<Enter>\n", &[]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("typo.keys:2:") && err.contains("expected a finite positive number"),
        "{err}"
    );
}
