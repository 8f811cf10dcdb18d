//! Part of section `latency`: a nudge key held down on every paper scene.
//! The selected body is dragged along the plot's x axis by 40 presses of
//! `l` at the middle of the motion, replayed as a held key arrives: with no
//! pause between presses, so nothing the editor defers to a pause runs
//! until the keys stop. Each press is timed from the key to its frame
//! drawn; the work left for the pause after the last press is timed on its
//! own.

use super::cases::PAPER_SCENES;
use super::table::{Align, Table, ms};
use crate::edit::{Core, Editor};
use crate::scene::load_str;
use crate::script::{Latency, Replay, latency, parse_keys, run_script, run_script_with};
use crate::tui::Key;
use std::io::{self, Write};
use std::time::Instant;

/// Presses of the held key.
pub(crate) const PRESSES: usize = 40;

/// Screen size (columns, rows): the design size.
const SCREEN: (u16, u16) = (80, 24);

/// One scene's held key.
pub(crate) struct Held {
    /// Key to frame, per press, ms.
    pub frames: Vec<f64>,
    /// Presses whose nudge was blocked or conflicted (the drag went on by
    /// sampling, or stopped).
    pub blocked: usize,
    /// The work left for the pause after the last press, ms.
    pub pause_ms: f64,
}

/// Hold `l` on `scene_text` (a scene file's text) at the middle of its
/// motion.
pub(crate) fn hold(scene_text: &str, origin: &str) -> Result<Held, String> {
    let scene = load_str(scene_text, origin).map_err(|e| e.to_string())?;
    let middle = 0.5 * scene.duration;
    let mut editor = Editor::new(scene, None).map_err(|e| e.to_string())?;
    editor.set_wall_clock(false);
    editor.set_defer_motion(true);
    let select = parse_keys(&format!(":t {middle}<CR>"), "held key").map_err(|e| e.to_string())?;
    run_script(&mut editor, &select, SCREEN);
    let blocks0 = editor.view().status.blocks;
    let presses = vec![Key::char('l'); PRESSES];
    let held = Replay {
        pauses: false,
        ..Replay::default()
    };
    let r = run_script_with(&mut editor, &presses, SCREEN, held);
    let start = Instant::now();
    while editor.idle() {}
    Ok(Held {
        frames: r.frame_ms,
        blocked: editor.view().status.blocks - blocks0,
        pause_ms: start.elapsed().as_secs_f64() * 1e3,
    })
}

/// Print the held-key table.
pub(crate) fn print(out: &mut dyn Write) -> io::Result<()> {
    let mut t = Table::new(&[
        ("scene", Align::Left),
        ("presses", Align::Right),
        ("blocked", Align::Right),
        ("key→frame median [ms]", Align::Right),
        ("p95 [ms]", Align::Right),
        ("max [ms]", Align::Right),
        ("then pause [ms]", Align::Right),
    ]);
    let mut met = 0;
    for (name, text) in PAPER_SCENES {
        let held = match hold(text, &format!("scenes/{name}.toml")) {
            Ok(h) => h,
            Err(e) => {
                t.message(vec![name.into()], e);
                continue;
            }
        };
        let l: Option<Latency> = latency(&held.frames);
        let cells = l.map_or([f64::NAN; 3], |l| [l.median, l.p95, l.max]);
        if l.is_some_and(|l| l.p95 <= 16.0) {
            met += 1;
        }
        let mut row = vec![
            name.to_string(),
            held.frames.len().to_string(),
            held.blocked.to_string(),
        ];
        row.extend(cells.iter().map(|v| ms(*v)));
        row.push(ms(held.pause_ms));
        t.row(row);
    }
    writeln!(
        out,
        "\n  `l` held ×{PRESSES} at the middle of each paper scene's motion, no pause between presses;"
    )?;
    writeln!(
        out,
        "  key→frame: the press's update, view and render; then pause: the rest of the motion and its estimate"
    )?;
    write!(out, "{}", t.render())?;
    writeln!(
        out,
        "  target: key→frame p95 ≤ 16 ms: met on {met}/{} scenes",
        PAPER_SCENES.len()
    )
}
