//! Located reading of a parsed TOML document: every value keeps its byte
//! span, and every error names `origin:line:column`, the field, the value as
//! written in the file, and how to fix it.
//!
//! Messages have the shape `origin:line:col: <what is wrong>: <value>; <fix>`
//! (or `origin:line:col: <what is wrong>; <fix>` when there is no value, as
//! for a missing field). They are part of the user interface and pinned by
//! `tests/invalid_scenes/`, so change them deliberately.
use super::super::model::Block;
use super::SceneError;
use crate::math::Vec3;
use std::ops::Range;
use toml::Spanned;
use toml::de::{DeArray, DeTable, DeValue};

/// A located TOML value.
pub(super) type Value<'i> = Spanned<DeValue<'i>>;

/// A string and where it was written.
pub(super) type Located<'a> = (&'a str, Range<usize>);

/// Longest value quoted in a message (characters); longer ones are elided.
const MAX_QUOTE: usize = 60;

/// The scene text and the name it is reported under.
pub(super) struct Source<'a> {
    pub text: &'a str,
    pub origin: &'a str,
}

impl Source<'_> {
    /// 1-based line and column (in characters) of a byte offset.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let before = &self.text[..offset];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let col = before[line_start..].chars().count() + 1;
        (line, col)
    }

    /// `origin:line:col` of a byte offset.
    pub fn at(&self, offset: usize) -> String {
        let (line, col) = self.line_col(offset);
        format!("{}:{line}:{col}", self.origin)
    }

    /// The text of a span as the user wrote it, on one line (comments
    /// dropped, whitespace runs collapsed) and elided when long.
    pub fn quote(&self, span: &Range<usize>) -> String {
        let raw = self.text.get(span.clone()).unwrap_or("");
        let mut out = String::new();
        for line in raw.lines() {
            let code = strip_comment(line).trim();
            if code.is_empty() {
                continue;
            }
            if !out.is_empty() && !out.ends_with(['[', '{']) && !code.starts_with([']', '}']) {
                out.push(' ');
            }
            out.push_str(code);
        }
        let mut collapsed = String::with_capacity(out.len());
        let mut in_space = false;
        for c in out.chars() {
            if hidden(c) && !c.is_whitespace() {
                // Never echo a character that hides or reorders text (or
                // drives the terminal): show its code point.
                collapsed.push_str(&format!("<U+{:04X}>", u32::from(c)));
                in_space = false;
            } else if c.is_whitespace() {
                if !in_space {
                    collapsed.push(' ');
                }
                in_space = true;
            } else {
                collapsed.push(c);
                in_space = false;
            }
        }
        if collapsed.chars().count() > MAX_QUOTE {
            let mut short: String = collapsed.chars().take(MAX_QUOTE - 3).collect();
            short.push_str("...");
            short
        } else {
            collapsed
        }
    }

    /// `origin:line:col: what: value; fix`.
    pub fn error(&self, span: &Range<usize>, what: &str, value: &str, fix: &str) -> SceneError {
        SceneError::Invalid(format!("{}: {what}: {value}; {fix}", self.at(span.start)))
    }

    /// `origin:line:col: what; fix` (no value to quote).
    pub fn error_bare(&self, span: &Range<usize>, what: &str, fix: &str) -> SceneError {
        SceneError::Invalid(format!("{}: {what}; {fix}", self.at(span.start)))
    }

    /// An error quoting the value at `span` as written.
    pub fn error_at(&self, span: &Range<usize>, what: &str, fix: &str) -> SceneError {
        self.error(span, what, &self.quote(span), fix)
    }
}

/// Whether `c` is a control character or one that is invisible or
/// reorders text (zero-width spaces and joiners, bidirectional controls,
/// the byte-order mark, the soft hyphen): it would hide what a name says
/// or, sent to a terminal, act on it.
pub(super) fn hidden(c: char) -> bool {
    c.is_control()
        || matches!(
            u32::from(c),
            0x00AD
                | 0x061C
                | 0x180E
                | 0x200B..=0x200F
                | 0x202A..=0x202E
                | 0x2060..=0x2064
                | 0x2066..=0x206F
                | 0xFEFF
                | 0xFFF9..=0xFFFB
        )
}

/// A line without its trailing `# comment` (ignoring `#` inside strings).
fn strip_comment(line: &str) -> &str {
    let mut quote: Option<char> = None;
    let mut escaped = false;
    for (i, c) in line.char_indices() {
        match quote {
            Some(q) => {
                if escaped {
                    escaped = false;
                } else if c == '\\' && q == '"' {
                    escaped = true;
                } else if c == q {
                    quote = None;
                }
            }
            None => match c {
                '"' | '\'' => quote = Some(c),
                '#' => return &line[..i],
                _ => {}
            },
        }
    }
    line
}

/// Levenshtein distance, for "did you mean" suggestions.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != *cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

/// `did you mean x? ` for the closest candidate within two edits, else "".
pub(super) fn suggestion(word: &str, candidates: &[&str]) -> String {
    candidates
        .iter()
        .map(|c| (edit_distance(word, c), *c))
        .filter(|(d, c)| *d <= 2 && *d < c.len())
        .min_by_key(|(d, _)| *d)
        .map(|(_, c)| format!("did you mean {c}? "))
        .unwrap_or_default()
}

/// A bound a number must satisfy.
#[derive(Debug, Clone, Copy)]
pub(super) enum Bound {
    /// `> 0`.
    Positive,
    /// `≥ 0`.
    NonNegative,
    /// In `[0, 1]`.
    Unit,
    /// `> 0` and `≤ max`.
    PositiveAtMost(f64),
}

impl Bound {
    fn holds(self, x: f64) -> bool {
        match self {
            Bound::Positive => x > 0.0,
            Bound::NonNegative => x >= 0.0,
            Bound::Unit => (0.0..=1.0).contains(&x),
            Bound::PositiveAtMost(max) => x > 0.0 && x <= max,
        }
    }

    fn describe(self) -> String {
        match self {
            Bound::Positive => "greater than 0".into(),
            Bound::NonNegative => "0 or greater".into(),
            Bound::Unit => "between 0 and 1".into(),
            Bound::PositiveAtMost(max) => format!("greater than 0 and at most {max:e}"),
        }
    }
}

/// A table being read: its entries, its location, and how to name its fields
/// in messages (`body "egg1" field shape.radius`).
#[derive(Clone)]
pub(super) struct Table<'a, 'i> {
    pub src: &'a Source<'a>,
    pub map: &'a DeTable<'i>,
    /// Where the table starts (its header, its `{`, or the file start).
    pub span: Range<usize>,
    /// Who owns the table: `scene`, `accuracy`, `body "egg1"`, `body #2`.
    pub owner: &'a str,
    /// Dotted path of the table inside its owner, with a trailing dot
    /// (`shape.parts[0].shape.`), or empty.
    pub path: &'a str,
}

impl<'a, 'i> Table<'a, 'i> {
    /// How messages name a field of this table.
    pub fn field(&self, key: &str) -> String {
        format!("{} field {}{key}", self.owner, self.path)
    }

    /// How messages name this table.
    pub fn name(&self) -> String {
        if self.path.is_empty() {
            self.owner.to_string()
        } else {
            format!("{} field {}", self.owner, self.path.trim_end_matches('.'))
        }
    }

    /// The entries in the order they appear in the file.
    pub fn entries(&self) -> Vec<(&'a Spanned<std::borrow::Cow<'i, str>>, &'a Value<'i>)> {
        let mut v: Vec<_> = self.map.iter().collect();
        v.sort_by_key(|(k, _)| k.span().start);
        v
    }

    /// Reject keys outside `allowed` (the first in file order).
    pub fn allow_only(&self, allowed: &[&str]) -> Result<(), SceneError> {
        for (key, _) in self.entries() {
            let k: &str = key.get_ref();
            if !allowed.contains(&k) {
                return Err(self.src.error(
                    &key.span(),
                    &format!("unknown field in {}", self.name()),
                    k,
                    &format!(
                        "{}allowed fields: {}",
                        suggestion(k, allowed),
                        allowed.join(", ")
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The value of `key`, if present.
    pub fn get(&self, key: &str) -> Option<&'a Value<'i>> {
        self.map.get(key)
    }

    /// The span of `key`'s value, or of the table when absent.
    pub fn span_of(&self, key: &str) -> Range<usize> {
        self.get(key)
            .map_or_else(|| self.span.clone(), Spanned::span)
    }

    /// Error for a missing required field.
    pub fn missing(&self, key: &str, fix: &str) -> SceneError {
        self.src
            .error_bare(&self.span, &format!("{} is missing", self.field(key)), fix)
    }

    /// Error quoting `key`'s value.
    pub fn bad(&self, key: &str, what: &str, fix: &str) -> SceneError {
        self.src.error_at(
            &self.span_of(key),
            &format!("{} {what}", self.field(key)),
            fix,
        )
    }

    /// A number (integer or float), finite, if present.
    pub fn number(&self, key: &str, hint: &str) -> Result<Option<f64>, SceneError> {
        let Some(v) = self.get(key) else {
            return Ok(None);
        };
        number(self.src, v, &self.field(key), hint).map(Some)
    }

    /// A number satisfying `bound`, or `default` when absent.
    pub fn number_or(
        &self,
        key: &str,
        default: f64,
        bound: Bound,
        hint: &str,
    ) -> Result<f64, SceneError> {
        Ok(self.bounded(key, bound, hint)?.unwrap_or(default))
    }

    /// A number satisfying `bound`, if present.
    pub fn bounded(&self, key: &str, bound: Bound, hint: &str) -> Result<Option<f64>, SceneError> {
        let Some(x) = self.number(key, hint)? else {
            return Ok(None);
        };
        if bound.holds(x) {
            Ok(Some(x))
        } else {
            Err(self.bad(key, &format!("must be {}", bound.describe()), hint))
        }
    }

    /// A required number satisfying `bound`.
    pub fn required(&self, key: &str, bound: Bound, hint: &str) -> Result<f64, SceneError> {
        self.bounded(key, bound, hint)?
            .ok_or_else(|| self.missing(key, hint))
    }

    /// A boolean, if present.
    pub fn boolean(&self, key: &str, hint: &str) -> Result<Option<bool>, SceneError> {
        let Some(v) = self.get(key) else {
            return Ok(None);
        };
        match v.get_ref() {
            DeValue::Boolean(b) => Ok(Some(*b)),
            _ => Err(self.src.error_at(
                &v.span(),
                &format!("{} must be true or false", self.field(key)),
                hint,
            )),
        }
    }

    /// A non-negative integer, if present.
    pub fn index(&self, key: &str, hint: &str) -> Result<Option<u64>, SceneError> {
        let Some(v) = self.get(key) else {
            return Ok(None);
        };
        let field = self.field(key);
        match v.get_ref() {
            DeValue::Integer(i) => match u64::from_str_radix(i.as_str(), i.radix()) {
                Ok(n) => Ok(Some(n)),
                Err(_) => Err(self.src.error_at(
                    &v.span(),
                    &format!("{field} must be a whole number 0 or greater"),
                    hint,
                )),
            },
            _ => {
                Err(self
                    .src
                    .error_at(&v.span(), &format!("{field} must be a whole number"), hint))
            }
        }
    }

    /// A 3-vector of finite numbers, if present.
    pub fn vec3(&self, key: &str, hint: &str) -> Result<Option<Vec3>, SceneError> {
        let Some(v) = self.get(key) else {
            return Ok(None);
        };
        vec3(self.src, v, &self.field(key), hint).map(Some)
    }

    /// A 3-vector, or `default` when absent.
    pub fn vec3_or(&self, key: &str, default: Vec3, hint: &str) -> Result<Vec3, SceneError> {
        Ok(self.vec3(key, hint)?.unwrap_or(default))
    }

    /// A string, if present.
    pub fn string(&self, key: &str, hint: &str) -> Result<Option<&'a str>, SceneError> {
        let Some(v) = self.get(key) else {
            return Ok(None);
        };
        match v.get_ref() {
            DeValue::String(s) => {
                // Line breaks (LF, or CRLF in a file with CRLF line endings,
                // as a multi-line string keeps them) and tabs belong in
                // notes; nowhere else do control or invisible characters.
                let allowed = |c: char, next: Option<char>| {
                    key == "notes"
                        && (matches!(c, '\n' | '\t') || (c == '\r' && next == Some('\n')))
                };
                let mut chars = s.chars().peekable();
                let mut found = None;
                while let Some(c) = chars.next() {
                    if hidden(c) && !allowed(c, chars.peek().copied()) {
                        found = Some(c);
                        break;
                    }
                }
                if let Some(c) = found {
                    return Err(self.src.error_at(
                        &v.span(),
                        &format!(
                            "{} contains the invisible or control character U+{:04X}",
                            self.field(key),
                            u32::from(c)
                        ),
                        "write it with visible characters only",
                    ));
                }
                Ok(Some(s.as_ref()))
            }
            _ => Err(self.src.error_at(
                &v.span(),
                &format!("{} must be a string", self.field(key)),
                hint,
            )),
        }
    }

    /// An array, if present.
    pub fn array(&self, key: &str, hint: &str) -> Result<Option<&'a DeArray<'i>>, SceneError> {
        let Some(v) = self.get(key) else {
            return Ok(None);
        };
        match v.get_ref() {
            DeValue::Array(a) => Ok(Some(a)),
            _ => Err(self.src.error_at(
                &v.span(),
                &format!("{} must be an array", self.field(key)),
                hint,
            )),
        }
    }

    /// An array of strings, if present; each with its span.
    pub fn strings(&self, key: &str, hint: &str) -> Result<Option<Vec<Located<'a>>>, SceneError> {
        let Some(a) = self.array(key, hint)? else {
            return Ok(None);
        };
        let mut out = Vec::with_capacity(a.len());
        for (k, v) in a.iter().enumerate() {
            match v.get_ref() {
                DeValue::String(s) => out.push((s.as_ref(), v.span())),
                _ => {
                    return Err(self.src.error_at(
                        &v.span(),
                        &format!("{}[{k}] must be a string", self.field(key)),
                        hint,
                    ));
                }
            }
        }
        Ok(Some(out))
    }

    /// A sub-table, if present, read as `path.key.`.
    pub fn table(&self, key: &str, hint: &str) -> Result<Option<&'a Value<'i>>, SceneError> {
        let Some(v) = self.get(key) else {
            return Ok(None);
        };
        match v.get_ref() {
            DeValue::Table(_) => Ok(Some(v)),
            _ => Err(self.src.error_at(
                &v.span(),
                &format!("{} must be a table", self.field(key)),
                hint,
            )),
        }
    }

    /// Free block names (`free = [...]`), deduplicated, in control-vector order.
    pub fn blocks(&self, key: &str) -> Result<Vec<Block>, SceneError> {
        let names: Vec<&str> = Block::ALL.iter().map(|b| b.name()).collect();
        let hint = format!("list blocks from {}", names.join(", "));
        let Some(items) = self.strings(key, &hint)? else {
            return Ok(Vec::new());
        };
        let mut free = Vec::new();
        for (name, span) in items {
            let Some(b) = Block::parse(name) else {
                return Err(self.src.error_at(
                    &span,
                    &format!("{} lists an unknown block", self.field(key)),
                    &format!(
                        "{}the blocks are {}",
                        suggestion(name, &names),
                        names.join(", ")
                    ),
                ));
            };
            free.push(b);
        }
        Ok(Block::ALL
            .into_iter()
            .filter(|b| free.contains(b))
            .collect())
    }
}

/// A finite number (integer or float) named `field` in messages.
pub(super) fn number(
    src: &Source<'_>,
    v: &Value<'_>,
    field: &str,
    hint: &str,
) -> Result<f64, SceneError> {
    match v.get_ref() {
        DeValue::Float(f) => match f.as_str().parse::<f64>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(src.error_at(&v.span(), &format!("{field} must be a finite number"), hint)),
        },
        DeValue::Integer(i) => match i64::from_str_radix(i.as_str(), i.radix()) {
            #[allow(clippy::cast_precision_loss)]
            Ok(n) => Ok(n as f64),
            Err(_) => Err(src.error_at(&v.span(), &format!("{field} is too large"), hint)),
        },
        _ => Err(src.error_at(&v.span(), &format!("{field} must be a number"), hint)),
    }
}

/// An array of exactly `N` finite numbers named `field` in messages.
pub(super) fn numbers<const N: usize>(
    src: &Source<'_>,
    v: &Value<'_>,
    field: &str,
    hint: &str,
) -> Result<[f64; N], SceneError> {
    let count = match N {
        2 => "2",
        3 => "3",
        _ => "N",
    };
    let DeValue::Array(a) = v.get_ref() else {
        return Err(src.error_at(
            &v.span(),
            &format!("{field} must be an array of {count} numbers"),
            hint,
        ));
    };
    if a.len() != N {
        let what = if a.is_empty() {
            format!("{field} is empty (it needs exactly {count} numbers)")
        } else {
            format!("{field} has {} numbers instead of {count}", a.len())
        };
        return Err(src.error_at(&v.span(), &what, hint));
    }
    let mut out = [0.0; N];
    for (k, x) in a.iter().enumerate() {
        out[k] = number(src, x, &format!("{field}[{k}]"), hint)?;
    }
    Ok(out)
}

/// A 3-vector of finite numbers named `field` in messages.
pub(super) fn vec3(
    src: &Source<'_>,
    v: &Value<'_>,
    field: &str,
    hint: &str,
) -> Result<Vec3, SceneError> {
    numbers::<3>(src, v, field, hint).map(Vec3::from)
}

/// The table inside a value, if it is one.
pub(super) fn as_table<'a, 'i>(v: &'a Value<'i>) -> Option<&'a DeTable<'i>> {
    match v.get_ref() {
        DeValue::Table(t) => Some(t),
        _ => None,
    }
}

/// Convert a located value to a plain `toml::Value` (kept as the shape's
/// source and handed to serde for constraints).
pub(super) fn plain(v: &DeValue<'_>) -> toml::Value {
    match v {
        DeValue::String(s) => toml::Value::String(s.to_string()),
        DeValue::Integer(i) => match i64::from_str_radix(i.as_str(), i.radix()) {
            Ok(n) => toml::Value::Integer(n),
            #[allow(clippy::cast_precision_loss)]
            Err(_) => toml::Value::Float(i.as_str().parse::<f64>().unwrap_or(f64::NAN)),
        },
        DeValue::Float(f) => toml::Value::Float(f.as_str().parse::<f64>().unwrap_or(f64::NAN)),
        DeValue::Boolean(b) => toml::Value::Boolean(*b),
        DeValue::Datetime(d) => toml::Value::Datetime(*d),
        DeValue::Array(a) => toml::Value::Array(a.iter().map(|x| plain(x.get_ref())).collect()),
        DeValue::Table(t) => {
            let mut entries: Vec<_> = t.iter().collect();
            entries.sort_by_key(|(k, _)| k.span().start);
            toml::Value::Table(
                entries
                    .into_iter()
                    .map(|(k, x)| (k.get_ref().to_string(), plain(x.get_ref())))
                    .collect(),
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_count_characters_not_bytes() {
        let src = Source {
            text: "a = \"é\"\nbb = 1",
            origin: "t",
        };
        assert_eq!(src.line_col(0), (1, 1));
        assert_eq!(src.line_col(7), (1, 7));
        assert_eq!(src.line_col(8), (1, 8));
        assert_eq!(src.line_col(9), (2, 1));
        assert_eq!(src.line_col(14), (2, 6));
    }

    #[test]
    fn quotes_are_one_line_without_comments() {
        let text = "[\n  [1, 2], # first\n  [3, 4],\n]";
        let src = Source { text, origin: "t" };
        assert_eq!(src.quote(&(0..text.len())), "[[1, 2], [3, 4],]");
    }

    #[test]
    fn suggestions_need_a_close_match() {
        assert_eq!(
            suggestion("densty", &["density", "mass"]),
            "did you mean density? "
        );
        assert_eq!(suggestion("colour", &["density", "mass"]), "");
    }
}
