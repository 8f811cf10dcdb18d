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

/// Smallest run of events on neighbouring columns drawn as one mark.
const GROUP: usize = 3;

/// The event marks of a bar `width` cells wide: a tick per event (`╪` when
/// grazing), and a run of at least [`GROUP`] events on neighbouring columns
/// (a body rocking or settling) as one tick with its count, `┼×37`.
pub fn marks(v: &View, width: usize) -> Vec<(usize, String)> {
    let mut cols: Vec<(usize, bool)> = v
        .events
        .iter()
        .filter_map(|e| column(e.t, v.duration, width).map(|x| (x, e.grazing)))
        .collect();
    cols.sort();
    let mut out = Vec::new();
    let mut i = 0;
    while i < cols.len() {
        let mut j = i + 1;
        while j < cols.len() && cols[j].0 <= cols[j - 1].0 + 1 {
            j += 1;
        }
        let grazing = cols[i..j].iter().any(|c| c.1);
        let tick = if grazing { '╪' } else { '┼' };
        if j - i >= GROUP {
            out.push((cols[i].0, format!("{tick}×{}", j - i)));
        } else {
            out.extend(
                cols[i..j]
                    .iter()
                    .map(|&(x, g)| (x, if g { '╪' } else { '┼' }.to_string())),
            );
        }
        i = j;
    }
    out
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
        for (x, text) in marks(v, width) {
            for (k, c) in text.chars().enumerate() {
                if let Some(cell) = bar.get_mut(x + k) {
                    *cell = c;
                }
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
            ..EventMark::default()
        }
    }

    #[test]
    fn a_run_of_micro_contacts_is_one_mark_with_its_count() {
        let mut view = View {
            time: 0.0,
            duration: 2.0,
            ..View::default()
        };
        view.events.push(ev(0.2));
        view.events
            .extend((0..37).map(|k| ev(1.5 + 1e-3 * f64::from(k))));
        let m = marks(&view, 40);
        assert_eq!(m.len(), 2, "{m:?}");
        assert_eq!(m[0].1, "┼");
        assert_eq!(m[1].1, "┼×37");
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
