//! Smoke test of the real binary in a pseudo-terminal: it draws, takes
//! keys, asks before discarding edits, quits cleanly and restores the
//! terminal (leaves the alternate screen).

use std::io::Write;
use std::process::{Child, Command, Stdio};
use std::time::Duration;

/// Run `shell` (a `sh` command line; `$NUDGE` is the binary and `$SCENE`
/// the bounce scene) in an 80×24 pseudo-terminal allocated by util-linux
/// `script`, with every stream piped.
fn in_pty(shell: &str) -> Child {
    if Command::new("script").arg("--version").output().is_err() {
        // util-linux `script` allocates the pty; every CI machine here has it.
        panic!("the `script` command (util-linux) is needed for this test");
    }
    Command::new("script")
        .args([
            "-qfec",
            &format!("stty cols 80 rows 24; {shell}"),
            "/dev/null",
        ])
        .env("TERM", "xterm")
        .env("NUDGE", env!("CARGO_BIN_EXE_nudge"))
        .env(
            "SCENE",
            concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/bounce.toml"),
        )
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn script")
}

#[test]
fn the_editor_runs_in_a_pseudo_terminal_and_quits_cleanly() {
    let mut child = in_pty(r#""$NUDGE" "$SCENE""#);
    let mut stdin = child.stdin.take().expect("stdin");
    let pause = |ms| std::thread::sleep(Duration::from_millis(ms));
    pause(1500);
    // Nudge the ball (an unsaved edit), try to quit, then confirm.
    stdin.write_all(b"]]]]]lll").unwrap();
    pause(1500);
    stdin.write_all(b"q").unwrap();
    pause(500);
    stdin.write_all(b"y").unwrap();
    pause(500);
    drop(stdin);
    let out = child.wait_with_output().expect("wait");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "exit status {:?}, stderr {}",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.contains("\u{1b}[?1049h"),
        "entered the alternate screen"
    );
    assert!(text.contains("bounce"), "drew the scene");
    assert!(
        text.contains("quit anyway?"),
        "asked before discarding the edit"
    );
    let left = text
        .rfind("\u{1b}[?1049l")
        .expect("left the alternate screen");
    assert!(
        left > text.rfind("quit anyway?").unwrap_or(0),
        "restored after the prompt"
    );
}

/// Killed with SIGTERM (or SIGHUP, when an SSH connection drops) the
/// editor used to die in raw mode on the alternate screen, leaving the
/// terminal unusable. It now restores the terminal and exits with an error.
#[test]
fn regression_a_terminated_editor_left_the_terminal_in_raw_mode() {
    let child = in_pty(
        r#""$NUDGE" "$SCENE" & pid=$!; sleep 1.5; kill -TERM $pid; wait $pid; echo "exit=$?""#,
    );
    let out = child.wait_with_output().expect("wait");
    let text = String::from_utf8_lossy(&out.stdout);
    let entered = text
        .find("\u{1b}[?1049h")
        .expect("entered the alternate screen");
    let left = text
        .rfind("\u{1b}[?1049l")
        .expect("left the alternate screen");
    assert!(left > entered, "restored after drawing");
    assert!(text.contains("terminated by a signal"), "said why: {text}");
    assert!(!text.contains("exit=0"), "a non-zero exit status: {text}");
}
