//! Saving: the scene's [`sections`] printed as TOML text.
//!
//! Floats are printed with Rust's shortest round-trip formatting (`{:?}`),
//! so every number parses back to the same `f64` and the text loads back to
//! the same scene bit for bit. Shapes longer than [`MAX_INLINE_SHAPE`] are
//! written as a sub-table after the body's or obstacle's other keys.
use super::saved::{Section, sections};
use crate::scene::model::Scene;
use std::fmt::Write as _;

/// Shapes whose inline form is longer than this are written as a sub-table.
const MAX_INLINE_SHAPE: usize = 100;

/// A float as TOML: shortest round-trip digits (`nan`/`inf` for non-finite
/// values, which then fail to load with a located message rather than
/// making the file unreadable).
pub(super) fn float(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf".into() } else { "-inf".into() }
    } else {
        format!("{x:?}")
    }
}

fn quoted(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

fn key(k: &str) -> String {
    if !k.is_empty()
        && k.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    {
        k.to_string()
    } else {
        quoted(k)
    }
}

/// The order shape keys are written in; other keys follow, sorted.
const KEY_ORDER: [&str; 14] = [
    "type",
    "shape",
    "position",
    "orientation",
    "radius",
    "half_extents",
    "radii",
    "bottom",
    "resolution",
    "points",
    "normal",
    "curvature",
    "half_width",
    "parts",
];

/// Keys of a table in writing order (see [`KEY_ORDER`]).
fn ordered(t: &toml::Table) -> Vec<&String> {
    let rank = |k: &str| {
        KEY_ORDER
            .iter()
            .position(|x| *x == k)
            .unwrap_or(KEY_ORDER.len())
    };
    let mut keys: Vec<&String> = t.keys().collect();
    keys.sort_by(|a, b| rank(a).cmp(&rank(b)).then_with(|| a.cmp(b)));
    keys
}

/// A value on one line.
pub(super) fn inline(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => quoted(s),
        toml::Value::Integer(i) => i.to_string(),
        toml::Value::Float(f) => float(*f),
        toml::Value::Boolean(b) => b.to_string(),
        toml::Value::Datetime(d) => d.to_string(),
        toml::Value::Array(a) => {
            format!("[{}]", a.iter().map(inline).collect::<Vec<_>>().join(", "))
        }
        toml::Value::Table(t) if t.is_empty() => "{}".into(),
        toml::Value::Table(t) => {
            let fields: Vec<String> = ordered(t)
                .into_iter()
                .map(|k| format!("{} = {}", key(k), inline(&t[k.as_str()])))
                .collect();
            format!("{{ {} }}", fields.join(", "))
        }
    }
}

/// Write `shape` inline when short, else return the lines of a sub-table.
fn shape_lines(out: &mut String, shape: &toml::Value) -> Option<String> {
    let one_line = inline(shape);
    if one_line.len() <= MAX_INLINE_SHAPE || !shape.is_table() {
        let _ = writeln!(out, "shape = {one_line}");
        return None;
    }
    let mut sub = String::new();
    if let toml::Value::Table(t) = shape {
        for k in ordered(t) {
            match &t[k.as_str()] {
                toml::Value::Array(items)
                    if items.iter().all(toml::Value::is_table) && !items.is_empty() =>
                {
                    let _ = writeln!(sub, "{} = [", key(k));
                    for item in items {
                        let _ = writeln!(sub, "    {},", inline(item));
                    }
                    let _ = writeln!(sub, "]");
                }
                v => {
                    let _ = writeln!(sub, "{} = {}", key(k), inline(v));
                }
            }
        }
    }
    Some(sub)
}

/// The scene as new TOML text.
pub(super) fn to_toml(scene: &Scene) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# nudge scene (format: docs/scene-format.md)");
    for section in sections(scene) {
        write_section(&mut out, &section);
    }
    out
}

fn write_section(out: &mut String, s: &Section) {
    match (s.name, s.array) {
        ("", _) => {}
        (name, true) => {
            let _ = writeln!(out, "\n[[{name}]]");
        }
        (name, false) => {
            let _ = writeln!(out, "\n[{name}]");
        }
    }
    let mut sub = None;
    for (k, v) in &s.fields {
        if *k == "shape" {
            sub = shape_lines(out, v);
        } else {
            let _ = writeln!(out, "{} = {}", key(k), inline(v));
        }
    }
    if let Some(sub) = sub {
        let _ = write!(out, "\n[{}.shape]\n{sub}", s.name);
    }
}
