//! A mouse event as the editor sees it: the left button pressed, dragged
//! or released, or the wheel turned, at a screen cell. Terminal events and
//! key-script tokens (`<LeftMouse:12,5>`) both become a [`Mouse`], so
//! mouse editing is tested headless exactly as it runs.

use std::fmt;

/// What the mouse did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MouseKind {
    /// The left button went down.
    Press,
    /// The mouse moved with the left button held.
    Drag,
    /// The left button came up.
    Release,
    /// The wheel turned away from the user.
    ScrollUp,
    /// The wheel turned toward the user.
    ScrollDown,
}

/// Script names of the kinds, as `<Name:col,row>`.
pub const MOUSE_NAMES: &[(&str, MouseKind)] = &[
    ("LeftMouse", MouseKind::Press),
    ("LeftDrag", MouseKind::Drag),
    ("LeftRelease", MouseKind::Release),
    ("ScrollUp", MouseKind::ScrollUp),
    ("ScrollDown", MouseKind::ScrollDown),
];

/// One mouse event at screen cell (`col`, `row`), 0-based from the top left.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct Mouse {
    pub kind: MouseKind,
    pub col: u16,
    pub row: u16,
}

impl Mouse {
    /// Parse the inside of `<...>`, e.g. `LeftDrag:30,12`. `None` if it is
    /// not mouse notation at all; `Some(Err(why))` if it is, but malformed.
    pub fn from_name(name: &str) -> Option<Result<Mouse, String>> {
        let (kind_name, at) = name.split_once(':')?;
        let kind = MOUSE_NAMES
            .iter()
            .find(|(n, _)| n.eq_ignore_ascii_case(kind_name))
            .map(|(_, k)| *k)?;
        let cell = at.split_once(',').and_then(|(c, r)| {
            Some((c.trim().parse::<u16>().ok()?, r.trim().parse::<u16>().ok()?))
        });
        Some(match cell {
            Some((col, row)) => Ok(Mouse { kind, col, row }),
            None => Err(format!(
                "expected <{kind_name}:col,row> with whole numbers of screen cells, e.g. <{kind_name}:10,5>"
            )),
        })
    }

    /// From a crossterm event; `None` for buttons and moves the editor
    /// does not use (right and middle buttons, moves without a button).
    pub fn from_crossterm(e: ratatui::crossterm::event::MouseEvent) -> Option<Mouse> {
        use ratatui::crossterm::event::{MouseButton, MouseEventKind as K};
        let kind = match e.kind {
            K::Down(MouseButton::Left) => MouseKind::Press,
            K::Drag(MouseButton::Left) => MouseKind::Drag,
            K::Up(MouseButton::Left) => MouseKind::Release,
            K::ScrollUp => MouseKind::ScrollUp,
            K::ScrollDown => MouseKind::ScrollDown,
            _ => return None,
        };
        Some(Mouse {
            kind,
            col: e.column,
            row: e.row,
        })
    }
}

impl fmt::Display for Mouse {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = MOUSE_NAMES
            .iter()
            .find(|(_, k)| *k == self.kind)
            .map_or("LeftMouse", |(n, _)| n);
        write!(f, "<{name}:{},{}>", self.col, self.row)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_kind_round_trips_through_its_notation() {
        for (_, kind) in MOUSE_NAMES {
            let m = Mouse {
                kind: *kind,
                col: 12,
                row: 7,
            };
            let text = m.to_string();
            let inner = &text[1..text.len() - 1];
            assert_eq!(Mouse::from_name(inner), Some(Ok(m)), "{text}");
        }
    }

    #[test]
    fn malformed_cells_are_explained_and_other_names_are_not_mouse() {
        assert!(matches!(Mouse::from_name("LeftDrag:3"), Some(Err(_))));
        assert!(matches!(Mouse::from_name("LeftDrag:-1,2"), Some(Err(_))));
        assert_eq!(Mouse::from_name("Left"), None);
        assert_eq!(Mouse::from_name("Wheel:1,2"), None);
    }
}
