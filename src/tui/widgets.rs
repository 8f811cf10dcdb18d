//! Pure rendering: widgets over a [`View`] and the [`App`]'s UI state.
//! Nothing here changes state or runs the simulator; where each widget
//! goes is [`super::layout`]'s.

mod help;
mod panel;
mod readout;
mod scene;
mod status;
mod timeline;

pub use help::Popup;
pub use panel::{ConstraintsPanel, ControlsPanel};
pub use readout::Readout;
pub use scene::SceneCanvas;
pub use status::{BottomLine, StatusLine};
pub use timeline::Timeline;

use super::app::{App, Input};
use super::layout::{self, areas, too_small};
pub use super::layout::{MIN_HEIGHT, MIN_WIDTH};
use crate::view::View;
use ratatui::buffer::Buffer;
use ratatui::layout::{Alignment, Rect};
use ratatui::widgets::{Paragraph, Widget, Wrap};

/// The whole screen.
#[derive(Debug, Clone, Copy)]
pub struct Screen<'a> {
    pub view: &'a View,
    pub app: &'a App,
}

impl<'a> Screen<'a> {
    pub fn new(view: &'a View, app: &'a App) -> Self {
        Screen { view, app }
    }
}

impl Widget for &Screen<'_> {
    fn render(self, area: Rect, buf: &mut Buffer) {
        if too_small(area) {
            TooSmall.render(area, buf);
            return;
        }
        let (view, app) = (self.view, self.app);
        let a = areas(area);
        let theme = app.theme;
        SceneCanvas {
            view,
            camera: &app.camera,
            theme,
            playing: app.playing,
            show_ghost: app.show_ghost,
            alternative: app.alternative().map(|(a, ..)| a.paths.as_slice()),
        }
        .render(a.canvas, buf);
        let [readout, controls, constraints] = layout::side(a.side, view.constraints.len());
        let selected = app
            .selected_constraint
            .min(view.constraints.len().saturating_sub(1));
        (&Readout {
            view,
            theme,
            selected,
        })
            .render(readout, buf);
        (&ControlsPanel { view, theme }).render(controls, buf);
        (&ConstraintsPanel {
            view,
            theme,
            selected,
        })
            .render(constraints, buf);
        (&Timeline { view, theme }).render(a.timeline, buf);
        (&StatusLine { view, app }).render(a.status, buf);
        (&BottomLine { view, app }).render(a.bottom, buf);
        if let Input::Popup { kind, scroll } = app.input {
            (&Popup {
                kind,
                data: app.popup_data(&view.notes),
                theme,
                scroll,
            })
                .render(area, buf);
        }
    }
}

/// The notice shown when the terminal is below [`MIN_WIDTH`]×[`MIN_HEIGHT`].
#[derive(Debug, Clone, Copy)]
pub struct TooSmall;

impl TooSmall {
    /// The notice for a terminal of `area`.
    pub fn text(area: Rect) -> String {
        format!(
            "terminal too small:\nneed at least {MIN_WIDTH}x{MIN_HEIGHT}, have {}x{}",
            area.width, area.height
        )
    }
}

impl Widget for TooSmall {
    fn render(self, area: Rect, buf: &mut Buffer) {
        if area.is_empty() {
            return;
        }
        let text = TooSmall::text(area);
        // Centre vertically when the wrapped text leaves room.
        let lines: u16 = text
            .lines()
            .map(|l| (l.chars().count() as u16).div_ceil(area.width.max(1)))
            .sum();
        let top = area.height.saturating_sub(lines) / 2;
        let inner = Rect {
            y: area.y + top,
            height: area.height - top,
            ..area
        };
        Paragraph::new(text)
            .alignment(Alignment::Center)
            .wrap(Wrap { trim: true })
            .render(inner, buf);
    }
}

/// The buffer as plain text: rows joined with `\n`, trailing spaces trimmed.
pub fn buffer_text(buf: &Buffer) -> String {
    let area = buf.area;
    let mut rows = Vec::with_capacity(area.height as usize);
    for y in area.top()..area.bottom() {
        let mut row = String::new();
        for x in area.left()..area.right() {
            row.push_str(buf[(x, y)].symbol());
        }
        rows.push(row.trim_end().to_string());
    }
    rows.join("\n")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tui::fixtures;
    use ratatui::style::Color;

    fn render(view: &View, app: &App, w: u16, h: u16) -> Buffer {
        let area = Rect::new(0, 0, w, h);
        let mut buf = Buffer::empty(area);
        (&Screen::new(view, app)).render(area, &mut buf);
        buf
    }

    #[test]
    fn tiny_areas_do_not_panic() {
        let view = fixtures::view();
        let app = fixtures::app(&view, 80, 24);
        for (w, h) in [(0, 0), (1, 1), (10, 3), (0, 5), (5, 0), (59, 16), (60, 15)] {
            let text = buffer_text(&render(&view, &app, w, h));
            assert_eq!(text.split('\n').count(), h.max(1) as usize, "{w}x{h}");
            if w >= 30 {
                assert!(text.contains("terminal too small"), "{w}x{h}: {text}");
            }
        }
    }

    /// The status line used to run past 80 columns once the render time
    /// was shown, cutting off the accuracy setting and a typed count.
    #[test]
    fn the_status_line_fits_and_keeps_the_count_when_narrow() {
        let view = fixtures::view();
        let mut app = fixtures::app(&view, 80, 24);
        app.show_render_ms = true;
        app.render_ms = Some(12.345);
        app.count = Some(5);
        for width in [80u16, 60] {
            let mut buf = Buffer::empty(Rect::new(0, 0, width, 1));
            (&status::StatusLine {
                view: &view,
                app: &app,
            })
                .render(buf.area, &mut buf);
            let text = buffer_text(&buf);
            assert!(text.trim_end().ends_with("5…"), "{width}: {text}");
            assert!(
                text.contains(" t=") && text.contains(" r="),
                "{width}: {text}"
            );
        }
        let mut wide = Buffer::empty(Rect::new(0, 0, 140, 1));
        (&status::StatusLine {
            view: &view,
            app: &app,
        })
            .render(wide.area, &mut wide);
        let text = buffer_text(&wide);
        assert!(text.contains(" draw ") && text.contains("rk4"), "{text}");
    }

    #[test]
    fn too_small_names_both_sizes() {
        let view = fixtures::view();
        let app = fixtures::app(&view, 80, 24);
        let text = buffer_text(&render(&view, &app, 40, 10));
        assert!(
            text.contains("terminal too small:") && text.contains("need at least"),
            "{text}"
        );
        assert!(
            text.contains("60x16") && text.contains("have 40x10"),
            "{text}"
        );
    }

    #[test]
    fn tiny_too_small_notice_is_clipped() {
        let mut buf = Buffer::empty(Rect::new(0, 0, 10, 3));
        TooSmall.render(buf.area, &mut buf);
        let text = buffer_text(&buf);
        let lines: Vec<&str> = text.lines().map(str::trim).collect();
        assert_eq!(lines, ["terminal", "too small:", "need at"]);
        assert!(TooSmall::text(buf.area).ends_with("need at least 60x16, have 10x3"));
        let mut one = Buffer::empty(Rect::new(0, 0, 1, 1));
        TooSmall.render(one.area, &mut one);
        assert_eq!(buffer_text(&one), "t");
    }

    #[test]
    fn full_screen_shows_every_part() {
        let view = fixtures::view();
        let app = fixtures::app(&view, 80, 24);
        let text = buffer_text(&render(&view, &app, 80, 24));
        for part in [
            "bounce",
            "front",
            "controls",
            "constraints",
            "POS",
            "ball",
            "hjkl nudge",
            "rk4 h=1e-3",
        ] {
            assert!(text.contains(part), "missing {part}:\n{text}");
        }
        assert!(
            text.chars().any(|c| ('\u{2801}'..='\u{28ff}').contains(&c)),
            "no braille:\n{text}"
        );
    }

    /// Under NO_COLOR the selected outline still stands out (its cells are
    /// bold and reversed) and the ghost of the last edit is drawn.
    #[test]
    fn without_colour_the_outline_is_reversed_and_the_ghost_drawn() {
        use ratatui::style::Modifier;
        let mut view = fixtures::view();
        let app = fixtures::app(&view, 80, 24);
        let reversed = |buf: &Buffer| {
            buf.content()
                .iter()
                .filter(|c| c.modifier.contains(Modifier::REVERSED | Modifier::BOLD))
                .count()
        };
        let plain = render(&view, &app, 80, 24);
        // The mode badge and the selected rows are reversed too; the
        // outline adds its cells.
        let mut no_outline = view.clone();
        no_outline.selected_outline.clear();
        let base = reversed(&render(&no_outline, &app, 80, 24));
        assert!(reversed(&plain) > base, "{} vs {base}", reversed(&plain));
        // A ghost far from the traces shows as dots where there were none.
        let braille = |buf: &Buffer| {
            buf.content()
                .iter()
                .filter(|c| {
                    c.symbol()
                        .chars()
                        .any(|ch| ('\u{2801}'..='\u{28ff}').contains(&ch))
                })
                .count()
        };
        let before = braille(&plain);
        view.ghost = view.paths.clone();
        for p in &mut view.ghost {
            for q in &mut p.points {
                q.z += 0.4;
            }
        }
        assert!(braille(&render(&view, &app, 80, 24)) > before);
    }

    #[test]
    fn plain_theme_uses_no_colour_anywhere() {
        let view = fixtures::view();
        let mut app = fixtures::app(&view, 80, 24);
        for input in [
            Input::Normal,
            Input::Popup {
                kind: crate::tui::popup::PopupKind::Help,
                scroll: 0,
            },
            Input::Command("set".into()),
        ] {
            app.input = input;
            let buf = render(&view, &app, 80, 24);
            for cell in buf.content() {
                assert_eq!((cell.fg, cell.bg), (Color::Reset, Color::Reset), "{cell:?}");
            }
        }
    }

    #[test]
    fn non_finite_numbers_never_reach_the_screen() {
        let mut view = fixtures::view();
        view.time = f64::NAN;
        view.duration = f64::INFINITY;
        view.status.residual = f64::NAN;
        view.status.update_ms = f64::INFINITY;
        view.status.step = f64::NEG_INFINITY;
        for c in &mut view.controls {
            c.value = f64::NAN;
            c.delta = f64::INFINITY;
            c.scale = f64::NAN;
        }
        for c in &mut view.constraints {
            c.residual = f64::NAN;
        }
        view.paths[0]
            .points
            .push(crate::math::Vec3::new(f64::NAN, f64::INFINITY, 0.0));
        view.events[0].t = f64::NAN;
        let app = fixtures::app(&view, 80, 24);
        for (w, h) in [(80, 24), (120, 40), (60, 16)] {
            let text = buffer_text(&render(&view, &app, w, h));
            assert!(!text.contains("NaN") && !text.contains("inf"), "{text}");
            assert!(text.contains('—'), "{text}");
        }
    }
}
