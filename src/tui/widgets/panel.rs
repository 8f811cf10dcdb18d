//! The side panel: the control vector (free rows first) and the
//! constraints, each under a one-line titled rule.

use crate::tui::format::{
    num, pad_left_aligned, pad_right_aligned, resolved, scrub, short_control_name, signed, truncate,
};
use crate::tui::theme::Theme;
use crate::view::{ControlRow, View};
use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Widget};

/// Control-vector rows: marker (`●` free, `○` fixed), name, value, Δ since
/// the last edit, scale. Free rows come first, the selected body's and the
/// events' before the others; what does not fit is counted in a last
/// `+N more` row.
#[derive(Debug, Clone, Copy)]
pub struct ControlsPanel<'a> {
    pub view: &'a View,
    pub theme: Theme,
}

/// Constraint rows: kind, body, where, residual; the selected row is marked.
#[derive(Debug, Clone, Copy)]
pub struct ConstraintsPanel<'a> {
    pub view: &'a View,
    pub theme: Theme,
    pub selected: usize,
}

fn titled(title: String, theme: Theme) -> Block<'static> {
    Block::new()
        .borders(Borders::TOP)
        .border_style(theme.border())
        .title(Span::styled(title, theme.title()))
}

/// Column widths `(name, value, delta, scale)` for a panel `width` wide.
fn control_columns(width: usize) -> (usize, usize, usize, usize) {
    // The scale column only where the names still get 12 columns.
    let (value, delta, scale) = match width {
        38.. => (8, 8, 4),
        34..38 => (6, 6, 3),
        _ => (6, 6, 0),
    };
    // marker, then a space after the marker, name, value and delta.
    let spaces = if scale > 0 { 5 } else { 4 };
    let name = width.saturating_sub(spaces + value + delta + scale).max(1);
    (name, value, delta, scale)
}

impl Widget for &ControlsPanel<'_> {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let theme = self.theme;
        let controls = &self.view.controls;
        let free = controls.iter().filter(|c| c.free).count();
        let block = titled(format!(" controls {free}/{} free ", controls.len()), theme);
        let inner = block.inner(area);
        block.render(area, buf);
        if inner.is_empty() {
            return;
        }
        let (nw, vw, dw, sw) = control_columns(inner.width as usize);
        let mut header = format!(
            "  {} {} {}",
            pad_left_aligned("name", nw),
            pad_right_aligned("value", vw),
            pad_right_aligned("Δ", dw),
        );
        if sw > 0 {
            header.push_str(&format!(" {}", pad_right_aligned("M", sw)));
        }
        let mut lines = vec![Line::styled(header, theme.dim())];
        // Free rows first, and among them the selected body's and the
        // events' (Tab brings another body's controls into view).
        let selected = self
            .view
            .bodies
            .get(self.view.selected)
            .map(|b| format!("{b}."))
            .unwrap_or_default();
        let near = |c: &ControlRow| c.name.starts_with(&selected) || c.name.starts_with("event");
        let mut rows: Vec<&ControlRow> = controls.iter().collect();
        rows.sort_by_key(|c| (!c.free, !near(c)));
        let room = (inner.height as usize).saturating_sub(1);
        let shown = if rows.len() > room {
            room.saturating_sub(1)
        } else {
            rows.len()
        };
        for c in &rows[..shown] {
            let marker = if c.free { "●" } else { "○" };
            let value = resolved(c.value, c.scale);
            let change = resolved(c.delta, c.scale);
            let delta = if change == 0.0 {
                String::new()
            } else {
                signed(change, dw)
            };
            let base = if c.free {
                ratatui::style::Style::new()
            } else {
                theme.dim()
            };
            lines.push(Line::from(vec![
                Span::styled(
                    format!(
                        "{marker} {} ",
                        pad_left_aligned(&short_control_name(&c.name, nw), nw)
                    ),
                    base,
                ),
                Span::styled(format!("{} ", pad_right_aligned(&num(value, vw), vw)), base),
                Span::styled(
                    pad_right_aligned(&delta, dw),
                    if change != 0.0 { theme.changed() } else { base },
                ),
                Span::styled(
                    if sw > 0 {
                        format!(" {}", pad_right_aligned(&num(c.scale, sw), sw))
                    } else {
                        String::new()
                    },
                    theme.dim(),
                ),
            ]));
        }
        if shown < rows.len() {
            let hidden_free = rows[shown..].iter().filter(|c| c.free).count();
            let more = format!("  +{} more ({hidden_free} free)", rows.len() - shown);
            lines.push(Line::styled(more, theme.dim()));
        }
        if controls.is_empty() {
            lines.push(Line::styled("  none: :free body block", theme.dim()));
        }
        for (i, line) in lines.iter().enumerate().take(inner.height as usize) {
            line.render(
                Rect {
                    y: inner.y + i as u16,
                    height: 1,
                    ..inner
                },
                buf,
            );
        }
    }
}

/// Kind as shown in a 5-character column.
fn short_kind(kind: &str) -> String {
    let k = match kind {
        "floating" => "float",
        "equal_speed" => "speed",
        "angular_speed" => "spin",
        "point_on_plane" => "plane",
        "distance" => "dist",
        other => other,
    };
    truncate(k, 5)
}

/// Where a constraint applies, within `width`: `hit#3 post` becomes
/// `#3 post` when it has to.
fn short_at(at: &str, width: usize) -> String {
    if at.chars().count() <= width {
        return at.to_string();
    }
    truncate(&at.replace("hit#", "#"), width)
}

impl Widget for &ConstraintsPanel<'_> {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let theme = self.theme;
        let rows = &self.view.constraints;
        let block = titled(format!(" constraints {} ", rows.len()), theme);
        let inner = block.inner(area);
        block.render(area, buf);
        if inner.is_empty() {
            return;
        }
        let width = inner.width as usize;
        if rows.is_empty() {
            Line::styled("  none: a nails, f floats", theme.dim()).render(inner, buf);
            return;
        }
        // marker kind body at residual
        let rest = width.saturating_sub(1 + 5 + 1 + 1 + 1 + 6);
        let body_w = (rest * 5 / 13).max(3).min(rest);
        let at_w = rest - body_w;
        let height = inner.height as usize;
        // Keep the selected row visible.
        let first = (self.selected + 1).saturating_sub(height);
        for (i, (k, c)) in rows.iter().enumerate().skip(first).take(height).enumerate() {
            let selected = k == self.selected;
            let text = format!(
                "{}{} {} {} {}",
                if selected { "▸" } else { " " },
                pad_left_aligned(&short_kind(&c.kind), 5),
                pad_left_aligned(&c.body, body_w),
                pad_left_aligned(&short_at(&scrub(&c.at), at_w), at_w),
                pad_right_aligned(&num(c.residual, 6), 6)
            );
            let style = if selected {
                theme.selected()
            } else {
                ratatui::style::Style::new()
            };
            Line::styled(text, style).render(
                Rect {
                    y: inner.y + i as u16,
                    height: 1,
                    ..inner
                },
                buf,
            );
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tui::fixtures;
    use crate::tui::widgets::buffer_text;
    use crate::view::ConstraintRow;

    /// The controls panel of `view`, 28 columns by `height` rows, as text.
    fn controls_text(view: &View, height: u16) -> String {
        let mut buf = Buffer::empty(Rect::new(0, 0, 28, height));
        (&ControlsPanel {
            view,
            theme: Theme::PLAIN,
        })
            .render(buf.area, &mut buf);
        buffer_text(&buf)
    }

    /// With more controls than rows, the selected body's free controls come
    /// first: Tab to another body brings its controls into view.
    #[test]
    fn the_selected_bodys_free_controls_come_first() {
        let mut view = fixtures::view();
        let row = |name: &str, free: bool| ControlRow {
            name: name.into(),
            value: 1.0,
            delta: 0.0,
            free,
            scale: 1.0,
        };
        view.bodies = vec!["a".into(), "b".into()];
        view.controls = vec![
            row("a.p.x", true),
            row("a.p.y", true),
            row("b.p.x", true),
            row("b.m", false),
        ];
        for (selected, first) in [(0, "a.p.x"), (1, "b.p.x")] {
            view.selected = selected;
            let text = controls_text(&view, 4);
            let line = text.lines().nth(2).unwrap_or_default();
            assert!(line.contains(first), "selected {selected}: {text}");
        }
    }

    /// Solver round-off (a value of 2e-18 on a scale of 1) reads 0 and
    /// a round-off change is no change; real small values stay.
    #[test]
    fn round_off_values_and_changes_read_as_zero() {
        let mut view = fixtures::view();
        let row = |name: &str, value: f64, delta: f64| ControlRow {
            name: name.into(),
            value,
            delta,
            free: true,
            scale: 1.0,
        };
        view.controls = vec![row("ball.r.x", 2e-18, -3e-17), row("ball.r.y", 2e-6, 1e-7)];
        let text = controls_text(&view, 4);
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[2], "● ball.r.x          0", "\n{text}");
        assert_eq!(lines[3], "● ball.r.y       2e-6  +1e-7", "\n{text}");
    }

    #[test]
    fn names_shorten_block_first_then_body() {
        assert_eq!(short_control_name("ball.velocity.x", 15), "ball.velocity.x");
        assert_eq!(short_control_name("ball.velocity.x", 10), "ball vel.x");
        assert_eq!(
            short_control_name("plank.angular_velocity.y", 10),
            "plank ω.y"
        );
        assert_eq!(
            short_control_name("longbodyname.angular_velocity.z", 10),
            "longb… ω.z"
        );
        assert_eq!(short_control_name("hit3.restitution", 9), "hit3 e");
        assert_eq!(short_control_name("x", 0), "");
        assert_eq!(short_at("hit#12 post", 8), "#12 post");
        assert_eq!(short_at("t=1.250", 8), "t=1.250");
        assert_eq!(short_at("hit#123 post", 6), "#123 …");
    }

    #[test]
    fn controls_at_28_columns() {
        let view = fixtures::view();
        let text = controls_text(&view, 5);
        let expected = [
            " controls 4/6 free ─────────",
            "  name          value      Δ",
            "● ball pos.x     -0.5",
            "● ball pos.z        1  +0.01",
            "  +4 more (2 free)",
        ];
        assert_eq!(text, expected.join("\n"), "\n{text}");
    }

    #[test]
    fn constraints_keep_the_selection_visible() {
        let mut view = fixtures::view();
        view.constraints = (0..6)
            .map(|i| ConstraintRow {
                kind: "nail".into(),
                body: "ball".into(),
                at: format!("t={i}.000"),
                residual: 1e-9,
                gap: None,
            })
            .collect();
        let mut buf = Buffer::empty(Rect::new(0, 0, 28, 4));
        (&ConstraintsPanel {
            view: &view,
            theme: Theme::PLAIN,
            selected: 5,
        })
            .render(buf.area, &mut buf);
        let text = buffer_text(&buf);
        assert!(
            text.lines()
                .last()
                .unwrap_or_default()
                .starts_with("▸nail  ball  t=5.000"),
            "{text}"
        );
    }

    #[test]
    fn panels_render_in_tiny_areas() {
        let view = fixtures::view();
        for (w, h) in [(0, 0), (1, 1), (10, 3), (3, 10)] {
            let mut buf = Buffer::empty(Rect::new(0, 0, w, h));
            (&ControlsPanel {
                view: &view,
                theme: Theme::COLOR,
            })
                .render(buf.area, &mut buf);
            (&ConstraintsPanel {
                view: &view,
                theme: Theme::COLOR,
                selected: 9,
            })
                .render(buf.area, &mut buf);
        }
    }
}
