//! A popup: the key help, the message log or the scene's notes, drawn
//! over the screen and scrolled (what it says is [`crate::tui::popup`]'s).

use crate::tui::layout;
use crate::tui::popup::{self, PopupData, PopupKind};
use crate::tui::theme::Theme;
use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::text::Span;
use ratatui::widgets::{Block, Clear, Paragraph, Widget};

/// A popup scrolled `scroll` lines (clamped to the end).
#[derive(Debug, Clone, Copy)]
pub struct Popup<'a> {
    pub kind: PopupKind,
    pub data: PopupData<'a>,
    pub theme: Theme,
    pub scroll: u16,
}

impl Widget for &Popup<'_> {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let rect = layout::popup(area);
        let lines = popup::lines(self.kind, self.data, self.theme, area);
        let max = popup::max_scroll(self.kind, self.data, area);
        let block = Block::bordered()
            .border_style(self.theme.border())
            .title(Span::styled(self.kind.title(), self.theme.title()));
        Clear.render(rect, buf);
        Paragraph::new(lines)
            .block(block)
            .scroll((self.scroll.min(max), 0))
            .render(rect, buf);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tui::command::usage_rows;
    use crate::tui::keymap::KEYMAP;
    use crate::tui::widgets::buffer_text;

    /// Draw the key help scrolled `scroll` lines into `buf`.
    fn help(theme: Theme, scroll: u16, area: Rect, buf: &mut Buffer) {
        let data = PopupData {
            log: &[],
            notes: "",
            sensitivity: None,
            accuracy: None,
        };
        (&Popup {
            kind: PopupKind::Help,
            data,
            theme,
            scroll,
        })
            .render(area, buf);
    }

    #[test]
    fn lists_every_key_and_command() {
        let mut buf = Buffer::empty(Rect::new(0, 0, 120, 200));
        help(Theme::PLAIN, 0, buf.area, &mut buf);
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
        help(Theme::PLAIN, 1000, a.area, &mut a);
        help(Theme::PLAIN, u16::MAX, b.area, &mut b);
        assert_eq!(a, b);
        assert!(buffer_text(&a).contains(":help"), "{}", buffer_text(&a));
    }

    #[test]
    fn renders_in_tiny_areas() {
        for (w, h) in [(0, 0), (1, 1), (10, 3), (4, 2)] {
            let mut buf = Buffer::empty(Rect::new(0, 0, w, h));
            help(Theme::COLOR, 3, buf.area, &mut buf);
        }
    }
}
