//! Saving into the text a scene was loaded from: the document is edited in
//! place with `toml_edit`, so the user's comments, blank lines, key order
//! and the spelling of every untouched value stay as they were written.
//!
//! What is saved is decided by [`sections`], as for new text; this module
//! decides only where it goes. A key is touched only where the sections of
//! the scene differ from the sections of the text as loaded (the *base*):
//! so a `density` stays while the mass is unchanged, an obstacle's omitted
//! orientation stays omitted, and `1e-9` is not respelt. Where they differ:
//! - a changed value is replaced in place, keeping the comments around it
//!   (an array of the same length is edited element by element);
//! - a new key goes after the nearest key that precedes it in writing order
//!   (`mass` takes the place of the `density` it replaces), a new table
//!   after the last table before it;
//! - a key or table that no longer applies is removed, and any comment it
//!   carried moves to what follows it, so no comment is lost.
//!
//! The edited text is loaded back and must give the scene's sections bit
//! for bit; otherwise the caller writes new text instead.
use super::saved::{Section, identity, same_fields, same_sections, same_value, sections};
use super::write::inline;
use super::{SceneError, load_str};
use crate::scene::model::Scene;
use toml::Value as Plain;
use toml_edit::{ArrayOfTables, DocumentMut, Item, Key, RawString, Table, TableLike, Value};

/// Why a scene's text could not be edited in place.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub(super) enum Unkept {
    /// The text does not load (it did when the scene was opened).
    #[error("{0}")]
    Load(#[from] SceneError),
    /// `toml_edit` does not read the text, or a value it cannot take.
    #[error("the text cannot be edited: {0}")]
    Parse(String),
    /// A part of the scene is written in a form this module does not edit
    /// (bodies as an inline array, say).
    #[error("{0} is written in a form that is not edited in place")]
    Layout(String),
    /// The edited text loads back to another scene (a bug here).
    #[error("the edited text does not load back to the scene")]
    Mismatch,
}

/// Keys a file may give instead of a saved key, which the saved key
/// replaces where it stands.
const ALIASES: [(&str, &str); 1] = [("mass", "density")];

/// `text`, loaded from `origin`, edited to hold `scene`.
///
/// # Errors
/// [`Unkept`] when the text cannot be edited in place; nothing is written.
pub(super) fn edit(text: &str, scene: &Scene, origin: &str) -> Result<String, Unkept> {
    let base = sections(&load_str(text, origin)?);
    let new = sections(scene);
    if same_sections(&base, &new) {
        return Ok(text.to_string());
    }
    let mut doc: DocumentMut = text
        .parse()
        .map_err(|e: toml_edit::TomlError| Unkept::Parse(e.message().to_string()))?;
    let mut moved = Moved::default();
    merge(&mut doc, &base, &new, &mut moved)?;
    moved.place(&mut doc);
    let out = doc.to_string();
    if same_sections(&sections(&load_str(&out, origin)?), &new) {
        Ok(out)
    } else {
        Err(Unkept::Mismatch)
    }
}

fn of<'a>(all: &'a [Section], name: &str) -> Vec<&'a Section> {
    all.iter().filter(|s| s.name == name).collect()
}

fn merge(
    doc: &mut DocumentMut,
    base: &[Section],
    new: &[Section],
    moved: &mut Moved,
) -> Result<(), Unkept> {
    let mut tables: Vec<(&'static str, bool)> = Vec::new();
    for s in new.iter().chain(base) {
        if !s.name.is_empty() && !tables.iter().any(|(n, _)| *n == s.name) {
            tables.push((s.name, s.array));
        }
    }
    let top = |all: &[Section]| of(all, "").first().map(|s| s.fields.clone());
    let (base_top, new_top) = (top(base).unwrap_or_default(), top(new).unwrap_or_default());
    // The top level's order: its own keys, then the tables.
    let order: Vec<&str> = new_top
        .iter()
        .map(|(k, _)| *k)
        .chain(tables.iter().map(|(n, _)| *n))
        .collect();
    // Parsed tables are numbered from 1: the top level comes before them.
    let root_pos = doc.as_table().position().or(Some(0));
    let root = doc.as_table_mut();
    merge_fields(root, &base_top, &new_top, root_pos, moved)?;
    for (name, array) in tables {
        let (b, n) = (of(base, name), of(new, name));
        if array {
            merge_array(root, name, &b, &n, &order, moved)?;
        } else {
            merge_table(root, name, b.first(), n.first(), &order, moved)?;
        }
    }
    Ok(())
}

/// `[name]`: created when it appears, removed when it no longer applies.
fn merge_table(
    root: &mut Table,
    name: &str,
    base: Option<&&Section>,
    new: Option<&&Section>,
    order: &[&str],
    moved: &mut Moved,
) -> Result<(), Unkept> {
    let fields = |s: Option<&&Section>| s.map_or_else(Vec::new, |s| s.fields.clone());
    let (bf, nf) = (fields(base), fields(new));
    if same_fields(&bf, &nf) {
        return Ok(());
    }
    if !root.contains_key(name) {
        if nf.is_empty() {
            return Ok(());
        }
        insert_ordered(root, Key::new(name), Item::Table(Table::new()), order);
    }
    let pos = root
        .get(name)
        .and_then(Item::as_table)
        .and_then(Table::position);
    let t = root
        .get_mut(name)
        .and_then(Item::as_table_like_mut)
        .ok_or_else(|| Unkept::Layout(format!("[{name}]")))?;
    merge_fields(t, &bf, &nf, pos, moved)?;
    if nf.is_empty()
        && t.is_empty()
        && let Some(item) = root.remove(name)
    {
        moved.push(pos, comments_of_item(&item));
    }
    Ok(())
}

/// `[[name]]`: the text's tables matched to the base's sections and then
/// to the new ones (bodies and obstacles by name, event controls by event,
/// constraints by content), edited, added or removed, in the new order.
fn merge_array(
    root: &mut Table,
    name: &'static str,
    base: &[&Section],
    new: &[&Section],
    order: &[&str],
    moved: &mut Moved,
) -> Result<(), Unkept> {
    if base.len() == new.len()
        && base
            .iter()
            .zip(new)
            .all(|(b, n)| same_fields(&b.fields, &n.fields))
    {
        return Ok(());
    }
    let layout = || Unkept::Layout(format!("[[{name}]]"));
    if !root.contains_key(name) && base.is_empty() {
        let empty = Item::ArrayOfTables(ArrayOfTables::new());
        insert_ordered(root, Key::new(name), empty, order);
    }
    let Some(Item::ArrayOfTables(aot)) = root.get_mut(name) else {
        return Err(layout());
    };
    if aot.len() != base.len() {
        return Err(layout());
    }
    let id = identity(name);
    // The text's table for each base section.
    let mut slots: Vec<Option<Table>> = vec![None; base.len()];
    for (i, table) in std::mem::take(aot).into_iter().enumerate() {
        let j = match id {
            Some(key) => {
                let value = table.get(key).and_then(Item::as_value);
                base.iter()
                    .enumerate()
                    .position(|(j, b)| {
                        slots[j].is_none()
                            && value.zip(b.get(key)).is_some_and(|(v, p)| equal(v, p))
                    })
                    .ok_or_else(layout)?
            }
            None => i,
        };
        slots[j] = Some(table);
    }
    let mut used = vec![false; base.len()];
    for n in new {
        let found = (0..base.len()).find(|&j| {
            !used[j]
                && match id {
                    Some(key) => base[j]
                        .get(key)
                        .zip(n.get(key))
                        .is_some_and(|(a, b)| same_value(a, b)),
                    None => same_fields(&base[j].fields, &n.fields),
                }
        });
        let table = match found {
            Some(j) => {
                used[j] = true;
                let mut table = slots[j].take().ok_or_else(layout)?;
                let pos = table.position();
                merge_fields(&mut table, &base[j].fields, &n.fields, pos, moved)?;
                table
            }
            None => {
                let mut table = Table::new();
                for (k, v) in &n.fields {
                    table.insert(k, Item::Value(value_of(v)?));
                }
                table
            }
        };
        aot.push(table);
    }
    for table in slots.into_iter().flatten() {
        moved.push(table.position(), comments_of_table(&table));
    }
    if aot.is_empty() {
        root.remove(name);
    }
    Ok(())
}

/// Edit the keys of one table from `base` to `new`; `pos` is the table's
/// position in the document (for comments that move past its end).
fn merge_fields(
    t: &mut dyn TableLike,
    base: &[(&str, Plain)],
    new: &[(&str, Plain)],
    pos: Option<isize>,
    moved: &mut Moved,
) -> Result<(), Unkept> {
    let order: Vec<&str> = new.iter().map(|(k, _)| *k).collect();
    for (k, v) in new {
        let before = base.iter().find(|(b, _)| b == k).map(|(_, v)| v);
        if !before.is_some_and(|b| same_value(b, v)) {
            set(t, k, v, &order, pos, moved)?;
        }
    }
    for (k, _) in base {
        if !new.iter().any(|(n, _)| n == k) {
            remove(t, k, pos, moved);
        }
    }
    Ok(())
}

fn set(
    t: &mut dyn TableLike,
    k: &str,
    v: &Plain,
    order: &[&str],
    pos: Option<isize>,
    moved: &mut Moved,
) -> Result<(), Unkept> {
    let names = names(t);
    let at = names.iter().position(|n| n == k);
    match t.get_mut(k) {
        Some(Item::Value(old)) => {
            let lines = merge_value(old, v)?;
            rehome(t, at.map_or(0, |i| i + 1), lines, pos, moved);
            return Ok(());
        }
        Some(item @ (Item::Table(_) | Item::ArrayOfTables(_))) => {
            // A sub-table (`[body.shape]`) becomes an inline value.
            let sub_pos = item.as_table().and_then(Table::position);
            moved.push(sub_pos.or(pos), comments_of_item(item));
            *item = Item::Value(value_of(v)?);
            return Ok(());
        }
        Some(Item::None) | None => {}
    }
    let mut value = value_of(v)?;
    let alias = ALIASES
        .iter()
        .find(|(key, alias)| *key == k && t.contains_key(alias))
        .map(|(_, alias)| *alias);
    if let Some(alias) = alias
        && let Some(index) = names.iter().position(|n| n == alias)
        && let Some(old_key) = t.key(alias).cloned()
    {
        // The saved key takes the alias's place, comments and all.
        let mut lines = Vec::new();
        if let Some(Item::Value(old)) = t.remove(alias) {
            *value.decor_mut() = old.decor().clone();
            lines = comments_inside(&old);
        }
        let key = Key::new(k).with_leaf_decor(old_key.leaf_decor().clone());
        let rest: Vec<String> = names.into_iter().filter(|n| n != alias).collect();
        place(t, key, Item::Value(value), index, &rest);
        rehome(t, index + 1, lines, pos, moved);
    } else {
        insert_ordered(t, Key::new(k), Item::Value(value), order);
    }
    Ok(())
}

/// Remove `k`, moving its comments to what follows it.
fn remove(t: &mut dyn TableLike, k: &str, pos: Option<isize>, moved: &mut Moved) {
    let Some(index) = names(t).iter().position(|n| n == k) else {
        return;
    };
    let mut lines = Vec::new();
    if let Some(key) = t.key(k) {
        comment_lines(key.leaf_decor().prefix(), &mut lines);
    }
    if let Some(item) = t.remove(k) {
        lines.extend(comments_of_item(&item));
    }
    rehome(t, index, lines, pos, moved);
}

/// Edit `old` to `new`, keeping its decor; returns the comments inside an
/// array or inline table that was replaced whole.
fn merge_value(old: &mut Value, new: &Plain) -> Result<Vec<String>, Unkept> {
    if equal(old, new) {
        return Ok(Vec::new());
    }
    if let (Value::Array(a), Plain::Array(n)) = (&mut *old, new)
        && a.len() == n.len()
    {
        let mut lines = Vec::new();
        for (i, x) in n.iter().enumerate() {
            if let Some(e) = a.get_mut(i) {
                lines.extend(merge_value(e, x)?);
            }
        }
        return Ok(lines);
    }
    let lines = comments_inside(old);
    let decor = old.decor().clone();
    *old = value_of(new)?;
    *old.decor_mut() = decor;
    Ok(lines)
}

/// Whether the text's value loads as the saved value (an integer where a
/// float is saved loads as that float).
fn equal(text: &Value, saved: &Plain) -> bool {
    match (text, saved) {
        (Value::Float(f), Plain::Float(x)) => f.value().to_bits() == x.to_bits(),
        #[allow(clippy::cast_precision_loss, reason = "as the loader reads it")]
        (Value::Integer(i), Plain::Float(x)) => (*i.value() as f64).to_bits() == x.to_bits(),
        (Value::Integer(i), Plain::Integer(x)) => i.value() == x,
        (Value::String(s), Plain::String(x)) => s.value() == x,
        (Value::Boolean(b), Plain::Boolean(x)) => b.value() == x,
        (Value::Array(a), Plain::Array(x)) => {
            a.len() == x.len() && a.iter().zip(x).all(|(p, q)| equal(p, q))
        }
        (Value::InlineTable(t), Plain::Table(x)) => {
            t.len() == x.len() && x.iter().all(|(k, q)| t.get(k).is_some_and(|p| equal(p, q)))
        }
        _ => false,
    }
}

/// A saved value as `toml_edit` holds it, spelled as new text spells it
/// (floats in shortest round-trip form).
fn value_of(v: &Plain) -> Result<Value, Unkept> {
    inline(v)
        .parse()
        .map_err(|e: toml_edit::TomlError| Unkept::Parse(e.message().to_string()))
}

fn names(t: &dyn TableLike) -> Vec<String> {
    t.iter().map(|(k, _)| k.to_string()).collect()
}

/// Insert after the nearest key that precedes `key` in `order` and is in
/// the table; at the front when there is none.
fn insert_ordered(t: &mut dyn TableLike, key: Key, item: Item, order: &[&str]) {
    let names = names(t);
    let index = order
        .iter()
        .position(|o| *o == key.get())
        .and_then(|me| {
            order[..me]
                .iter()
                .rev()
                .find_map(|p| names.iter().position(|n| n == p))
        })
        .map_or(0, |i| i + 1);
    place(t, key, item, index, &names);
}

/// Insert `key` so that it is the `index`-th of `names` (the table's keys
/// without it). A key put first takes over the comments above the first
/// key (a file's opening comment block stays at the top).
fn place(t: &mut dyn TableLike, mut key: Key, item: Item, index: usize, names: &[String]) {
    if index == 0
        && key.leaf_decor().prefix().is_none()
        && let Some(first) = names.first()
        && t.get(first).is_some_and(Item::is_value)
        && let Some(mut first) = t.key_mut(first)
        && let Some(prefix) = first.leaf_decor().prefix().cloned()
    {
        first.leaf_decor_mut().set_prefix("");
        key.leaf_decor_mut().set_prefix(prefix);
    }
    t.entry_format(&key).or_insert(item);
    for n in names.iter().skip(index) {
        if let Some(k) = t.key(n).cloned()
            && let Some(it) = t.remove(n)
        {
            t.entry_format(&k).or_insert(it);
        }
    }
}

/// Put comment lines above the first value at or after `index`, or, when
/// the table has none, after the table.
fn rehome(
    t: &mut dyn TableLike,
    index: usize,
    lines: Vec<String>,
    pos: Option<isize>,
    moved: &mut Moved,
) {
    if lines.is_empty() {
        return;
    }
    let next = names(t)
        .into_iter()
        .skip(index)
        .find(|n| t.get(n).is_some_and(Item::is_value));
    match next.as_deref().and_then(|n| t.key_mut(n)) {
        Some(mut key) => {
            let decor = key.leaf_decor_mut();
            let old = decor.prefix().and_then(RawString::as_str).unwrap_or("");
            let prefix = lines.concat() + old;
            decor.set_prefix(prefix);
        }
        None => moved.push(pos, lines),
    }
}

/// The comment lines in a piece of decor, each ending in a newline.
fn comment_lines(raw: Option<&RawString>, out: &mut Vec<String>) {
    if let Some(s) = raw.and_then(RawString::as_str) {
        out.extend(
            s.lines()
                .map(str::trim)
                .filter(|l| l.starts_with('#'))
                .map(|l| format!("{l}\n")),
        );
    }
}

/// Comments inside a value, not counting those around it.
fn comments_inside(v: &Value) -> Vec<String> {
    let mut out = Vec::new();
    match v {
        Value::Array(a) => {
            for e in a {
                comment_lines(e.decor().prefix(), &mut out);
                out.extend(comments_inside(e));
                comment_lines(e.decor().suffix(), &mut out);
            }
            comment_lines(Some(a.trailing()), &mut out);
        }
        Value::InlineTable(t) => {
            for (k, e) in t.iter() {
                if let Some(key) = t.key(k) {
                    comment_lines(key.leaf_decor().prefix(), &mut out);
                }
                comment_lines(e.decor().prefix(), &mut out);
                out.extend(comments_inside(e));
                comment_lines(e.decor().suffix(), &mut out);
            }
            comment_lines(Some(t.trailing()), &mut out);
        }
        _ => {}
    }
    out
}

fn comments_of_item(item: &Item) -> Vec<String> {
    let mut out = Vec::new();
    match item {
        Item::Value(v) => {
            comment_lines(v.decor().prefix(), &mut out);
            out.extend(comments_inside(v));
            comment_lines(v.decor().suffix(), &mut out);
        }
        Item::Table(t) => out = comments_of_table(t),
        Item::ArrayOfTables(a) => a.iter().for_each(|t| out.extend(comments_of_table(t))),
        Item::None => {}
    }
    out
}

fn comments_of_table(t: &Table) -> Vec<String> {
    let mut out = Vec::new();
    comment_lines(t.decor().prefix(), &mut out);
    comment_lines(t.decor().suffix(), &mut out);
    for (k, item) in t.iter() {
        if let Some(key) = t.key(k) {
            comment_lines(key.leaf_decor().prefix(), &mut out);
        }
        out.extend(comments_of_item(item));
    }
    out
}

/// Comments of removed keys and tables that had nothing after them in
/// their own table: they go above the next table in the document (where
/// they were), or at its end.
#[derive(Default)]
struct Moved(Vec<(Option<isize>, Vec<String>)>);

impl Moved {
    fn push(&mut self, pos: Option<isize>, lines: Vec<String>) {
        if !lines.is_empty() {
            self.0.push((pos, lines));
        }
    }

    fn place(self, doc: &mut DocumentMut) {
        for (pos, lines) in self.0 {
            let mut next: Option<isize> = None;
            if let Some(p) = pos {
                visit_tables(doc.as_table_mut(), &mut |t| {
                    if let Some(q) = t.position()
                        && q > p
                        && next.is_none_or(|n| q < n)
                    {
                        next = Some(q);
                    }
                });
            }
            let text = lines.concat();
            let mut placed = false;
            if let Some(n) = next {
                visit_tables(doc.as_table_mut(), &mut |t| {
                    if !placed && t.position() == Some(n) {
                        let decor = t.decor_mut();
                        let old = decor.prefix().and_then(RawString::as_str).unwrap_or("\n");
                        let prefix = text.clone() + old;
                        decor.set_prefix(prefix);
                        placed = true;
                    }
                });
            }
            if !placed {
                let old = doc.trailing().as_str().unwrap_or("").to_string();
                doc.set_trailing(text + &old);
            }
        }
    }
}

/// Every standard table below `t` (sub-tables and arrays of tables).
fn visit_tables(t: &mut Table, f: &mut dyn FnMut(&mut Table)) {
    for (_, item) in t.iter_mut() {
        match item {
            Item::Table(sub) => {
                if !sub.is_dotted() {
                    f(sub);
                }
                visit_tables(sub, f);
            }
            Item::ArrayOfTables(a) => {
                for sub in a.iter_mut() {
                    f(sub);
                    visit_tables(sub, f);
                }
            }
            _ => {}
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::model::Method;

    const BALL: &str =
        "[[body]]\nname = \"b\"\nshape = { type = \"sphere\", radius = 0.1 }\nmass = 1.0\n";

    fn scene(text: &str) -> Scene {
        load_str(text, "t.toml").unwrap_or_else(|e| panic!("{e}"))
    }

    fn edited(text: &str, scene: &Scene) -> String {
        edit(text, scene, "t.toml").unwrap_or_else(|e| panic!("{e}"))
    }

    #[test]
    fn keys_that_no_longer_apply_go_and_leave_their_comments() {
        let text = format!(
            "duration = 1.0\neffects = []\n\n[accuracy]\n# integrator\nmethod = \"adaptive\"\n# tight\ntol = 1e-10\nmax_step = 0.02  # small steps\n\n{BALL}"
        );
        let mut s = scene(&text);
        s.accuracy.method = Method::Rk4 { step: 1e-3 };
        assert_eq!(
            edited(&text, &s),
            format!(
                "duration = 1.0\neffects = []\n\n[accuracy]\n# integrator\nmethod = \"rk4\"\nstep = 0.001\n# tight\n# small steps\n\n{BALL}"
            )
        );
    }

    #[test]
    fn a_removed_last_top_level_key_leaves_its_comments_above_the_first_table() {
        let text = format!("duration = 1.0\neffects = []\n# The story.\nnotes = \"x\"\n\n{BALL}");
        let mut s = scene(&text);
        s.notes.clear();
        assert_eq!(
            edited(&text, &s),
            format!("duration = 1.0\neffects = []\n# The story.\n\n{BALL}")
        );
    }

    #[test]
    fn a_table_the_text_lacks_goes_where_it_is_written() {
        let text = format!("duration = 1.0\neffects = []\n\n# The ball.\n{BALL}");
        let mut s = scene(&text);
        s.accuracy.method = Method::Adaptive {
            tol: 1e-10,
            max_step: 0.01,
        };
        assert_eq!(
            edited(&text, &s),
            format!(
                "duration = 1.0\neffects = []\n\n[accuracy]\nmethod = \"adaptive\"\ntol = 1e-10\nmax_step = 0.01\n\n# The ball.\n{BALL}"
            )
        );
    }

    #[test]
    fn a_removed_table_leaves_its_comments_for_the_next() {
        let nail = |t: &str, note: &str| {
            format!(
                "{note}[[constraint]]\nkind = \"nail\"\nbody = \"b\"\ntime = {t}\nquantities = [\"position\"]\ntarget = [0.0, 0.0, 0.0]\n"
            )
        };
        let head = format!("duration = 1.0\neffects = []\n\n{BALL}");
        let text = format!(
            "{head}\n{}\n{}",
            nail("0.1  # s", "# Hold it early.\n"),
            nail("0.5", "")
        );
        let mut s = scene(&text);
        s.constraints.remove(0);
        assert_eq!(
            edited(&text, &s),
            format!("{head}{}", nail("0.5", "# Hold it early.\n# s\n\n"))
        );
    }

    #[test]
    fn an_edited_mass_takes_the_place_of_the_density() {
        let text = "duration = 1.0\neffects = []\n\n[[body]]\nname = \"b\"\n# wood\ndensity = 500.0  # pine\nshape = { type = \"box\", half_extents = [0.3, 0.2, 0.1] }\nfree = [\"mass\"]\n";
        let mut s = scene(text);
        s.bodies[0].mass = 10.0;
        let out = edited(text, &s);
        assert!(
            out.starts_with("duration = 1.0\neffects = []\n\n[[body]]\nname = \"b\"\n# wood\nmass = 10.0  # pine\ninertia = ["),
            "{out}"
        );
        assert!(
            out.contains("]\ninertia_axes = [0.0, 0.0, 0.0]\nshape = { type"),
            "{out}"
        );
        let back = scene(&out);
        assert_eq!(back.bodies[0].inertia, s.bodies[0].inertia);
        assert!(back.bodies[0].inertia_given);
    }

    #[test]
    fn a_key_put_first_keeps_the_opening_comment_block_on_top() {
        let text = format!("# A ball.\n# Dropped.\n\nduration = 1.0\neffects = []\n\n{BALL}");
        let s = scene(&text);
        // Saved under another name, the scene's name must be written.
        let out = edit(&text, &s, "other.toml").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            out,
            format!(
                "# A ball.\n# Dropped.\n\nname = \"t\"\nduration = 1.0\neffects = []\n\n{BALL}"
            )
        );
    }

    #[test]
    fn bodies_in_an_inline_array_are_not_edited_in_place() {
        let text = "duration = 1.0\neffects = []\nbody = [{ name = \"b\", shape = { type = \"sphere\", radius = 0.1 }, mass = 1.0 }]\n";
        let mut s = scene(text);
        s.bodies[0].position.z = 2.0;
        assert_eq!(
            edit(text, &s, "t.toml"),
            Err(Unkept::Layout("[[body]]".into()))
        );
        // Saving falls back to new text, which holds the edit.
        let saved = super::super::saved_text(&s, std::path::Path::new("t.toml"));
        assert_eq!(saved, super::super::to_toml(&s));
        assert_eq!(scene(&saved).bodies[0].position.z, 2.0);
    }
}
