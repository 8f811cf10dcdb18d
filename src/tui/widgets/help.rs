//! The `?` popup: every key of the key map by context, then the `:`
//! commands. Generated from the same table the App dispatches from.

use crate::tui::command::{COMMAND_NOTES, usage_rows};
use crate::tui::keymap::{Context, help_rows};
use crate::tui::theme::Theme;
use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Clear, Paragraph, Widget};

/// The help popup, scrolled `scroll` lines (clamped to the end).
#[derive(Debug, Clone, Copy)]
pub struct HelpPopup {
    pub theme: Theme,
    pub scroll: u16,
}

/// Widest keys column.
const MAX_KEYS_WIDTH: usize = 26;

impl HelpPopup {
    /// The popup's lines.
    pub fn lines(theme: Theme) -> Vec<Line<'static>> {
        let mut lines = Vec::new();
        let rows = help_rows();
        let widest = rows
            .iter()
            .map(|r| r.keys.join(" ").chars().count())
            .max()
            .unwrap_or(0);
        let keys_width = widest.min(MAX_KEYS_WIDTH) + 1;
        let widest = usage_rows()
            .map(|(c, _)| c.chars().count())
            .max()
            .unwrap_or(0);
        let commands_width = widest.min(MAX_KEYS_WIDTH) + 1;
        for context in Context::ALL {
            if !lines.is_empty() {
                lines.push(Line::raw(""));
            }
            lines.push(Line::styled(context.title().to_string(), theme.title()));
            for row in rows.iter().filter(|r| r.context == context) {
                let keys = row.keys.join(" ");
                let pad = keys_width.saturating_sub(keys.chars().count()).max(1);
                lines.push(Line::from(vec![
                    Span::styled(format!("  {keys}"), theme.key()),
                    Span::raw(format!("{}{}", " ".repeat(pad), row.help)),
                ]));
            }
        }
        lines.push(Line::raw(""));
        lines.push(Line::styled("commands (:)", theme.title()));
        for (cmd, does) in usage_rows() {
            let pad = commands_width.saturating_sub(cmd.chars().count()).max(1);
            lines.push(Line::from(vec![
                Span::styled(format!("  {cmd}"), theme.key()),
                Span::raw(format!("{}{does}", " ".repeat(pad))),
            ]));
        }
        for note in COMMAND_NOTES {
            lines.push(Line::styled(format!("  {note}"), theme.dim()));
        }
        lines
    }

    /// Where the popup sits on a screen of `area`.
    fn popup(area: Rect) -> Rect {
        let width = area.width.saturating_sub(4).min(100);
        let height = area.height.saturating_sub(2);
        Rect {
            x: area.x + (area.width - width) / 2,
            y: area.y + (area.height - height) / 2,
            width,
            height,
        }
    }

    /// How far the popup can scroll on a screen of `area` (the last line at
    /// the bottom).
    pub fn max_scroll(area: Rect) -> u16 {
        let visible = Block::bordered().inner(HelpPopup::popup(area)).height;
        (HelpPopup::lines(Theme::PLAIN).len() as u16).saturating_sub(visible)
    }
}

impl Widget for &HelpPopup {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let popup = HelpPopup::popup(area);
        let lines = HelpPopup::lines(self.theme);
        let block = Block::bordered()
            .border_style(self.theme.border())
            .title(Span::styled(
                " keys: j/k scroll, ? or Esc closes ",
                self.theme.title(),
            ));
        Clear.render(popup, buf);
        Paragraph::new(lines)
            .block(block)
            .scroll((self.scroll.min(HelpPopup::max_scroll(area)), 0))
            .render(popup, buf);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tui::keymap::KEYMAP;
    use crate::tui::widgets::buffer_text;

    #[test]
    fn lists_every_key_and_command() {
        let mut buf = Buffer::empty(Rect::new(0, 0, 120, 200));
        (&HelpPopup {
            theme: Theme::PLAIN,
            scroll: 0,
        })
            .render(buf.area, &mut buf);
        let text = buffer_text(&buf);
        for b in KEYMAP {
            let key = b.key.to_string();
            let listed = text.lines().any(|l| {
                let keys = l
                    .trim_start_matches(['│', ' '])
                    .split("  ")
                    .next()
                    .unwrap_or_default()
                    .trim_end();
                keys.split(' ').any(|k| k == key) && l.contains(b.help)
            });
            assert!(listed, "{key} ({}) missing from help:\n{text}", b.help);
        }
        for (cmd, _) in usage_rows() {
            assert!(text.contains(cmd), "{cmd} missing");
        }
    }

    #[test]
    fn scrolling_past_the_end_stops_at_the_end() {
        let mut a = Buffer::empty(Rect::new(0, 0, 80, 24));
        let mut b = Buffer::empty(Rect::new(0, 0, 80, 24));
        (&HelpPopup {
            theme: Theme::PLAIN,
            scroll: 1000,
        })
            .render(a.area, &mut a);
        (&HelpPopup {
            theme: Theme::PLAIN,
            scroll: u16::MAX,
        })
            .render(b.area, &mut b);
        assert_eq!(a, b);
        assert!(buffer_text(&a).contains(":help"), "{}", buffer_text(&a));
    }

    #[test]
    fn renders_in_tiny_areas() {
        for (w, h) in [(0, 0), (1, 1), (10, 3), (4, 2)] {
            let mut buf = Buffer::empty(Rect::new(0, 0, w, h));
            (&HelpPopup {
                theme: Theme::COLOR,
                scroll: 3,
            })
                .render(buf.area, &mut buf);
        }
    }
}
