//! The terminal session's guards: whatever ends the editor, the terminal
//! is left as it was found, and an editor whose terminal is gone exits.
//!
//! - **Signals.** A thread waits for every signal whose default action
//!   terminates the process (INT, TERM, HUP, QUIT, USR1, USR2, ALRM,
//!   VTALRM, PROF). It restores the terminal (raw mode off, main screen,
//!   cursor shown, mouse capture off) and then ends the process as the
//!   signal's default action would (status 128 + signal number). It does
//!   not wait for the event loop, so a signal is honoured during a long
//!   solve too.
//! - **A terminal that went away.** When the terminal closes under the
//!   editor (a dropped SSH connection, a killed tmux server), reads from it
//!   fail at once forever and crossterm's reader retries them in a loop.
//!   A watchdog thread polls standard input for a hang-up and exits the
//!   process (status 129, as SIGHUP would) with nothing to restore; what
//!   the user saved is on disk already.

use rustix::event::{PollFd, PollFlags, poll};
use signal_hook::consts::signal::{
    SIGALRM, SIGHUP, SIGINT, SIGPROF, SIGQUIT, SIGTERM, SIGUSR1, SIGUSR2, SIGVTALRM,
};
use signal_hook::iterator::Signals;
use std::io;
use std::time::Duration;

/// The signals whose default action terminates the process and which the
/// session catches to restore the terminal first (STOP, TSTP, CONT, WINCH
/// and CHLD do not terminate; KILL cannot be caught).
pub const TERMINATING: [i32; 9] = [
    SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1, SIGUSR2, SIGALRM, SIGVTALRM, SIGPROF,
];

/// How often the watchdog looks for a hang-up of the terminal.
const WATCH: Duration = Duration::from_millis(100);

/// Put the terminal back: raw mode off, the main screen, the cursor shown,
/// mouse reporting off. Errors are ignored: the terminal may be gone.
pub fn restore_terminal() {
    use ratatui::crossterm::{cursor::Show, event::DisableMouseCapture, execute};
    ratatui::restore();
    let _ = execute!(io::stdout(), DisableMouseCapture, Show);
}

/// Start the guards for an editor running in the terminal. They live for
/// the rest of the process (the editor exits when its session ends).
///
/// # Errors
/// When the signal handlers cannot be installed or a thread cannot start.
pub fn guard() -> io::Result<()> {
    let mut signals = Signals::new(TERMINATING)?;
    std::thread::Builder::new()
        .name("nudge-signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                restore_terminal();
                let _ = signal_hook::low_level::emulate_default_handler(signal);
                // Every signal listed terminates by default; should the
                // emulation fail, exit with the status it would have given.
                std::process::exit(128 + signal);
            }
        })?;
    // The terminal crossterm reads: standard input when it is one (its
    // other end closing is what a dropped connection looks like), else
    // /dev/tty. A closed pipe on standard input is not the terminal going.
    let stdin = rustix::stdio::stdin();
    let tty: Option<std::fs::File> = if rustix::termios::isatty(stdin) {
        None
    } else {
        std::fs::File::open("/dev/tty").ok()
    };
    std::thread::Builder::new()
        .name("nudge-terminal-watch".into())
        .spawn(move || {
            loop {
                let gone = match &tty {
                    Some(f) => hung_up(f),
                    None => hung_up(rustix::stdio::stdin()),
                };
                if gone {
                    std::process::exit(128 + SIGHUP);
                }
                std::thread::sleep(WATCH);
            }
        })?;
    Ok(())
}

/// Whether the terminal `fd` has hung up: its other end was closed.
fn hung_up(fd: impl std::os::fd::AsFd) -> bool {
    let mut fds = [PollFd::new(&fd, PollFlags::empty())];
    match poll(&mut fds, Some(&ZERO)) {
        Ok(_) => fds[0]
            .revents()
            .intersects(PollFlags::HUP | PollFlags::ERR | PollFlags::NVAL),
        Err(_) => false,
    }
}

const ZERO: rustix::event::Timespec = rustix::event::Timespec {
    tv_sec: 0,
    tv_nsec: 0,
};
