//! The key-script parser: whitespace-separated tokens in vim notation.
//!
//! * A plain character is that key: `h`, `L`, `:`, `[`.
//! * `<Name>` is a named key, with optional `C-` (Ctrl), `A-`/`M-` (Alt) and
//!   `S-` (Shift) prefixes: `<Left>`, `<S-Left>`, `<C-r>`, `<S-Tab>`,
//!   `<Enter>`/`<CR>`, `<Esc>`, `<Space>`, `<BS>`, `<lt>` (a literal `<`).
//! * `<LeftMouse:col,row>`, `<LeftDrag:col,row>`, `<LeftRelease:col,row>`,
//!   `<ScrollUp:col,row>`, `<ScrollDown:col,row>` are mouse events at a
//!   screen cell (0-based, at the script's screen size).
//! * A token types its characters one by one; whitespace between tokens
//!   types nothing (use `<Space>`).
//! * `:` opens a command line: everything after it up to `<Enter>` (or
//!   `<CR>`, `<Esc>`) is typed as written, spaces and `#` included, so
//!   `:t 0.7<Enter>` works as typed. A command line must end on its line.
//! * `#` at the start of a token comments out the rest of the line (type
//!   `#` itself as `<Hash>`).

use crate::tui::{Event, KEY_NAMES, Key, KeyCode, MOUSE_NAMES, Mouse};

/// One scripted input and where it was written (1-based line and column).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Step {
    pub event: Event,
    pub line: usize,
    pub col: usize,
}

impl From<Key> for Step {
    /// A key written nowhere in particular (line and column 0).
    fn from(key: Key) -> Step {
        Step {
            event: Event::Key(key),
            line: 0,
            col: 0,
        }
    }
}

/// A key script that could not be parsed; names the place (`origin:line:col`,
/// both 1-based) and what would be accepted.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum KeyScriptError {
    #[error(
        "{origin}:{line}:{col}: unknown key <{name}>; known names: {}",
        known_names()
    )]
    UnknownKey {
        origin: String,
        line: usize,
        col: usize,
        name: String,
    },
    #[error(
        "{origin}:{line}:{col}: `<` opens a key name that is never closed with `>`; type `<` itself as <lt>"
    )]
    Unclosed {
        origin: String,
        line: usize,
        col: usize,
    },
    #[error("{origin}:{line}:{col}: <{name}>: {problem}")]
    BadMouse {
        origin: String,
        line: usize,
        col: usize,
        name: String,
        problem: String,
    },
    #[error(
        "{origin}:{line}:{col}: the command line `{text}` is not ended on its line: end it with <Enter> (or <Esc> to abandon it)"
    )]
    UnendedCommand {
        origin: String,
        line: usize,
        col: usize,
        text: String,
    },
}

/// The names accepted inside `<...>`, for error messages.
pub fn known_names() -> String {
    let names: Vec<&str> = KEY_NAMES.iter().map(|(n, _)| *n).collect();
    let mouse: Vec<String> = MOUSE_NAMES
        .iter()
        .map(|(n, _)| format!("{n}:col,row"))
        .collect();
    format!(
        "{}, F1..F24, any single character; prefixes C- (Ctrl), A- or M- (Alt), S- (Shift); mouse: {}",
        names.join(", "),
        mouse.join(", ")
    )
}

/// Parse a key script into keys only; a mouse event in it is an error.
/// For scripts that are known to type (tests, benchmarks).
pub fn parse_keys(text: &str, origin: &str) -> Result<Vec<Key>, KeyScriptError> {
    let steps = parse_script(text, origin)?;
    let mut keys = Vec::with_capacity(steps.len());
    for s in steps {
        match s.event {
            Event::Key(k) => keys.push(k),
            other => {
                return Err(KeyScriptError::BadMouse {
                    origin: origin.to_string(),
                    line: s.line,
                    col: s.col,
                    name: format!("{other:?}"),
                    problem: "only keys are accepted here".into(),
                });
            }
        }
    }
    Ok(keys)
}

/// Parse a key script. `origin` names it in error messages (a file name).
pub fn parse_script(text: &str, origin: &str) -> Result<Vec<Step>, KeyScriptError> {
    let mut steps = Vec::new();
    for (line_index, line) in text.lines().enumerate() {
        let chars: Vec<char> = line.chars().collect();
        let at = |col: usize| (origin.to_string(), line_index + 1, col + 1);
        let mut i = 0;
        // Where the open command line's `:` is, while one is open.
        let mut command: Option<usize> = None;
        while i < chars.len() {
            if command.is_none() {
                if chars[i].is_whitespace() {
                    i += 1;
                    continue;
                }
                if chars[i] == '#' && (i == 0 || chars[i - 1].is_whitespace()) {
                    break;
                }
            }
            let (event, next) = if chars[i] == '<' {
                named(&chars, i, &at)?
            } else {
                (Event::Key(Key::char(chars[i])), i + 1)
            };
            steps.push(Step {
                event,
                line: line_index + 1,
                col: i + 1,
            });
            match event {
                Event::Key(k) if command.is_none() && k == Key::char(':') && chars[i] == ':' => {
                    command = Some(i);
                }
                Event::Key(k) if matches!(k.code, KeyCode::Enter | KeyCode::Esc) => {
                    command = None;
                }
                _ => {}
            }
            i = next;
        }
        if let Some(start) = command {
            let (origin, line, col) = at(start);
            return Err(KeyScriptError::UnendedCommand {
                origin,
                line,
                col,
                text: chars[start..].iter().collect(),
            });
        }
    }
    Ok(steps)
}

/// The `<...>` at `i`: the event and the index after the `>`.
fn named(
    chars: &[char],
    i: usize,
    at: &dyn Fn(usize) -> (String, usize, usize),
) -> Result<(Event, usize), KeyScriptError> {
    let close = chars[i + 1..]
        .iter()
        .position(|c| *c == '>' || c.is_whitespace())
        .map(|k| i + 1 + k);
    let Some(end) = close.filter(|&end| chars[end] == '>') else {
        let (origin, line, col) = at(i);
        return Err(KeyScriptError::Unclosed { origin, line, col });
    };
    let name: String = chars[i + 1..end].iter().collect();
    if let Some(mouse) = Mouse::from_name(&name) {
        return match mouse {
            Ok(m) => Ok((Event::Mouse(m), end + 1)),
            Err(problem) => {
                let (origin, line, col) = at(i);
                Err(KeyScriptError::BadMouse {
                    origin,
                    line,
                    col,
                    name,
                    problem,
                })
            }
        };
    }
    match Key::from_name(&name) {
        Some(key) => Ok((Event::Key(key), end + 1)),
        None => {
            let (origin, line, col) = at(i);
            Err(KeyScriptError::UnknownKey {
                origin,
                line,
                col,
                name,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tui::{KEYMAP, KeyCode};

    fn one(text: &str) -> Key {
        match parse_keys(text, "t").as_deref() {
            Ok([k]) => *k,
            other => panic!("{text}: {other:?}"),
        }
    }

    #[test]
    fn every_named_key_parses() {
        for (name, code) in KEY_NAMES {
            assert_eq!(one(&format!("<{name}>")).code, *code, "{name}");
        }
        assert_eq!(one("<S-Left>"), Key::new(KeyCode::Left).shift());
        assert_eq!(one("<C-r>"), Key::char('r').ctrl());
        assert_eq!(one("<S-Tab>"), Key::new(KeyCode::Tab).shift());
        assert_eq!(one("<CR>"), Key::new(KeyCode::Enter));
        assert_eq!(one("<A-h>"), Key::char('h').alt());
        assert_eq!(one("<F3>"), Key::new(KeyCode::F(3)));
        assert_eq!(one("<lt>"), Key::char('<'));
    }

    #[test]
    fn every_keymap_key_round_trips() {
        for b in KEYMAP {
            let printed = b.key.to_string();
            // `:` opens a command line, which must be ended.
            let keys = parse_keys(&format!("{printed}<Esc>"), "t").unwrap_or_default();
            assert_eq!(keys.first(), Some(&b.key), "{printed}");
        }
    }

    #[test]
    fn words_type_their_characters_and_comments_are_skipped() {
        let keys = parse_keys(
            "# a session\n5l  h\t:w<Space>a.toml<Enter> # save\n  <Esc>#not-a-comment",
            "s",
        )
        .unwrap_or_default();
        let text: Vec<String> = keys.iter().map(ToString::to_string).collect();
        assert_eq!(
            text.join(" "),
            "5 l h : w <Space> a . t o m l <Enter> <Esc> <Hash> n o t - a - c o m m e n t"
        );
    }

    #[test]
    fn unknown_names_give_line_and_column() {
        let err = parse_keys("l\nhh <Left>\nll <Lft>", "keys.txt").expect_err("unknown");
        let msg = err.to_string();
        assert!(
            msg.starts_with("keys.txt:3:4: unknown key <Lft>; known names: Left, Right"),
            "{msg}"
        );
        assert_eq!(
            err,
            KeyScriptError::UnknownKey {
                origin: "keys.txt".into(),
                line: 3,
                col: 4,
                name: "Lft".into()
            }
        );
    }

    #[test]
    fn unclosed_names_are_errors() {
        let err = parse_keys("  <Left", "k").expect_err("unclosed");
        assert_eq!(
            err,
            KeyScriptError::Unclosed {
                origin: "k".into(),
                line: 1,
                col: 3
            }
        );
        assert!(parse_keys("< Left>", "k").is_err());
        assert!(parse_keys("<>", "k").is_err());
    }

    #[test]
    fn nan_in_a_command_is_just_characters() {
        let keys = parse_keys(":set<Space>tol<Space>nan<CR>", "k").unwrap_or_default();
        assert_eq!(keys.len(), 1 + 3 + 1 + 3 + 1 + 3 + 1);
    }

    #[test]
    fn a_command_line_is_typed_as_written_up_to_enter() {
        let keys = parse_keys(":t 0.7<Enter> l :w my scene.toml # not a comment<CR>", "k")
            .unwrap_or_default();
        let text: String = keys.iter().map(ToString::to_string).collect();
        assert_eq!(
            text,
            ":t<Space>0.7<Enter>l:w<Space>my<Space>scene.toml<Space><Hash><Space>not<Space>a<Space>comment<Enter>"
        );
        let err = parse_keys("l\n  :t 0.7  # forgot enter\nl", "k.keys").expect_err("unended");
        assert_eq!(
            err.to_string(),
            "k.keys:2:3: the command line `:t 0.7  # forgot enter` is not ended on its line: end it with <Enter> (or <Esc> to abandon it)"
        );
        // <Esc> abandons a command line; `<lt>` and named keys still work in one.
        assert!(parse_keys(":nail<Esc> :set<Space>tol 1e-9<CR>", "k").is_ok());
    }

    #[test]
    fn mouse_events_have_a_notation_with_their_place() {
        let steps = parse_script("l\n  <LeftMouse:10,5> <LeftDrag:12,5>", "m").unwrap_or_default();
        assert_eq!(steps.len(), 3);
        assert_eq!((steps[1].line, steps[1].col), (2, 3));
        assert_eq!(
            steps[2].event,
            Event::Mouse(Mouse {
                kind: crate::tui::MouseKind::Drag,
                col: 12,
                row: 5
            })
        );
        let err = parse_script("<LeftDrag:1>", "m").expect_err("malformed");
        assert!(
            err.to_string().starts_with("m:1:1: <LeftDrag:1>: expected"),
            "{err}"
        );
        assert!(parse_keys("<LeftMouse:1,1>", "m").is_err());
    }

    #[test]
    fn empty_and_blank_scripts_have_no_keys() {
        assert_eq!(parse_keys("", "k"), Ok(vec![]));
        assert_eq!(parse_keys("  \n# only\n\t\n", "k"), Ok(vec![]));
    }
}
