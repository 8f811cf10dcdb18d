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

/// Killed by a signal, the editor used to die in raw mode on the
/// alternate screen with the cursor hidden for SIGINT, SIGUSR1 and SIGALRM
/// (SIGTERM, SIGHUP and SIGQUIT were caught). Every terminating signal now
/// restores the terminal first, and the process still ends as the signal
/// says (status 128 + signal number), whatever the editor was doing.
#[test]
fn regression_a_signal_left_the_terminal_in_raw_mode() {
    for (name, number) in [
        ("INT", 2),
        ("TERM", 15),
        ("HUP", 1),
        ("QUIT", 3),
        ("USR1", 10),
        ("ALRM", 14),
    ] {
        let child = in_pty(&format!(
            r#"ulimit -c 0; "$NUDGE" "$SCENE" & pid=$!; sleep 1.5; kill -{name} $pid; wait $pid; echo "exit=$?"; stty -a"#
        ));
        let out = child.wait_with_output().expect("wait");
        let text = String::from_utf8_lossy(&out.stdout);
        let entered = text
            .find("\u{1b}[?1049h")
            .unwrap_or_else(|| panic!("SIG{name}: entered the alternate screen"));
        let left = text
            .rfind("\u{1b}[?1049l")
            .unwrap_or_else(|| panic!("SIG{name}: left the alternate screen: {text}"));
        assert!(left > entered, "SIG{name}: restored after drawing");
        let shown = text.rfind("\u{1b}[?25h").unwrap_or(0);
        assert!(shown > entered, "SIG{name}: the cursor is shown again");
        assert!(
            text.contains(&format!("exit={}", 128 + number)),
            "SIG{name}: ended by the signal: {text}"
        );
        let modes = &text[text.rfind("exit=").unwrap_or(0)..];
        for mode in [" echo ", " icanon ", " isig ", " opost "] {
            let off = format!(" -{}", mode.trim_start());
            assert!(
                !modes.contains(&off),
                "SIG{name}: terminal mode{mode}restored: {modes}"
            );
        }
    }
}

/// A pseudo-terminal whose master this test holds: the editor gets the
/// slave as its standard streams (not as its controlling terminal, so no
/// SIGHUP is sent when the master closes: only the hang-up tells).
fn editor_on_own_pty() -> (std::os::fd::OwnedFd, Child) {
    use rustix::pty::{OpenptFlags, grantpt, openpt, ptsname, unlockpt};
    let master =
        openpt(OpenptFlags::RDWR | OpenptFlags::NOCTTY | OpenptFlags::CLOEXEC).expect("openpt");
    grantpt(&master).expect("grantpt");
    unlockpt(&master).expect("unlockpt");
    let name = ptsname(&master, Vec::new()).expect("ptsname");
    let name = std::path::PathBuf::from(name.to_string_lossy().into_owned());
    rustix::termios::tcsetwinsize(
        &master,
        rustix::termios::Winsize {
            ws_row: 24,
            ws_col: 80,
            ws_xpixel: 0,
            ws_ypixel: 0,
        },
    )
    .expect("window size");
    let open = || {
        std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .open(&name)
            .expect("open the pty slave")
    };
    let child = Command::new(env!("CARGO_BIN_EXE_nudge"))
        .arg(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/bounce.toml"))
        .env("TERM", "xterm")
        .stdin(open())
        .stdout(open())
        .stderr(open())
        .spawn()
        .expect("spawn nudge");
    (master, child)
}

/// Read and discard what the editor draws on `master` for `running` (so it
/// never blocks on a full pty buffer), then close the master: the
/// terminal goes away under the editor. Returns once it is closed.
fn close_after(master: std::os::fd::OwnedFd, running: Duration) {
    use rustix::event::{PollFd, PollFlags, Timespec, poll};
    let start = std::time::Instant::now();
    let mut sink = [0u8; 4096];
    while start.elapsed() < running {
        let mut fds = [PollFd::new(&master, PollFlags::IN)];
        let wait = Timespec {
            tv_sec: 0,
            tv_nsec: 50_000_000,
        };
        if matches!(poll(&mut fds, Some(&wait)), Ok(n) if n > 0)
            && rustix::io::read(&master, &mut sink).is_err()
        {
            break;
        }
    }
    drop(master);
}

/// Whether `child` exits within `limit`; how long it took.
fn exits_within(child: &mut Child, limit: Duration) -> Option<Duration> {
    let start = std::time::Instant::now();
    while start.elapsed() < limit {
        if child.try_wait().expect("try_wait").is_some() {
            return Some(start.elapsed());
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let _ = child.kill();
    let _ = child.wait();
    None
}

/// Closing the editor's terminal under it (a dropped SSH connection, a
/// killed tmux server) used to leave nudge spinning at 70-90 % CPU for
/// hours on the dead pty, deaf to SIGTERM: crossterm's reader retries the
/// failing reads forever. It now notices the hang-up and exits.
#[test]
fn regression_the_editor_spun_forever_when_its_terminal_went_away() {
    let (master, mut child) = editor_on_own_pty();
    close_after(master, Duration::from_millis(1500));
    assert!(
        child.try_wait().unwrap().is_none(),
        "the editor was running"
    );
    let took = exits_within(&mut child, Duration::from_secs(10));
    assert!(
        took.is_some(),
        "the editor did not exit after its terminal closed"
    );
}

/// The same, with SIGTERM sent after the terminal closed: it is honoured.
#[test]
fn sigterm_is_honoured_after_the_terminal_went_away() {
    let (master, mut child) = editor_on_own_pty();
    close_after(master, Duration::from_millis(1500));
    let pid = rustix::process::Pid::from_child(&child);
    let _ = rustix::process::kill_process(pid, rustix::process::Signal::TERM);
    assert!(
        exits_within(&mut child, Duration::from_secs(10)).is_some(),
        "the editor ignored SIGTERM with its terminal gone"
    );
}

/// With mouse capture on (the default), the terminal reports clicks and
/// drags to the editor: a click on the ball's trace and a drag nudge it (an
/// unsaved edit, so quitting asks). On quitting, capture is switched off
/// with the rest of the terminal state.
#[test]
fn mouse_clicks_and_drags_reach_the_editor_and_capture_ends_on_quit() {
    let mut child = in_pty(r#""$NUDGE" "$SCENE""#);
    let mut stdin = child.stdin.take().expect("stdin");
    let pause = |ms| std::thread::sleep(Duration::from_millis(ms));
    pause(1500);
    // SGR mouse reports (1-based cells): press on the ball's rising trace
    // in the default 80x24 front view, drag up and right, release.
    stdin.write_all(b"\x1b[<0;27;11M").unwrap();
    pause(300);
    stdin.write_all(b"\x1b[<32;31;9M").unwrap();
    pause(300);
    stdin.write_all(b"\x1b[<0;31;9m").unwrap();
    pause(1500);
    stdin.write_all(b"q").unwrap();
    pause(500);
    stdin.write_all(b"y").unwrap();
    pause(500);
    drop(stdin);
    let out = child.wait_with_output().expect("wait");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "exit status {:?}", out.status);
    let on = text
        .find("\u{1b}[?1000h")
        .expect("mouse capture switched on");
    let asked = text
        .find("quit anyway?")
        .expect("the drag made an edit, so quitting asked");
    assert!(asked > on);
    let off = text
        .rfind("\u{1b}[?1000l")
        .expect("mouse capture switched off");
    assert!(off > asked, "capture ended after the session");
    assert!(text.rfind("\u{1b}[?1049l").is_some_and(|l| l > asked));
}
