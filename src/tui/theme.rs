//! Colours and emphasis. Only the 16 basic terminal colours are used, and
//! with `NO_COLOR` set (<https://no-color.org>) no colour at all: emphasis
//! then comes from modifiers (bold, dim, reversed) alone.

use ratatui::style::{Color, Modifier, Style};

/// How the screen is styled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Theme {
    /// Whether colours may be used.
    pub color: bool,
}

impl Default for Theme {
    fn default() -> Self {
        Theme::COLOR
    }
}

/// Colours of traced paths, by body index (cycled).
const BODY_COLORS: [Color; 6] = [
    Color::Cyan,
    Color::Yellow,
    Color::Magenta,
    Color::Green,
    Color::LightBlue,
    Color::LightRed,
];

impl Theme {
    pub const COLOR: Theme = Theme { color: true };
    pub const PLAIN: Theme = Theme { color: false };

    /// Colour unless the `NO_COLOR` environment variable is set to a
    /// non-empty value.
    pub fn from_env() -> Theme {
        Theme {
            color: std::env::var_os("NO_COLOR").is_none_or(|v| v.is_empty()),
        }
    }

    /// `c`, or the terminal's default colour without colour.
    pub fn paint(self, c: Color) -> Color {
        if self.color { c } else { Color::Reset }
    }

    fn fg(self, c: Color) -> Style {
        if self.color {
            Style::new().fg(c)
        } else {
            Style::new()
        }
    }

    /// The colour of body `i`'s paths.
    pub fn body(self, i: usize) -> Color {
        self.paint(BODY_COLORS[i % BODY_COLORS.len()])
    }

    /// Obstacle outlines.
    pub fn obstacle(self) -> Color {
        self.paint(Color::Gray)
    }

    /// Outlines of the bodies that are not selected.
    pub fn other_body(self) -> Color {
        self.paint(Color::DarkGray)
    }

    /// The selected body's outline.
    pub fn selected_body(self) -> Color {
        self.paint(Color::White)
    }

    /// The motion before the last edit (drawn dotted in every mode).
    pub fn ghost(self) -> Color {
        self.paint(Color::DarkGray)
    }

    /// An explored alternative's traces.
    pub fn alternative(self) -> Color {
        self.paint(Color::LightMagenta)
    }

    /// Constraint targets on the plot.
    pub fn target(self) -> Style {
        self.fg(Color::LightMagenta).add_modifier(Modifier::BOLD)
    }

    /// The cells the selected body's outline passes through: bold and
    /// reversed, so it stands out without colour too.
    pub fn selected_cells(self) -> Style {
        Style::new().add_modifier(Modifier::BOLD | Modifier::REVERSED)
    }

    /// Collision event marks.
    pub fn event(self) -> Style {
        self.fg(Color::LightRed).add_modifier(Modifier::BOLD)
    }

    /// Block titles and headings.
    pub fn title(self) -> Style {
        self.fg(Color::White).add_modifier(Modifier::BOLD)
    }

    /// Less important text.
    pub fn dim(self) -> Style {
        if self.color {
            Style::new().fg(Color::DarkGray)
        } else {
            Style::new().add_modifier(Modifier::DIM)
        }
    }

    /// The selected row and the mode badge.
    pub fn selected(self) -> Style {
        Style::new().add_modifier(Modifier::REVERSED)
    }

    /// A value that just changed.
    pub fn changed(self) -> Style {
        self.fg(Color::Yellow).add_modifier(Modifier::BOLD)
    }

    /// Error messages.
    pub fn error(self) -> Style {
        self.fg(Color::LightRed).add_modifier(Modifier::BOLD)
    }

    /// Informational messages.
    pub fn info(self) -> Style {
        self.fg(Color::LightGreen)
    }

    /// Keys in the hint line and help.
    pub fn key(self) -> Style {
        self.fg(Color::LightCyan).add_modifier(Modifier::BOLD)
    }

    /// Borders.
    pub fn border(self) -> Style {
        self.fg(Color::DarkGray)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plain_theme_has_no_colours() {
        let t = Theme::PLAIN;
        for s in [
            t.event(),
            t.title(),
            t.dim(),
            t.selected(),
            t.changed(),
            t.error(),
            t.info(),
            t.key(),
            t.border(),
        ] {
            assert_eq!((s.fg, s.bg), (None, None), "{s:?}");
        }
        for c in [
            t.body(0),
            t.body(7),
            t.obstacle(),
            t.other_body(),
            t.selected_body(),
        ] {
            assert_eq!(c, Color::Reset);
        }
    }

    #[test]
    fn colours_are_the_basic_sixteen() {
        let t = Theme::COLOR;
        let styles = [
            t.event(),
            t.title(),
            t.dim(),
            t.changed(),
            t.error(),
            t.info(),
            t.key(),
            t.border(),
        ];
        let colors = styles
            .iter()
            .filter_map(|s| s.fg)
            .chain((0..6).map(|i| t.body(i)));
        for c in colors {
            assert!(!matches!(c, Color::Rgb(..) | Color::Indexed(_)), "{c:?}");
        }
    }
}
