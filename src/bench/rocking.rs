//! Rocking to rest, in section `scaling`: what a body that lands and
//! rocks or pivots before it rests costs — the motions the paper sessions
//! leave (the scissors somersaulting onto the coatrack's peg, the plank
//! landing on its supports) and a box dropped onto one edge. Each row is
//! one simulation with tangents, as the editor pays for it after an edit.

use super::cases::{Case, paper};
use super::measure::{Plan, guarded, measure};
use super::table::{Align, Table, ms, num};
use crate::controls::Controls;
use crate::geometry::Geometry;
use crate::math::Vec3;
use crate::scene::Scene;
use crate::sim::{SimOptions, Trajectory, simulate};
use crate::testkit;
use std::io::{self, Write};

/// A 0.3 × 0.2 × 0.1 m box dropped from 5 cm onto one long edge, tilted
/// 0.4 rad, restitution 0.3 on a grippy floor: it rocks onto a face.
fn box_on_an_edge() -> Result<Scene, String> {
    let mut scene = testkit::scene(2.0);
    scene.name = "box on an edge".into();
    let g = Geometry::cuboid(Vec3::new(0.15, 0.1, 0.05)).map_err(|e| e.to_string())?;
    let tilt = 0.4_f64;
    let low = 0.1 * tilt.sin() + 0.05 * tilt.cos();
    let mut b = testkit::body("box", g, Vec3::new(0.0, 0.0, low + 0.05));
    b.orientation = Vec3::new(tilt, 0.0, 0.0);
    b.restitution = 0.3;
    b.friction = 0.8;
    scene.bodies.push(b);
    let mut ground = testkit::ground();
    ground.friction = 0.8;
    scene.obstacles.push(ground);
    scene.effects.friction = true;
    Ok(scene)
}

/// The motion a paper session leaves, as a scene whose initial state and
/// event parameters are the session's result.
fn after_session(name: &str, case: &Case) -> Option<Result<(Scene, Controls), String>> {
    let editor = super::explore::session(name, case)?;
    Some(editor.map(|e| (e.scene().clone(), e.controls().clone())))
}

/// A motion to time, or why it could not be set up.
type Row = (String, Result<(Scene, Controls), String>);

/// When the last body came to rest, if all did.
fn rests_at(tr: &Trajectory) -> Option<f64> {
    tr.tracks
        .iter()
        .map(|track| track.segments.last().filter(|s| s.rest).map(|s| s.t0))
        .try_fold(0.0_f64, |latest, t| t.map(|t| latest.max(t)))
}

pub(crate) fn print(out: &mut dyn Write, plan: &Plan) -> io::Result<()> {
    let mut rows: Vec<Row> = Vec::new();
    for entry in paper() {
        if !matches!(entry.name, "plank" | "scissors-bounce") {
            continue;
        }
        let row = match &entry.case {
            Ok(case) => after_session(entry.name, case),
            Err(e) => Some(Err(e.clone())),
        };
        if let Some(row) = row {
            rows.push((format!("{} session", entry.name), row));
        }
    }
    rows.push((
        "box on an edge".into(),
        box_on_an_edge().map(|s| {
            let c = Controls::new(&s);
            (s, c)
        }),
    ));
    let mut t = Table::new(&[
        ("motion", Align::Left),
        ("events", Align::Right),
        ("micro", Align::Right),
        ("rests at [s]", Align::Right),
        ("sim [ms]", Align::Right),
        ("reps", Align::Right),
    ]);
    for (name, row) in rows {
        let lead = vec![name];
        let result = row.and_then(|(scene, controls)| {
            guarded(|| {
                measure(plan, || simulate(&scene, &controls, &SimOptions::default()))
                    .map_err(|e| e.to_string())
            })
        });
        match result {
            Ok((timing, tr)) => {
                let mut c = lead;
                c.extend([
                    tr.events.len().to_string(),
                    tr.events.iter().filter(|e| e.micro).count().to_string(),
                    rests_at(&tr).map_or_else(|| "moving".into(), |t| num(t, 3)),
                    ms(timing.ms),
                    timing.reps.to_string(),
                ]);
                t.row(c);
            }
            Err(e) => t.message(lead, format!("error: {e}")),
        }
    }
    writeln!(out)?;
    write!(out, "{}", t.render())?;
    writeln!(
        out,
        "  Rocking to rest: the motions the plank and scissors-bounce sessions leave, and a box dropped onto"
    )?;
    writeln!(
        out,
        "  an edge; one simulation with tangents each; micro: micro-collisions; rests at: the last body's rest."
    )?;
    Ok(())
}
