//! Section `explore`: how many sampled worlds per second exploring
//! simulates (docs/design.md §12), per paper scene, and how many distinct
//! collision sequences it finds, from the unedited motion and from where
//! the scene's paper session leaves the editor. Sampling only: polishing is a handful of
//! differential updates, timed by the other sections.

use super::cases::{Case, Entry};
use super::measure::{Plan, guarded};
use super::table::{Align, Table, num};
use crate::edit::Editor;
use crate::explore::{self, Exploration, ExploreOptions, Progress, Start};
use crate::script::run_script;
use crate::solve::Constraint;
use std::io::{self, Write};
use std::time::Instant;

/// The target for single-body scenes on the project's 2-core machine.
const TARGET: f64 = 2000.0;

/// One exploration of `samples` worlds from the editor's state, after a
/// short warm-up; the exploration and its wall time, s.
fn explore_once(editor: &Editor, samples: usize) -> Result<(Exploration, f64), String> {
    let start = Start::from_editor(editor);
    let opts = |samples| ExploreOptions {
        samples,
        polish: 0,
        ..ExploreOptions::default()
    };
    explore::run(&start, &opts(32), &Progress::default()).map_err(|e| e.to_string())?;
    let t = Instant::now();
    let x =
        explore::run(&start, &opts(samples), &Progress::default()).map_err(|e| e.to_string())?;
    Ok((x, t.elapsed().as_secs_f64()))
}

/// The paper session of scene `name` (compiled in, without its saves),
/// replayed on a fresh editor; `None` when there is none.
pub(super) fn session(name: &str, case: &Case) -> Option<Result<Editor, String>> {
    let steps = super::latency::session_steps(name).ok()?;
    Some((|| {
        let mut editor = Editor::new(case.scene.clone(), None).map_err(|e| e.to_string())?;
        editor.set_wall_clock(false);
        run_script(&mut editor, &steps, (80, 24));
        Ok(editor)
    })())
}

/// How far exploring simulates each world: just past the last constrained
/// time (as the solver's trials), or the whole motion.
fn horizon(editor: &Editor) -> f64 {
    let duration = editor.scene().duration;
    let mut constrained: Vec<Constraint> = editor.constraints().to_vec();
    constrained.extend(editor.pending_drag().cloned());
    if constrained.is_empty() {
        return duration;
    }
    let last = constrained
        .iter()
        .filter_map(|c| c.time(editor.trajectory()))
        .fold(0.0, f64::max);
    (last + 0.02 * duration).min(duration)
}

/// Print the section.
pub(crate) fn print(out: &mut dyn Write, plan: &Plan, paper: &[Entry]) -> io::Result<()> {
    let samples = if plan.quick { 256 } else { 2048 };
    let mut t = Table::new(&[
        ("scene", Align::Left),
        ("bodies", Align::Right),
        ("m", Align::Right),
        ("until [s]", Align::Right),
        ("worlds", Align::Right),
        ("pruned", Align::Right),
        ("skipped", Align::Right),
        ("sequences", Align::Right),
        ("time [s]", Align::Right),
        ("worlds/s", Align::Right),
    ]);
    // Single-body rows: (whole motion or session, name, worlds/s).
    let mut single: Vec<(bool, String, f64)> = Vec::new();
    let mut rows: Vec<(String, bool, Result<Editor, String>)> = Vec::new();
    for e in paper {
        let c = match &e.case {
            Ok(c) => c,
            Err(x) => {
                rows.push((e.name.to_string(), false, Err(x.clone())));
                continue;
            }
        };
        let name = if c.freed {
            format!("{}*", e.name)
        } else {
            e.name.to_string()
        };
        let editor = Editor::new(c.scene.clone(), None).map_err(|x| x.to_string());
        rows.push((name.clone(), false, editor));
        if let Some(s) = session(e.name, c) {
            rows.push((format!("{name} session"), true, s));
        }
    }
    for (name, after_session, row) in rows {
        let lead = vec![name.clone()];
        let measured =
            row.and_then(|editor| guarded(|| explore_once(&editor, samples)).map(|r| (editor, r)));
        match measured {
            Ok((editor, (x, secs))) => {
                // Worlds actually simulated: a pruned one costs a draw.
                let rate = (x.worlds - x.pruned) as f64 / secs;
                let bodies = editor.scene().bodies.len();
                if bodies == 1 {
                    single.push((after_session, name.clone(), rate));
                }
                t.row(vec![
                    name,
                    bodies.to_string(),
                    editor.controls().m().to_string(),
                    num(horizon(&editor), 2),
                    x.worlds.to_string(),
                    x.pruned.to_string(),
                    (x.failed + x.non_finite).to_string(),
                    x.groups.to_string(),
                    num(secs, 3),
                    num(rate, 0),
                ]);
            }
            Err(e) => t.message(lead, format!("error: {e}")),
        }
    }
    write!(out, "{}", t.render())?;
    let threads = rayon::current_num_threads();
    writeln!(
        out,
        "  One exploration of `worlds` sampled control vectors (seed {:#x}, σ = {}·2^k over {} rounds),",
        ExploreOptions::default().seed,
        ExploreOptions::default().sigma0,
        ExploreOptions::default().rounds
    )?;
    writeln!(
        out,
        "  simulated without tangents up to `until` on {threads} threads, after a 32-world warm-up; no polishing."
    )?;
    writeln!(
        out,
        "  A scene row explores its unedited motion: no constraints, so a world is the whole motion. A"
    )?;
    writeln!(
        out,
        "  session row explores where its paper session (tests/sessions/<scene>.keys) leaves the editor:"
    )?;
    writeln!(
        out,
        "  worlds stop just past the last constrained time. skipped: failed or non-finite worlds;"
    )?;
    writeln!(
        out,
        "  pruned: not simulated, their style term alone scoring them below every group that can be"
    )?;
    writeln!(
        out,
        "  kept (the alternatives are the same); worlds/s counts the simulated worlds, up to `until`."
    )?;
    writeln!(
        out,
        "  sequences: distinct collision signatures among the worlds (one alternative each)."
    )?;
    writeln!(
        out,
        "  *: no free controls in the scene; the initial state of every body was freed."
    )?;
    for (sessions, what) in [(false, "whole motions"), (true, "after the sessions")] {
        let rows: Vec<&(bool, String, f64)> = single.iter().filter(|r| r.0 == sessions).collect();
        if rows.is_empty() {
            continue;
        }
        let missed: Vec<String> = rows
            .iter()
            .filter(|(_, _, r)| r.is_nan() || *r < TARGET)
            .map(|(_, n, r)| format!("{n} {}", num(*r, 0)))
            .collect();
        writeln!(
            out,
            "  target: ≥ {TARGET:.0} worlds/s for single-body scenes, {what}: met on {}/{}{}",
            rows.len() - missed.len(),
            rows.len(),
            if missed.is_empty() {
                String::new()
            } else {
                format!(" (missed: {})", missed.join(", "))
            }
        )?;
    }
    Ok(())
}
