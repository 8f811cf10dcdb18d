//! Replay keys through the real App on a `TestBackend` and measure.

use super::keys::Step;
use crate::edit::Core;
use crate::tui::{App, Event, Theme, buffer_text, draw};
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use ratatui::layout::Rect;

/// Motion time the animation advances per key while playing (`p`), s. Key
/// scripts have no wall clock, so playback is one 30 fps frame per key.
pub const FRAME_SECONDS: f64 = 1.0 / 30.0;

/// What a replay produced.
#[derive(Debug, Clone, PartialEq)]
pub struct RunResult {
    /// The final screen: rows joined with `\n`, trailing spaces trimmed.
    /// Frame render times are not shown on it, so it is deterministic for a
    /// deterministic core.
    pub screen: String,
    /// Successful `core.apply` calls (every [`crate::edit::Edit`], selections included).
    pub edits: usize,
    /// Per key that reached the core: wall time of its `core.apply` calls
    /// (and saves), ms.
    pub update_ms: Vec<f64>,
    /// Wall time of every frame render (one before the first key, one per
    /// key), ms.
    pub render_ms: Vec<f64>,
    /// Per key that reached the core: wall time from the key to its frame
    /// drawn (the key's edits, the view and the render), ms.
    pub frame_ms: Vec<f64>,
    /// Whether a key quit the editor (the remaining keys were not replayed).
    pub quit: bool,
    /// Wall time of the work done in pauses after keys (the rest of a
    /// nudged motion, the integration error estimate), ms.
    pub idle_ms: Vec<f64>,
    /// Where the time of the keys' updates and frames went.
    pub profile: crate::profile::Profile,
    /// Where the time of the pauses' work (and the frames it redrew) went.
    pub paused: crate::profile::Profile,
    /// Command lines that did not parse (a misspelt command, a bad
    /// number). Without `keep_going` the replay stops at the first.
    pub failures: Vec<ScriptFailure>,
}

/// A command line of a script that did not parse.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{line}:{col}: {error}")]
pub struct ScriptFailure {
    /// Where the `<Enter>` that ran it was written (1-based).
    pub line: usize,
    pub col: usize,
    pub error: crate::tui::CommandError,
}

/// Summary of a list of timings, ms.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Latency {
    pub median: f64,
    /// 95th percentile (nearest rank).
    pub p95: f64,
    pub max: f64,
}

/// Median, 95th percentile and maximum of `samples`, or `None` if there are
/// none.
pub fn latency(samples: &[f64]) -> Option<Latency> {
    let mut s: Vec<f64> = samples.iter().copied().filter(|v| v.is_finite()).collect();
    if s.is_empty() {
        return None;
    }
    s.sort_by(f64::total_cmp);
    let n = s.len();
    let median = if n % 2 == 1 {
        s[n / 2]
    } else {
        (s[n / 2 - 1] + s[n / 2]) / 2.0
    };
    let rank = ((0.95 * n as f64).ceil() as usize).clamp(1, n);
    Some(Latency {
        median,
        p95: s[rank - 1],
        max: s[n - 1],
    })
}

impl RunResult {
    /// Latency of the edits.
    pub fn update_latency(&self) -> Option<Latency> {
        latency(&self.update_ms)
    }

    /// Latency of the frame renders.
    pub fn render_latency(&self) -> Option<Latency> {
        latency(&self.render_ms)
    }
}

/// Replay `keys` on a `size = (columns, rows)` screen: each key goes through
/// the key map and the App exactly as typed in the terminal, its nudge (if
/// any) is applied at once, and a frame is rendered if the key changed
/// anything (the UI state, the core through an edit, or its unsaved flag):
/// a key that changes nothing would draw the same screen again, and a long
/// script of them would spend its time redrawing. A quit key ends the run
/// early.
pub fn run_script<S: Copy + Into<Step>>(
    core: &mut impl Core,
    steps: &[S],
    size: (u16, u16),
) -> RunResult {
    run_script_with(core, steps, size, Replay::default())
}

/// How a replay runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Replay {
    /// Go on past command lines that do not parse (they are all listed in
    /// [`RunResult::failures`]) instead of stopping at the first.
    pub keep_going: bool,
    /// Pause after every key, so the editor does its deferred work
    /// ([`Core::idle`]) as in the terminal when the user stops typing;
    /// `false` replays keys as a held key arrives, with no pause between.
    pub pauses: bool,
}

impl Default for Replay {
    fn default() -> Self {
        Replay {
            keep_going: false,
            pauses: true,
        }
    }
}

/// [`run_script`] as `replay` says.
pub fn run_script_with<S: Copy + Into<Step>>(
    core: &mut impl Core,
    steps: &[S],
    size: (u16, u16),
    replay: Replay,
) -> RunResult {
    let (w, h) = size;
    let mut app = App::new(&core.view(), Rect::new(0, 0, w, h), Theme::COLOR);
    app.show_render_ms = false;
    app.timer = crate::tui::Timer::Stub;
    let mut terminal = match Terminal::new(TestBackend::new(w, h)) {
        Ok(t) => t,
        Err(never) => match never {},
    };
    // The tally starts with the replay (the first frame included).
    let _ = crate::profile::take();
    let mut update_ms = Vec::new();
    let mut render_ms = Vec::new();
    let mut idle_ms = Vec::new();
    let mut keys = crate::profile::Profile::default();
    let mut paused = crate::profile::Profile::default();
    let mut frame_ms = Vec::new();
    if let Ok(ms) = draw(&mut terminal, core, &mut app) {
        render_ms.push(ms);
    }
    let mut failures = Vec::new();
    for step in steps {
        let step: Step = (*step).into();
        let pressed = std::time::Instant::now();
        let before = (app.clone(), core.dirty());
        match step.event {
            Event::Key(key) => app.handle_key(core, key),
            Event::Mouse(m) => app.handle_mouse(core, m),
            Event::Resize(w, h) => app.resize(Rect::new(0, 0, w, h), &core.view()),
            Event::Other => {}
        }
        // A replay does not depend on timing: an exploration the key
        // started is waited for here.
        app.wait_background();
        let failed = app.take_command_error().map(|error| ScriptFailure {
            line: step.line,
            col: step.col,
            error,
        });
        app.flush(core);
        app.tick(core, FRAME_SECONDS);
        let applied = app.take_apply_ms();
        if !applied.is_empty() {
            update_ms.push(applied.iter().sum());
        }
        let unchanged = failed.is_none()
            && applied.is_empty()
            && app.edits() == before.0.edits()
            && core.dirty() == before.1
            && app == before.0;
        if unchanged {
            continue;
        }
        if let Ok(ms) = draw(&mut terminal, core, &mut app) {
            render_ms.push(ms);
        }
        if !applied.is_empty() {
            frame_ms.push(pressed.elapsed().as_secs_f64() * 1e3);
        }
        // What the editor defers to a pause (as after each key in the
        // terminal when no other key is waiting), timed on its own.
        keys.add(&crate::profile::take());
        if replay.pauses {
            loop {
                let start = std::time::Instant::now();
                if !core.idle() {
                    break;
                }
                idle_ms.push(start.elapsed().as_secs_f64() * 1e3);
                if let Ok(ms) = draw(&mut terminal, core, &mut app) {
                    render_ms.push(ms);
                }
            }
        }
        paused.add(&crate::profile::take());
        let stop = failed.is_some() && !replay.keep_going;
        failures.extend(failed);
        if app.quit || stop {
            break;
        }
    }
    RunResult {
        screen: buffer_text(terminal.backend().buffer()),
        edits: app.edits(),
        update_ms,
        render_ms,
        quit: app.quit,
        profile: {
            keys.add(&crate::profile::take());
            keys
        },
        paused,
        frame_ms,
        idle_ms,
        failures,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::script::parse_keys;
    use crate::tui::fixtures;

    fn run(script: &str) -> (RunResult, fixtures::FakeCore) {
        let mut core = fixtures::core();
        let keys = parse_keys(script, "test").unwrap_or_default();
        (run_script(&mut core, &keys, (80, 24)), core)
    }

    #[test]
    fn latency_summary() {
        assert_eq!(latency(&[]), None);
        let l = latency(&[3.0, 1.0, 2.0, f64::NAN]).unwrap_or(Latency {
            median: 0.0,
            p95: 0.0,
            max: 0.0,
        });
        assert_eq!((l.median, l.p95, l.max), (2.0, 3.0, 3.0));
        let many: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(
            latency(&many).map(|l| (l.median, l.p95)),
            Some((50.5, 95.0))
        );
    }

    #[test]
    fn nan_tolerance_is_refused_in_the_status_line() {
        let (r, core) = run(":set<Space>tol<Space>nan<Enter>");
        assert!(
            r.screen
                .contains(":set tol nan: expected a finite positive number"),
            "{}",
            r.screen
        );
        assert!(core.log.is_empty() && r.edits == 0 && !r.quit);
    }

    #[test]
    fn count_prefix_multiplies_a_nudge() {
        let (r, core) = run("5l");
        assert_eq!(r.edits, 1);
        let step = fixtures::app(&fixtures::view(), 80, 24).step();
        match core.log.as_slice() {
            [crate::edit::Edit::Nudge { delta, .. }] => {
                assert!((delta.x - 5.0 * step).abs() < 1e-12)
            }
            other => panic!("{other:?}"),
        }
        assert_eq!(r.update_ms.len(), 1);
        assert_eq!(r.render_ms.len(), 3);
    }

    #[test]
    fn keys_that_change_nothing_are_not_redrawn() {
        // An unbound key says so once; pressed again it changes nothing and
        // is not drawn, and the screen is what a redraw would show.
        let (r, core) = run(&["<F12>"; 1000].join(" "));
        assert!(core.log.is_empty() && r.edits == 0 && !r.quit);
        assert_eq!(r.render_ms.len(), 2, "the first frame and the first <F12>");
        let (once, _) = run("<F12>");
        assert_eq!(r.screen, once.screen);
        assert!(r.screen.contains("<F12> does nothing here"), "{}", r.screen);
        // Keys that change the UI state are drawn, each once.
        let (r, _) = run("<F12> <F12> Z Z 5 5");
        assert_eq!(r.render_ms.len(), 6, "all but the second <F12>");
    }

    #[test]
    fn quit_ends_the_run_early() {
        let (r, core) = run("q l l");
        assert!(r.quit);
        assert!(core.log.is_empty());
    }

    #[test]
    fn dirty_quit_prompts_and_write_quit_saves() {
        let (r, core) = run("l q");
        assert!(!r.quit);
        assert!(
            r.screen.contains("unsaved edits, quit anyway?"),
            "{}",
            r.screen
        );
        let (r, core2) = run("l :wq<Space>out.toml<CR>");
        assert!(r.quit);
        assert_eq!(core2.saved, vec![Some("out.toml".into())]);
        drop(core);
    }
}
