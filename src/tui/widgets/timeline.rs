//! The timeline row: current time, a bar over the whole motion with a tick
//! per collision event and a marker at the current time, and the duration.

use crate::tui::format::{num, pad_right_aligned};
use crate::tui::theme::Theme;
use crate::view::View;
use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::text::{Line, Span};
use ratatui::widgets::Widget;

/// ` 1.250 ────┼───●────┼──── 3.000 s`
#[derive(Debug, Clone, Copy)]
pub struct Timeline<'a> {
    pub view: &'a View,
    pub theme: Theme,
}

/// Column of time `t` on a bar `width` cells wide over `[0, duration]`.
fn column(t: f64, duration: f64, width: usize) -> Option<usize> {
    if !(t.is_finite() && duration.is_finite() && duration > 0.0) || width == 0 {
        return None;
    }
    let x = (t / duration).clamp(0.0, 1.0) * (width - 1) as f64;
    Some(x.round() as usize)
}

impl Widget for &Timeline<'_> {
    fn render(self, area: Rect, buf: &mut Buffer) {
        if area.is_empty() {
            return;
        }
        let v = self.view;
        let left = format!("{} ", pad_right_aligned(&num(v.time, 7), 7));
        let right = format!(" {} s", num(v.duration, 7));
        let width =
            (area.width as usize).saturating_sub(left.chars().count() + right.chars().count());
        let mut bar: Vec<char> = vec!['─'; width];
        for e in &v.events {
            if let Some(x) = column(e.t, v.duration, width) {
                bar[x] = if e.grazing { '╪' } else { '┼' };
            }
        }
        let now = column(v.time, v.duration, width);
        let mut spans = vec![Span::styled(left, self.theme.title())];
        match now {
            Some(x) => {
                spans.push(Span::styled(
                    bar[..x].iter().collect::<String>(),
                    self.theme.dim(),
                ));
                spans.push(Span::styled("●", self.theme.changed()));
                spans.push(Span::styled(
                    bar[x + 1..].iter().collect::<String>(),
                    self.theme.dim(),
                ));
            }
            None => spans.push(Span::styled(
                bar.iter().collect::<String>(),
                self.theme.dim(),
            )),
        }
        spans.push(Span::raw(right));
        Line::from(spans).render(area, buf);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Vec3;
    use crate::tui::widgets::buffer_text;
    use crate::view::EventMark;

    fn ev(t: f64) -> EventMark {
        EventMark {
            index: 0,
            t,
            point: Vec3::zeros(),
            a: "a".into(),
            b: "b".into(),
            grazing: false,
        }
    }

    #[test]
    fn marks_time_and_events() {
        let view = View {
            time: 1.0,
            duration: 2.0,
            events: vec![ev(0.5), ev(2.0)],
            ..View::default()
        };
        let mut buf = Buffer::empty(Rect::new(0, 0, 30, 1));
        (&Timeline {
            view: &view,
            theme: Theme::PLAIN,
        })
            .render(buf.area, &mut buf);
        assert_eq!(buffer_text(&buf), "      1 ────┼────●───────┼ 2 s");
    }

    #[test]
    fn no_duration_no_marker_and_tiny_areas() {
        let view = View {
            time: f64::NAN,
            duration: 0.0,
            ..View::default()
        };
        let mut buf = Buffer::empty(Rect::new(0, 0, 24, 1));
        (&Timeline {
            view: &view,
            theme: Theme::PLAIN,
        })
            .render(buf.area, &mut buf);
        assert_eq!(buffer_text(&buf), "      — ──────────── 0 s");
        for (w, h) in [(0, 0), (1, 1), (10, 3)] {
            let mut buf = Buffer::empty(Rect::new(0, 0, w, h));
            (&Timeline {
                view: &view,
                theme: Theme::COLOR,
            })
                .render(buf.area, &mut buf);
        }
    }
}
