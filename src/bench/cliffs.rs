//! Section `cliffs`: scenes whose cost is out of proportion to what they
//! show, tracked so a change that removes (or worsens) the cliff shows in
//! a table. Today: a fine ellipsoid rocking to rest on the ground costs
//! hundreds of micro-collisions per body, since a body at rest on a curved
//! surface is a series of tiny impacts, not a sustained contact.

use super::measure::{Plan, Timing, guarded, measure};
use super::table::{Align, Table, ms};
use crate::controls::Controls;
use crate::geometry::Geometry;
use crate::math::Vec3;
use crate::scene::Scene;
use crate::sim::{SimOptions, simulate};
use crate::testkit;
use std::io::{self, Write};

/// `n` ellipsoids of `resolution` rings, dropped tilted onto the ground a
/// metre apart, rocking to rest over 2 s.
fn rocking_ellipsoids(n: usize, resolution: u32) -> Result<Scene, String> {
    let mut scene = testkit::scene(2.0);
    scene.name = format!("{n} rocking ellipsoids");
    let g = Geometry::ellipsoid(Vec3::new(0.2, 0.12, 0.08), resolution, 1.0)
        .map_err(|e| e.to_string())?;
    for i in 0..n {
        let mut b = testkit::body(
            &format!("ellipsoid{i}"),
            g.clone(),
            Vec3::new(i as f64, 0.0, 0.3),
        );
        b.orientation = Vec3::new(0.3, 0.2, 0.0);
        b.restitution = 0.3;
        scene.bodies.push(b);
    }
    scene.obstacles.push(testkit::ground());
    Ok(scene)
}

/// Time of one simulation (no tangents) and its events.
fn run(plan: &Plan, scene: &Scene) -> Result<(Timing, usize), String> {
    guarded(|| {
        let controls = Controls::new(scene);
        let opts = SimOptions::without_tangents();
        let (t, tr) =
            measure(plan, || simulate(scene, &controls, &opts)).map_err(|e| e.to_string())?;
        Ok((t, tr.events.len()))
    })
}

/// Print the section.
pub(crate) fn print(out: &mut dyn Write, plan: &Plan) -> io::Result<()> {
    let cases: &[(usize, u32)] = if plan.quick {
        &[(1, 16), (1, 64)]
    } else {
        &[(1, 16), (1, 64), (2, 64), (4, 64)]
    };
    let mut t = Table::new(&[
        ("bodies", Align::Right),
        ("rings", Align::Right),
        ("events", Align::Right),
        ("events/body", Align::Right),
        ("sim [ms]", Align::Right),
        ("per event [ms]", Align::Right),
        ("reps", Align::Right),
    ]);
    for &(n, resolution) in cases {
        let lead = vec![n.to_string(), resolution.to_string()];
        match rocking_ellipsoids(n, resolution).and_then(|s| run(plan, &s)) {
            Ok((timing, events)) => {
                let mut c = lead;
                c.extend([
                    events.to_string(),
                    (events / n).to_string(),
                    ms(timing.ms),
                    ms(timing.ms / events.max(1) as f64),
                    timing.reps.to_string(),
                ]);
                t.row(c);
            }
            Err(e) => t.message(lead, format!("error: {e}")),
        }
    }
    write!(out, "{}", t.render())?;
    writeln!(
        out,
        "  Ellipsoids 0.4 × 0.24 × 0.16 m dropped tilted from 0.3 m onto the ground, restitution 0.3, 2 s, no"
    )?;
    writeln!(
        out,
        "  tangents. Coming to rest on a curved hull is a series of micro-collisions, each a root search:"
    )?;
    writeln!(
        out,
        "  hundreds per body, each dearer on a finer hull. Sustained contact would remove most of them."
    )?;
    Ok(())
}
