//! What the popups say: the key help (`?`), the message log (`M`,
//! `:messages`) and the scene's notes (`:notes`), as lines wrapped to the
//! popup's width. The App scrolls them and the widget draws them, both from
//! here, so the two always agree on how long a popup is.

use super::app::Message;
use super::command::{COMMAND_NOTES, usage_rows};
use super::keymap::{Context, help_rows};
use super::layout;
use super::theme::Theme;
use ratatui::layout::Rect;
use ratatui::text::{Line, Span};

/// Which popup is open.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PopupKind {
    /// Every key by context, then the `:` commands.
    Help,
    /// Every message since the editor opened, oldest first.
    Messages,
    /// The scene's notes.
    Notes,
}

impl PopupKind {
    /// The popup's title.
    pub fn title(self) -> &'static str {
        match self {
            PopupKind::Help => " keys: j/k scroll, ? or Esc closes ",
            PopupKind::Messages => " messages: j/k scroll, Esc closes ",
            PopupKind::Notes => " scene notes: j/k scroll, Esc closes ",
        }
    }
}

/// Widest keys column of the help.
const MAX_KEYS_WIDTH: usize = 26;

/// What a popup shows on a screen of `area`.
pub fn lines(
    kind: PopupKind,
    log: &[Message],
    notes: &str,
    theme: Theme,
    area: Rect,
) -> Vec<Line<'static>> {
    let width = usize::from(layout::popup_inner(area).width.max(1));
    match kind {
        PopupKind::Help => help_lines(theme),
        PopupKind::Messages if log.is_empty() => vec![Line::styled("no messages yet", theme.dim())],
        PopupKind::Messages => log
            .iter()
            .flat_map(|m| {
                wrap(&m.text, width)
                    .into_iter()
                    .enumerate()
                    .map(|(k, l)| Line::raw(if k == 0 { l } else { format!("  {l}") }))
            })
            .collect(),
        PopupKind::Notes if notes.trim().is_empty() => {
            vec![Line::styled("this scene has no notes", theme.dim())]
        }
        PopupKind::Notes => notes
            .lines()
            .flat_map(|p| wrap(p, width))
            .map(Line::raw)
            .collect(),
    }
}

/// How far a popup can scroll (its last line at the bottom).
pub fn max_scroll(kind: PopupKind, log: &[Message], notes: &str, area: Rect) -> u16 {
    let visible = layout::popup_inner(area).height;
    let n = lines(kind, log, notes, Theme::PLAIN, area).len();
    u16::try_from(n).unwrap_or(u16::MAX).saturating_sub(visible)
}

/// `text` broken at spaces into lines of at most `width` characters (a
/// word longer than the width is cut).
pub fn wrap(text: &str, width: usize) -> Vec<String> {
    let width = width.max(4);
    let mut out = Vec::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        let mut word: String = word.to_string();
        loop {
            let need = line.chars().count() + usize::from(!line.is_empty()) + word.chars().count();
            if need <= width {
                if !line.is_empty() {
                    line.push(' ');
                }
                line.push_str(&word);
                break;
            }
            if !line.is_empty() {
                out.push(std::mem::take(&mut line));
                continue;
            }
            // A word wider than a line: cut it.
            let head: String = word.chars().take(width).collect();
            word = word.chars().skip(width).collect();
            out.push(head);
            if word.is_empty() {
                break;
            }
        }
    }
    if !line.is_empty() || out.is_empty() {
        out.push(line);
    }
    out
}

/// The key help: every key of the key map by context, then the `:`
/// commands, generated from the tables the App dispatches from.
pub fn help_lines(theme: Theme) -> Vec<Line<'static>> {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tui::app::Level;

    #[test]
    fn wrapping_keeps_every_word_within_the_width() {
        let text = "the nail of egg1 at t=1.3 holds its orientation: :nail pos instead";
        let lines = wrap(text, 20);
        assert!(lines.iter().all(|l| l.chars().count() <= 20), "{lines:?}");
        assert_eq!(lines.join(" "), text);
        assert_eq!(wrap("abcdefghij", 4), ["abcd", "efgh", "ij"]);
        assert_eq!(wrap("", 10), [""]);
    }

    #[test]
    fn the_log_scrolls_to_its_last_line() {
        let area = Rect::new(0, 0, 80, 24);
        let log: Vec<Message> = (0..40)
            .map(|k| Message {
                text: format!("message {k}"),
                level: Level::Info,
            })
            .collect();
        let visible = layout::popup_inner(area).height;
        assert_eq!(
            max_scroll(PopupKind::Messages, &log, "", area),
            40 - visible
        );
        assert_eq!(max_scroll(PopupKind::Messages, &log[..3], "", area), 0);
    }
}
