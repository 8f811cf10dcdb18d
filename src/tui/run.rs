//! The event loop, generic over the ratatui [`Backend`] and over where
//! events come from, so tests run it on a `TestBackend` with scripted input.
//!
//! Each turn: wait for input (or the next animation frame), drain *every*
//! pending event, apply the accumulated nudge as one edit, advance the
//! animation, redraw. Holding a key therefore drags: key repeats that
//! arrive while the core is solving are summed into the next nudge instead
//! of queueing one solve each.

use super::app::App;
use super::key::Key;
use super::mouse::Mouse;
use super::theme::Theme;
use super::widgets::Screen;
use crate::edit::Core;
use ratatui::Terminal;
use ratatui::backend::Backend;
use ratatui::layout::Rect;
use std::io;
use std::time::{Duration, Instant};

/// An input event the loop cares about.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Event {
    Key(Key),
    /// The left button or the wheel (when mouse capture is on).
    Mouse(Mouse),
    /// New terminal size, columns × rows.
    Resize(u16, u16),
    /// Anything else (focus, other buttons, key releases): ignored.
    Other,
}

/// Where events come from.
pub trait EventSource {
    /// Whether an event is ready within `timeout`.
    fn poll(&mut self, timeout: Duration) -> io::Result<bool>;
    /// The next event (blocks until there is one).
    fn read(&mut self) -> io::Result<Event>;
    /// Ask the terminal to report the mouse, or to stop (so its own text
    /// selection works). Sources without a terminal ignore it.
    fn set_mouse(&mut self, _on: bool) -> io::Result<()> {
        Ok(())
    }
}

/// Events from the real terminal, through crossterm. Signals and a
/// terminal that went away are handled by the session's guards
/// (`tui::session`), which restore the terminal and end the process.
#[derive(Debug, Default)]
pub struct TerminalEvents;

impl TerminalEvents {
    /// Events from the terminal.
    ///
    /// # Errors
    /// None today; kept fallible for sources that open a device.
    pub fn new() -> io::Result<TerminalEvents> {
        Ok(TerminalEvents)
    }
}

impl EventSource for TerminalEvents {
    fn poll(&mut self, timeout: Duration) -> io::Result<bool> {
        ratatui::crossterm::event::poll(timeout)
    }

    fn read(&mut self) -> io::Result<Event> {
        use ratatui::crossterm::event::Event as E;
        Ok(match ratatui::crossterm::event::read()? {
            E::Key(k) => Key::from_crossterm(k).map_or(Event::Other, Event::Key),
            E::Mouse(m) => Mouse::from_crossterm(m).map_or(Event::Other, Event::Mouse),
            E::Resize(w, h) => Event::Resize(w, h),
            _ => Event::Other,
        })
    }

    fn set_mouse(&mut self, on: bool) -> io::Result<()> {
        use ratatui::crossterm::event::{DisableMouseCapture, EnableMouseCapture};
        if on {
            ratatui::crossterm::execute!(io::stdout(), EnableMouseCapture)
        } else {
            ratatui::crossterm::execute!(io::stdout(), DisableMouseCapture)
        }
    }
}

/// Animation frame interval while playing.
const FRAME: Duration = Duration::from_millis(33);
/// How long to wait for input when idle (the loop just redraws after it).
const IDLE: Duration = Duration::from_millis(500);
/// How often a background exploration's progress is looked at.
const EXPLORE_POLL: Duration = Duration::from_millis(100);
/// Longest time spent draining a burst of events before redrawing.
const DRAIN_BUDGET: Duration = Duration::from_millis(30);

/// Run the editor in the terminal until the user quits. The terminal is
/// restored on return and on panic.
pub fn run<C: Core>(core: &mut C) -> io::Result<()> {
    let mut terminal = ratatui::try_init()?;
    if let Err(e) = super::session::guard() {
        super::session::restore_terminal();
        return Err(e);
    }
    let result = (|| {
        let size = terminal.size()?;
        let mut app = App::new(
            &core.view(),
            Rect::new(0, 0, size.width, size.height),
            Theme::from_env(),
        );
        event_loop(&mut terminal, core, &mut app, &mut TerminalEvents::new()?)
    })();
    super::session::restore_terminal();
    result
}

fn backend_error(e: impl std::fmt::Display) -> io::Error {
    io::Error::other(e.to_string())
}

/// Draw one frame of `app` over the core's current view; records the
/// render time in `app.render_ms` and returns it (ms).
pub fn draw<B: Backend, C: Core>(
    terminal: &mut Terminal<B>,
    core: &C,
    app: &mut App,
) -> io::Result<f64> {
    let view = core.view();
    let start = Instant::now();
    let _span = crate::profile::span(crate::profile::Part::Render);
    terminal
        .draw(|frame| {
            let area = frame.area();
            frame.render_widget(&Screen::new(&view, app), area);
        })
        .map_err(backend_error)?;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    app.render_ms = Some(ms);
    Ok(ms)
}

/// The event loop: returns when the user quits, or on an I/O error.
pub fn event_loop<B: Backend, C: Core, E: EventSource>(
    terminal: &mut Terminal<B>,
    core: &mut C,
    app: &mut App,
    events: &mut E,
) -> io::Result<()> {
    let mut last_tick = Instant::now();
    let mut captured = None;
    loop {
        if captured != Some(app.mouse) {
            events.set_mouse(app.mouse)?;
            captured = Some(app.mouse);
        }
        draw(terminal, core, app)?;
        if app.quit {
            return Ok(());
        }
        // Deferred work (the error estimate after a drag) when no key is
        // waiting: a held key's frames do not wait for it.
        while !events.poll(Duration::ZERO)? && core.idle() {
            draw(terminal, core, app)?;
        }
        let timeout = if app.playing {
            FRAME.saturating_sub(last_tick.elapsed())
        } else if app.busy() {
            // Progress of the background work on the status line.
            EXPLORE_POLL
        } else {
            IDLE
        };
        if events.poll(timeout)? {
            let start = Instant::now();
            loop {
                match events.read()? {
                    Event::Key(key) => app.handle_key(core, key),
                    Event::Mouse(m) => app.handle_mouse(core, m),
                    Event::Resize(w, h) => app.resize(Rect::new(0, 0, w, h), &core.view()),
                    Event::Other => {}
                }
                if app.quit || start.elapsed() > DRAIN_BUDGET || !events.poll(Duration::ZERO)? {
                    break;
                }
            }
        }
        app.flush(core);
        app.poll_background();
        let dt = last_tick.elapsed().as_secs_f64();
        last_tick = Instant::now();
        app.tick(core, dt);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::edit::Edit;
    use crate::tui::fixtures::{self, FakeCore};
    use crate::tui::key::KeyCode;
    use ratatui::backend::TestBackend;
    use std::collections::VecDeque;

    /// Scripted events; running dry is an error so a test cannot hang.
    struct Scripted(VecDeque<Event>);

    impl EventSource for Scripted {
        fn poll(&mut self, _: Duration) -> io::Result<bool> {
            if self.0.is_empty() {
                Err(io::Error::new(
                    io::ErrorKind::UnexpectedEof,
                    "script ran dry",
                ))
            } else {
                Ok(true)
            }
        }

        fn read(&mut self) -> io::Result<Event> {
            self.0
                .pop_front()
                .ok_or_else(|| io::Error::new(io::ErrorKind::UnexpectedEof, "script ran dry"))
        }
    }

    fn keys(s: &str) -> Vec<Event> {
        s.chars().map(|c| Event::Key(Key::char(c))).collect()
    }

    fn run_events(core: &mut FakeCore, events: Vec<Event>) -> io::Result<App> {
        let mut terminal = Terminal::new(TestBackend::new(80, 24)).map_err(backend_error)?;
        let mut app = App::new(&core.view(), Rect::new(0, 0, 80, 24), Theme::PLAIN);
        event_loop(&mut terminal, core, &mut app, &mut Scripted(events.into()))?;
        Ok(app)
    }

    #[test]
    fn a_burst_of_nudges_is_one_edit() {
        let mut core = fixtures::core();
        let events = keys("llllqy");
        let app = run_events(&mut core, events).expect("loop ends on q");
        assert!(app.quit);
        let nudges: Vec<_> = core
            .log
            .iter()
            .filter(|e| matches!(e, Edit::Nudge { .. }))
            .collect();
        assert_eq!(nudges.len(), 1, "{:?}", core.log);
        if let Edit::Nudge { delta, .. } = nudges[0] {
            assert!((delta.x - 4.0 * app.step()).abs() < 1e-12, "{delta:?}");
        }
    }

    #[test]
    fn resize_refits_and_a_dirty_quit_asks() {
        let mut core = fixtures::core();
        core.dirty = true;
        let mut events = vec![Event::Resize(100, 30), Event::Key(Key::char('q'))];
        events.push(Event::Key(Key::char('n')));
        // Esc never quits: it is a no-op here, and q asks again.
        events.push(Event::Key(Key::new(KeyCode::Esc)));
        events.push(Event::Key(Key::char('q')));
        events.push(Event::Key(Key::char('y')));
        let app = run_events(&mut core, events).expect("quits after y");
        assert_eq!(app.area, Rect::new(0, 0, 100, 30));
        assert!(app.quit);
    }

    #[test]
    fn running_dry_is_an_error_not_a_hang() {
        let mut core = fixtures::core();
        assert!(run_events(&mut core, keys("l")).is_err());
    }
}
