//! The key-script parser: whitespace-separated tokens in vim notation.
//!
//! * A plain character is that key: `h`, `L`, `:`, `[`.
//! * `<Name>` is a named key, with optional `C-` (Ctrl), `A-`/`M-` (Alt) and
//!   `S-` (Shift) prefixes: `<Left>`, `<S-Left>`, `<C-r>`, `<S-Tab>`,
//!   `<Enter>`/`<CR>`, `<Esc>`, `<Space>`, `<BS>`, `<lt>` (a literal `<`).
//! * A token types its characters one by one, so `:w<Space>out.toml<Enter>`
//!   is a whole command; whitespace between tokens types nothing (use
//!   `<Space>`).
//! * `#` at the start of a token comments out the rest of the line (type
//!   `#` itself as `<Hash>`).

use crate::tui::{KEY_NAMES, Key};

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
}

/// The names accepted inside `<...>`, for error messages.
pub fn known_names() -> String {
    let names: Vec<&str> = KEY_NAMES.iter().map(|(n, _)| *n).collect();
    format!(
        "{}, F1..F24, any single character; prefixes C- (Ctrl), A- or M- (Alt), S- (Shift)",
        names.join(", ")
    )
}

/// Parse a key script. `origin` names it in error messages (a file name).
pub fn parse_keys(text: &str, origin: &str) -> Result<Vec<Key>, KeyScriptError> {
    let mut keys = Vec::new();
    for (line_index, line) in text.lines().enumerate() {
        let chars: Vec<char> = line.chars().collect();
        let mut i = 0;
        while i < chars.len() {
            if chars[i].is_whitespace() {
                i += 1;
                continue;
            }
            if chars[i] == '#' {
                break;
            }
            // One token: up to the next whitespace.
            while i < chars.len() && !chars[i].is_whitespace() {
                if chars[i] != '<' {
                    keys.push(Key::char(chars[i]));
                    i += 1;
                    continue;
                }
                let at = (line_index + 1, i + 1);
                let close = chars[i + 1..]
                    .iter()
                    .position(|c| *c == '>' || c.is_whitespace())
                    .map(|k| i + 1 + k);
                match close {
                    Some(end) if chars[end] == '>' => {
                        let name: String = chars[i + 1..end].iter().collect();
                        match Key::from_name(&name) {
                            Some(key) => keys.push(key),
                            None => {
                                return Err(KeyScriptError::UnknownKey {
                                    origin: origin.to_string(),
                                    line: at.0,
                                    col: at.1,
                                    name,
                                });
                            }
                        }
                        i = end + 1;
                    }
                    _ => {
                        return Err(KeyScriptError::Unclosed {
                            origin: origin.to_string(),
                            line: at.0,
                            col: at.1,
                        });
                    }
                }
            }
        }
    }
    Ok(keys)
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
            assert_eq!(one(&printed), b.key, "{printed}");
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
    fn empty_and_blank_scripts_have_no_keys() {
        assert_eq!(parse_keys("", "k"), Ok(vec![]));
        assert_eq!(parse_keys("  \n# only\n\t\n", "k"), Ok(vec![]));
    }
}
