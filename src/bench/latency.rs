//! Section `latency`: replay the eggs editing session through the real key
//! map, editor core and renderer, and report how long edits and frames take.

use super::cases::PAPER_SCENES;
use super::table::{Align, Table, ms};
use crate::edit::Editor;
use crate::scene::load_str;
use crate::script::{Latency, parse_keys, run_script};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// Where the eggs session script is looked for, relative to the working
/// directory and to the crate.
pub(crate) fn session_paths() -> [PathBuf; 2] {
    let rel = Path::new("tests").join("sessions").join("eggs.keys");
    [rel.clone(), Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)]
}

/// Screen size of the replay (columns, rows).
const SCREEN: (u16, u16) = (120, 40);

/// Print the section.
pub(crate) fn print(out: &mut dyn Write) -> io::Result<()> {
    let Some(path) = session_paths().into_iter().find(|p| p.is_file()) else {
        return writeln!(out, "  session script not found: tests/sessions/eggs.keys");
    };
    let text = match std::fs::read_to_string(&path) {
        Ok(t) => t,
        Err(e) => return writeln!(out, "  could not read {}: {e}", path.display()),
    };
    let keys = match parse_keys(&text, &path.display().to_string()) {
        Ok(k) => k,
        Err(e) => return writeln!(out, "  {e}"),
    };
    let Some((_, scene_text)) = PAPER_SCENES.iter().find(|(n, _)| *n == "eggs") else {
        return writeln!(out, "  the eggs scene is not compiled in");
    };
    let mut editor = match load_str(scene_text, "scenes/eggs.toml")
        .map_err(|e| e.to_string())
        .and_then(|s| Editor::new(s, None).map_err(|e| e.to_string()))
    {
        Ok(ed) => ed,
        Err(e) => return writeln!(out, "  error: {e}"),
    };
    let r = run_script(&mut editor, &keys, SCREEN);
    let mut t = Table::new(&[
        ("what", Align::Left),
        ("count", Align::Right),
        ("median [ms]", Align::Right),
        ("p95 [ms]", Align::Right),
        ("max [ms]", Align::Right),
    ]);
    for (what, samples, lat) in [
        ("key → edit applied", &r.update_ms, r.update_latency()),
        ("frame render", &r.render_ms, r.render_latency()),
    ] {
        let cells = |l: Option<Latency>| match l {
            Some(l) => [ms(l.median), ms(l.p95), ms(l.max)],
            None => [ms(f64::NAN), ms(f64::NAN), ms(f64::NAN)],
        };
        let mut row = vec![what.to_string(), samples.len().to_string()];
        row.extend(cells(lat));
        t.row(row);
    }
    writeln!(
        out,
        "  {} keys from {} on a {}×{} screen; {} edits applied{}",
        keys.len(),
        path.display(),
        SCREEN.0,
        SCREEN.1,
        r.edits,
        if r.quit { "; quit" } else { "" }
    )?;
    write!(out, "{}", t.render())
}
