//! A key press as the editor sees it. Terminal events and key-script tokens
//! both become a [`Key`], so the keymap, the App and the headless runner see
//! exactly the same input.
//!
//! Keys print in vim notation (`h`, `<S-Left>`, `<C-r>`, `<lt>`), the same
//! notation key scripts are written in, so `parse(key.to_string())` gives the
//! key back.

use std::fmt;

/// Which key, without modifiers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum KeyCode {
    /// A printable character. Shift is folded into the character (`H`, `{`).
    Char(char),
    Left,
    Right,
    Up,
    Down,
    /// Tab; with [`Mods::shift`] it is back-tab (`<S-Tab>`).
    Tab,
    Enter,
    Esc,
    Backspace,
    Delete,
    Insert,
    Home,
    End,
    PageUp,
    PageDown,
    /// Function key `F1`..`F24`.
    F(u8),
}

/// Modifier keys held with a [`KeyCode`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Default)]
pub struct Mods {
    pub ctrl: bool,
    pub alt: bool,
    /// Only meaningful for non-character keys; a shifted character is the
    /// character itself (`H`, not `<S-h>`).
    pub shift: bool,
}

/// One key press.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct Key {
    pub code: KeyCode,
    pub mods: Mods,
}

/// Names accepted inside `<...>`, case-insensitively. The first name of each
/// key is the one it prints as.
pub const KEY_NAMES: &[(&str, KeyCode)] = &[
    ("Left", KeyCode::Left),
    ("Right", KeyCode::Right),
    ("Up", KeyCode::Up),
    ("Down", KeyCode::Down),
    ("Tab", KeyCode::Tab),
    ("Enter", KeyCode::Enter),
    ("CR", KeyCode::Enter),
    ("Return", KeyCode::Enter),
    ("Esc", KeyCode::Esc),
    ("Space", KeyCode::Char(' ')),
    ("lt", KeyCode::Char('<')),
    ("Hash", KeyCode::Char('#')),
    ("BS", KeyCode::Backspace),
    ("Del", KeyCode::Delete),
    ("Insert", KeyCode::Insert),
    ("Home", KeyCode::Home),
    ("End", KeyCode::End),
    ("PageUp", KeyCode::PageUp),
    ("PageDown", KeyCode::PageDown),
];

impl Key {
    /// A plain key.
    pub const fn new(code: KeyCode) -> Key {
        Key {
            code,
            mods: Mods {
                ctrl: false,
                alt: false,
                shift: false,
            },
        }
    }

    /// A plain character key.
    pub const fn char(c: char) -> Key {
        Key::new(KeyCode::Char(c))
    }

    /// The same key with Ctrl held.
    pub const fn ctrl(mut self) -> Key {
        self.mods.ctrl = true;
        self
    }

    /// The same key with Alt (Meta) held.
    pub const fn alt(mut self) -> Key {
        self.mods.alt = true;
        self
    }

    /// The same key with Shift held (use for non-character keys).
    pub const fn shift(mut self) -> Key {
        self.mods.shift = true;
        self
    }

    /// The canonical form: Shift folded into characters, Ctrl+letter in lower
    /// case. Terminals differ in how they report these; the keymap only ever
    /// sees normalised keys.
    pub fn normalized(mut self) -> Key {
        if let KeyCode::Char(c) = self.code {
            self.mods.shift = false;
            if self.mods.ctrl && c.is_ascii_uppercase() {
                self.code = KeyCode::Char(c.to_ascii_lowercase());
            }
        }
        self
    }

    /// The character this key types into a text field, if it types one.
    pub fn typed_char(self) -> Option<char> {
        match self.code {
            KeyCode::Char(c) if !self.mods.ctrl && !self.mods.alt && !c.is_control() => Some(c),
            _ => None,
        }
    }

    /// The key as reported by crossterm, or `None` for key releases and keys
    /// the editor has no name for.
    pub fn from_crossterm(ev: ratatui::crossterm::event::KeyEvent) -> Option<Key> {
        use ratatui::crossterm::event::{KeyCode as C, KeyEventKind, KeyModifiers as M};
        if ev.kind == KeyEventKind::Release {
            return None;
        }
        let mut shift = ev.modifiers.contains(M::SHIFT);
        let code = match ev.code {
            C::Char(c) => KeyCode::Char(c),
            C::Left => KeyCode::Left,
            C::Right => KeyCode::Right,
            C::Up => KeyCode::Up,
            C::Down => KeyCode::Down,
            C::Tab => KeyCode::Tab,
            C::BackTab => {
                shift = true;
                KeyCode::Tab
            }
            C::Enter => KeyCode::Enter,
            C::Esc => KeyCode::Esc,
            C::Backspace => KeyCode::Backspace,
            C::Delete => KeyCode::Delete,
            C::Insert => KeyCode::Insert,
            C::Home => KeyCode::Home,
            C::End => KeyCode::End,
            C::PageUp => KeyCode::PageUp,
            C::PageDown => KeyCode::PageDown,
            C::F(n) => KeyCode::F(n),
            _ => return None,
        };
        let mods = Mods {
            ctrl: ev.modifiers.contains(M::CONTROL),
            alt: ev.modifiers.contains(M::ALT) || ev.modifiers.contains(M::META),
            shift,
        };
        Some(Key { code, mods }.normalized())
    }

    /// Parse the inside of a `<...>` name: optional `C-`, `A-`/`M-`, `S-`
    /// prefixes, then a key name or a single character.
    pub fn from_name(name: &str) -> Option<Key> {
        let mut mods = Mods::default();
        let mut rest = name;
        loop {
            let mut chars = rest.chars();
            match (chars.next(), chars.next(), chars.next()) {
                (Some(m), Some('-'), Some(_)) => {
                    match m.to_ascii_lowercase() {
                        'c' => mods.ctrl = true,
                        'a' | 'm' => mods.alt = true,
                        's' => mods.shift = true,
                        _ => break,
                    }
                    rest = &rest[2..];
                }
                _ => break,
            }
        }
        let mut chars = rest.chars();
        let code = match (chars.next(), chars.next()) {
            (Some(c), None) => {
                let c = if mods.shift && !mods.ctrl {
                    c.to_uppercase().next().unwrap_or(c)
                } else {
                    c
                };
                KeyCode::Char(c)
            }
            _ => lookup_name(rest)?,
        };
        Some(Key { code, mods }.normalized())
    }
}

fn lookup_name(name: &str) -> Option<KeyCode> {
    if let Some((_, code)) = KEY_NAMES.iter().find(|(n, _)| n.eq_ignore_ascii_case(name)) {
        return Some(*code);
    }
    let digits = name.strip_prefix('F').or_else(|| name.strip_prefix('f'))?;
    match digits.parse::<u8>() {
        Ok(n @ 1..=24) => Some(KeyCode::F(n)),
        _ => None,
    }
}

fn code_name(code: KeyCode) -> Option<String> {
    if let KeyCode::F(n) = code {
        return Some(format!("F{n}"));
    }
    KEY_NAMES
        .iter()
        .find(|(_, c)| *c == code)
        .map(|(n, _)| (*n).to_string())
}

impl fmt::Display for Key {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Key { code, mods } = *self;
        let named = code_name(code);
        let plain = !mods.ctrl && !mods.alt && !mods.shift;
        if let (true, None, KeyCode::Char(c)) = (plain, &named, code) {
            return write!(f, "{c}");
        }
        f.write_str("<")?;
        if mods.ctrl {
            f.write_str("C-")?;
        }
        if mods.alt {
            f.write_str("A-")?;
        }
        if mods.shift {
            f.write_str("S-")?;
        }
        match (named, code) {
            (Some(n), _) => f.write_str(&n)?,
            (None, KeyCode::Char(c)) => write!(f, "{c}")?,
            (None, _) => f.write_str("?")?,
        }
        f.write_str(">")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ratatui::crossterm::event::{KeyCode as C, KeyEvent, KeyEventKind, KeyModifiers as M};

    #[test]
    fn prints_in_vim_notation() {
        assert_eq!(Key::char('h').to_string(), "h");
        assert_eq!(Key::char('<').to_string(), "<lt>");
        assert_eq!(Key::char(' ').to_string(), "<Space>");
        assert_eq!(Key::new(KeyCode::Left).shift().to_string(), "<S-Left>");
        assert_eq!(Key::char('r').ctrl().to_string(), "<C-r>");
        assert_eq!(Key::new(KeyCode::Tab).shift().to_string(), "<S-Tab>");
        assert_eq!(Key::char('h').alt().to_string(), "<A-h>");
        assert_eq!(Key::new(KeyCode::F(5)).to_string(), "<F5>");
    }

    #[test]
    fn names_parse_with_modifiers_in_any_case() {
        assert_eq!(Key::from_name("left"), Some(Key::new(KeyCode::Left)));
        assert_eq!(
            Key::from_name("S-Left"),
            Some(Key::new(KeyCode::Left).shift())
        );
        assert_eq!(Key::from_name("C-R"), Some(Key::char('r').ctrl()));
        assert_eq!(Key::from_name("S-h"), Some(Key::char('H')));
        assert_eq!(Key::from_name("M-j"), Some(Key::char('j').alt()));
        assert_eq!(Key::from_name("C--"), Some(Key::char('-').ctrl()));
        assert_eq!(Key::from_name("CR"), Some(Key::new(KeyCode::Enter)));
        assert_eq!(Key::from_name("f12"), Some(Key::new(KeyCode::F(12))));
        assert_eq!(Key::from_name("F25"), None);
        assert_eq!(Key::from_name("Lft"), None);
        assert_eq!(Key::from_name(""), None);
    }

    #[test]
    fn crossterm_shifted_characters_and_backtab_normalise() {
        let ev = |code, mods| KeyEvent::new(code, mods);
        assert_eq!(
            Key::from_crossterm(ev(C::Char('H'), M::SHIFT)),
            Some(Key::char('H'))
        );
        assert_eq!(
            Key::from_crossterm(ev(C::BackTab, M::SHIFT)),
            Some(Key::new(KeyCode::Tab).shift())
        );
        assert_eq!(
            Key::from_crossterm(ev(C::Char('R'), M::CONTROL | M::SHIFT)),
            Some(Key::char('r').ctrl())
        );
        assert_eq!(
            Key::from_crossterm(ev(C::Left, M::CONTROL)),
            Some(Key::new(KeyCode::Left).ctrl())
        );
        let mut release = ev(C::Char('h'), M::NONE);
        release.kind = KeyEventKind::Release;
        assert_eq!(Key::from_crossterm(release), None);
    }
}
