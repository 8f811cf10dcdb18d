//! Section `latency`: replay every paper editing session
//! (`tests/sessions/*.keys`, compiled in) through the real key map, editor
//! core and renderer, and report how long updates and frames take and
//! where an update's time goes ([`crate::profile`]). Saves in the scripts
//! are skipped: a benchmark writes no files.

use super::cases::PAPER_SCENES;
use super::table::{Align, Table, ms};
use crate::edit::Editor;
use crate::profile::Part;
use crate::scene::load_str;
use crate::script::{Latency, RunResult, Step, parse_script, run_script};
use crate::tui::{Event, Key, KeyCode};
use std::io::{self, Write};

/// The paper's sessions, by scene name.
const SESSIONS: [(&str, &str); 7] = [
    ("eggs", include_str!("../../tests/sessions/eggs.keys")),
    ("plank", include_str!("../../tests/sessions/plank.keys")),
    ("mug", include_str!("../../tests/sessions/mug.keys")),
    (
        "scissors",
        include_str!("../../tests/sessions/scissors.keys"),
    ),
    (
        "scissors-bounce",
        include_str!("../../tests/sessions/scissors-bounce.keys"),
    ),
    (
        "particle-parabola",
        include_str!("../../tests/sessions/particle-parabola.keys"),
    ),
    (
        "particle-polygon",
        include_str!("../../tests/sessions/particle-polygon.keys"),
    ),
];

/// Screen size of the replays (columns, rows): the design size.
const SCREEN: (u16, u16) = (80, 24);

/// The parts an update is made of (the view and the render happen between
/// updates, per frame).
const UPDATE_PARTS: [Part; 5] = [
    Part::Linearise,
    Part::Trials,
    Part::Sampling,
    Part::Resimulate,
    Part::Estimate,
];

/// Milliseconds of `part` spent in the keys' updates (not in the pauses
/// after them, [`RunResult::paused`]).
fn in_updates(r: &RunResult, part: Part) -> f64 {
    r.profile.get(part).1
}

/// `steps` without the command lines that write or quit (`:w`, `:wq`,
/// `:x`, `:q`): a replay for measuring must not touch files.
pub fn without_saves(steps: &[Step]) -> Vec<Step> {
    let mut out = Vec::with_capacity(steps.len());
    let mut i = 0;
    while i < steps.len() {
        if steps[i].event == Event::Key(Key::char(':')) {
            let end = steps[i..]
                .iter()
                .position(|s| {
                    matches!(s.event, Event::Key(k) if matches!(k.code, KeyCode::Enter | KeyCode::Esc))
                })
                .map_or(steps.len(), |k| i + k + 1);
            let first = steps.get(i + 1).map(|s| s.event);
            let saves = [Key::char('w'), Key::char('x'), Key::char('q')]
                .iter()
                .any(|k| first == Some(Event::Key(*k)));
            if !saves {
                out.extend_from_slice(&steps[i..end]);
            }
            i = end;
        } else {
            out.push(steps[i]);
            i += 1;
        }
    }
    out
}

/// The steps of paper session `name` without its saves, or why not.
pub(crate) fn session_steps(name: &str) -> Result<Vec<Step>, String> {
    let (_, keys) = SESSIONS
        .iter()
        .find(|(n, _)| *n == name)
        .ok_or_else(|| format!("no paper session for {name}"))?;
    let steps =
        parse_script(keys, &format!("tests/sessions/{name}.keys")).map_err(|e| e.to_string())?;
    Ok(without_saves(&steps))
}

/// Replay one paper session, or say why it cannot run.
fn replay(name: &str) -> Result<RunResult, String> {
    let steps = session_steps(name)?;
    let (_, scene_text) = PAPER_SCENES
        .iter()
        .find(|(n, _)| *n == name)
        .ok_or_else(|| format!("scene {name} is not compiled in"))?;
    let scene = load_str(scene_text, &format!("scenes/{name}.toml")).map_err(|e| e.to_string())?;
    let mut editor = Editor::new(scene, None).map_err(|e| e.to_string())?;
    // Deterministic: settles stop by convergence, not the clock.
    editor.set_wall_clock(false);
    editor.set_defer_motion(true);
    Ok(run_script(&mut editor, &steps, SCREEN))
}

/// The profile of a replay as a table: per part, calls, total, per update
/// and share of the update time; then the view and render per frame.
pub fn profile_table(r: &RunResult) -> String {
    let updates = r.update_ms.len().max(1) as f64;
    let total: f64 = r.update_ms.iter().sum();
    let mut t = Table::new(&[
        ("part", Align::Left),
        ("calls", Align::Right),
        ("total [ms]", Align::Right),
        ("per update [ms]", Align::Right),
        ("share", Align::Right),
    ]);
    let mut counted = 0.0;
    let share = |v: f64| {
        if total > 0.0 {
            format!("{:.0}%", 100.0 * v / total)
        } else {
            "—".into()
        }
    };
    for part in UPDATE_PARTS {
        let calls = r.profile.get(part).0;
        let v = in_updates(r, part);
        counted += v;
        t.row(vec![
            part.name().into(),
            calls.to_string(),
            ms(v),
            ms(v / updates),
            share(v),
        ]);
    }
    let other = (total - counted).max(0.0);
    t.row(vec![
        "other (paths, bookkeeping)".into(),
        String::new(),
        ms(other),
        ms(other / updates),
        share(other),
    ]);
    // The work deferred to the pauses after keys: the rest of a nudged
    // motion, its error estimate.
    for part in [Part::Resimulate, Part::Estimate] {
        let (calls, v) = r.paused.get(part);
        t.row(vec![
            format!("{} in pauses", part.name()),
            calls.to_string(),
            ms(v),
            String::new(),
            String::new(),
        ]);
    }
    let frames = r.render_ms.len().max(1) as f64;
    for part in [Part::View, Part::Render] {
        let (calls, v) = {
            let (a, b) = (r.profile.get(part), r.paused.get(part));
            (a.0 + b.0, a.1 + b.1)
        };
        t.row(vec![
            format!("{} (per frame)", part.name()),
            calls.to_string(),
            ms(v),
            ms(v / frames),
            String::new(),
        ]);
    }
    format!(
        "{} updates, {} ms in all; {} frames\n{}",
        r.update_ms.len(),
        ms(total),
        r.render_ms.len(),
        t.render()
    )
}

/// Print the section.
pub(crate) fn print(out: &mut dyn Write) -> io::Result<()> {
    let mut t = Table::new(&[
        ("session", Align::Left),
        ("updates", Align::Right),
        ("median [ms]", Align::Right),
        ("p95 [ms]", Align::Right),
        ("max [ms]", Align::Right),
        ("lin", Align::Right),
        ("trials", Align::Right),
        ("sample", Align::Right),
        ("resim", Align::Right),
        ("estim", Align::Right),
        ("frame p95 [ms]", Align::Right),
        ("pause p95 [ms]", Align::Right),
    ]);
    for (name, _) in SESSIONS {
        let r = match replay(name) {
            Ok(r) => r,
            Err(e) => {
                t.message(vec![name.into()], e);
                continue;
            }
        };
        let total: f64 = r.update_ms.iter().sum();
        let cells = |l: Option<Latency>| match l {
            Some(l) => [ms(l.median), ms(l.p95), ms(l.max)],
            None => [ms(f64::NAN), ms(f64::NAN), ms(f64::NAN)],
        };
        let mut row = vec![name.to_string(), r.update_ms.len().to_string()];
        row.extend(cells(r.update_latency()));
        for part in UPDATE_PARTS {
            let v = in_updates(&r, part);
            row.push(if total > 0.0 {
                format!("{:.0}%", 100.0 * v / total)
            } else {
                "—".into()
            });
        }
        row.push(ms(r.render_latency().map_or(f64::NAN, |l| l.p95)));
        row.push(ms(
            crate::script::latency(&r.idle_ms).map_or(f64::NAN, |l| l.p95)
        ));
        t.row(row);
    }
    writeln!(
        out,
        "  each paper session (tests/sessions/*.keys, saves skipped) on a {}×{} screen;",
        SCREEN.0, SCREEN.1
    )?;
    writeln!(
        out,
        "  shares of the update time: linearise + KKT, step trials, sampling, re-simulation, error estimate;"
    )?;
    writeln!(
        out,
        "  pause: the rest of a nudged motion, then its error estimate, done when the keys stop"
    )?;
    write!(out, "{}", t.render())?;
    super::held::print(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::script::parse_script;

    #[test]
    fn saves_and_quits_are_dropped_and_the_rest_kept() {
        let steps =
            parse_script("l :t 1<CR> :w out.toml<CR> h :wq<CR> :nail<CR>", "t").unwrap_or_default();
        let kept: String = without_saves(&steps)
            .iter()
            .map(|s| match s.event {
                Event::Key(k) => k.to_string(),
                _ => String::new(),
            })
            .collect();
        assert_eq!(kept, "l:t<Space>1<Enter>h:nail<Enter>");
    }
}
