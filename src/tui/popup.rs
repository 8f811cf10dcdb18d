//! What the popups say: the key help (`?`), the message log (`M`,
//! `:messages`), the scene's notes (`:notes`), the Jacobian (`I`) and the
//! measured accuracy settings (`A`, [`accuracy`]), as lines wrapped to the
//! popup's width. The App scrolls them and the widget draws them, both from
//! here, so the two always agree on how long a popup is.

use super::app::{Measurements, Message};
use super::command::{COMMAND_NOTES, usage_rows};
use super::format::{num, short_control_name};
use super::keymap::{Context, help_rows};
use super::layout;
use super::theme::Theme;
use crate::view::Sensitivity;
use ratatui::layout::Rect;
use ratatui::text::{Line, Span};

pub(crate) mod accuracy;

/// Which popup is open.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PopupKind {
    /// Every key by context, then the `:` commands.
    Help,
    /// Every message since the editor opened, oldest first.
    Messages,
    /// The scene's notes.
    Notes,
    /// How each free control moves the selected body now.
    Jacobian,
    /// Accuracy settings around the current one: error and cost.
    Accuracy,
}

/// What the popups show besides the tables: the App's message log, the
/// scene's notes, and the Jacobian columns taken when the popup opened.
#[derive(Debug, Clone, Copy)]
pub struct PopupData<'a> {
    pub log: &'a [Message],
    pub notes: &'a str,
    pub sensitivity: Option<&'a Result<Sensitivity, String>>,
    /// The settings `:accuracy` measured.
    pub accuracy: Option<&'a Measurements>,
}

impl PopupKind {
    /// The popup's title.
    pub fn title(self) -> &'static str {
        match self {
            PopupKind::Help => " keys: j/k scroll, ? or Esc closes ",
            PopupKind::Messages => " messages: j/k scroll, Esc closes ",
            PopupKind::Notes => " scene notes: j/k scroll, Esc closes ",
            PopupKind::Jacobian => " how the free controls move the body: j/k, Esc ",
            PopupKind::Accuracy => " accuracy: j/k choose, Enter picks, Esc closes ",
        }
    }
}

/// Widest keys column of the help.
const MAX_KEYS_WIDTH: usize = 26;

/// What a popup shows on a screen of `area`.
pub fn lines(kind: PopupKind, data: PopupData, theme: Theme, area: Rect) -> Vec<Line<'static>> {
    let width = usize::from(layout::popup_inner(area).width.max(1));
    let (log, notes) = (data.log, data.notes);
    match kind {
        PopupKind::Jacobian => match data.sensitivity {
            Some(Ok(s)) => sensitivity_lines(s, theme, width),
            Some(Err(why)) => wrap(why, width).into_iter().map(Line::raw).collect(),
            None => vec![Line::styled("nothing to show", theme.dim())],
        },
        PopupKind::Accuracy => match data.accuracy {
            Some(m) => accuracy::lines(m, theme, width),
            None => vec![Line::styled("nothing measured", theme.dim())],
        },
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

/// The Jacobian popup: a row per free control, how far a unit of it moves
/// the body (m) and turns it (degrees), each with a bar scaled to the
/// column's largest.
fn sensitivity_lines(s: &Sensitivity, theme: Theme, width: usize) -> Vec<Line<'static>> {
    let name_w = 18.min(width / 3);
    let bar_w = width.saturating_sub(name_w + 2 * 10 + 4) / 2;
    let max_x = s.rows.iter().map(|r| r.position.norm()).fold(0.0, f64::max);
    let max_r = s
        .rows
        .iter()
        .map(|r| r.orientation.norm())
        .fold(0.0, f64::max);
    let bar = |v: f64, max: f64| {
        let n = if max > 0.0 && v.is_finite() {
            ((v / max) * bar_w as f64).round() as usize
        } else {
            0
        };
        format!("{:<bar_w$}", "█".repeat(n.min(bar_w)))
    };
    let mut out = vec![
        Line::styled(
            format!(
                "{} at t={}: per unit of each free control",
                s.body,
                num(s.t, 7)
            ),
            theme.title(),
        ),
        Line::styled(
            format!(
                "{:<name_w$} {:>9} {:<bar_w$} {:>9} {:<bar_w$}",
                "control", "|∂x| m", "", "|∂θ| °", ""
            ),
            theme.dim(),
        ),
    ];
    for r in &s.rows {
        let (dx, dr) = (r.position.norm(), r.orientation.norm().to_degrees());
        out.push(Line::from(vec![
            Span::raw(format!(
                "{:<name_w$} ",
                short_control_name(&r.control, name_w)
            )),
            Span::raw(format!("{:>9} ", num(dx, 9))),
            Span::styled(bar(dx, max_x), theme.info()),
            Span::raw(format!(" {:>9} ", num(dr, 9))),
            Span::styled(bar(dr, max_r.to_degrees()), theme.changed()),
        ]));
    }
    out
}

/// How far a popup can scroll (its last line at the bottom).
pub fn max_scroll(kind: PopupKind, data: PopupData, area: Rect) -> u16 {
    let visible = layout::popup_inner(area).height;
    let n = lines(kind, data, Theme::PLAIN, area).len();
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
        let data = |log| PopupData {
            log,
            notes: "",
            sensitivity: None,
            accuracy: None,
        };
        assert_eq!(
            max_scroll(PopupKind::Messages, data(&log), area),
            40 - visible
        );
        assert_eq!(max_scroll(PopupKind::Messages, data(&log[..3]), area), 0);
    }
}
