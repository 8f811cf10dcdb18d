//! Section `effects` (docs/design.md §3): a box tossed onto the ground with every
//! effect listed, and each effect switched off in turn. The effect's
//! evaluation counter proves that an unlisted effect is never evaluated.

use super::measure::{Plan, Timing, guarded, measure};
use super::table::{Align, Table, ms};
use crate::controls::Controls;
use crate::geometry::Geometry;
use crate::math::Vec3;
use crate::scene::{Effect, Effects, Scene};
use crate::sim::{Counters, SimOptions, simulate};
use crate::testkit;
use std::io::{self, Write};

/// A 0.4 × 0.3 × 0.2 m box tossed up and spinning, landing on the ground
/// with drag, friction and the gyroscopic term.
pub(crate) fn tossed_box() -> Result<Scene, String> {
    let mut scene = testkit::scene(2.0);
    scene.name = "tossed box".into();
    scene.effects = Effects {
        gravity: true,
        drag: true,
        gyroscopic: true,
        collisions: true,
        friction: true,
    };
    let g = Geometry::cuboid(Vec3::new(0.2, 0.15, 0.1)).map_err(|e| e.to_string())?;
    let mut b = testkit::body("box", g, Vec3::new(0.0, 0.0, 1.0));
    b.velocity = Vec3::new(1.0, 0.0, 2.0);
    b.angular_velocity = Vec3::new(1.0, 4.0, 0.5);
    b.restitution = 0.5;
    b.friction = 0.5;
    b.drag = 0.5;
    scene.bodies.push(b);
    scene.obstacles.push(testkit::ground());
    Ok(scene)
}

fn count(c: &Counters, e: Effect) -> u64 {
    match e {
        Effect::Gravity => c.gravity.get(),
        Effect::Drag => c.drag.get(),
        Effect::Gyroscopic => c.gyroscopic.get(),
        Effect::Collisions => c.collisions.get(),
        Effect::Friction => c.friction.get(),
    }
}

/// Time of one simulation (no tangents), the counted effect's evaluations
/// and the number of events.
fn run(plan: &Plan, scene: &Scene, e: Effect) -> Result<(Timing, u64, usize), String> {
    guarded(|| {
        let controls = Controls::new(scene);
        let (t, tr) = measure(plan, || {
            simulate(scene, &controls, &SimOptions::without_tangents())
        })
        .map_err(|e| e.to_string())?;
        Ok((t, count(&tr.counters, e), tr.events.len()))
    })
}

/// Print the section.
pub(crate) fn print(out: &mut dyn Write, plan: &Plan) -> io::Result<()> {
    let base = match tossed_box() {
        Ok(s) => s,
        Err(e) => return writeln!(out, "  error: {e}"),
    };
    let mut t = Table::new(&[
        ("effect", Align::Left),
        ("off: sim [ms]", Align::Right),
        ("evaluations", Align::Right),
        ("events", Align::Right),
        ("on: sim [ms]", Align::Right),
        ("evaluations", Align::Right),
        ("events", Align::Right),
        ("reps off/on", Align::Right),
    ]);
    for e in Effect::ALL {
        let mut off = base.clone();
        off.effects.set(e, false);
        let row = run(plan, &off, e).and_then(|a| run(plan, &base, e).map(|b| (a, b)));
        match row {
            Ok(((t0, c0, n0), (t1, c1, n1))) => t.row(vec![
                e.name().into(),
                ms(t0.ms),
                c0.to_string(),
                n0.to_string(),
                ms(t1.ms),
                c1.to_string(),
                n1.to_string(),
                format!("{}/{}", t0.reps, t1.reps),
            ]),
            Err(err) => t.message(vec![e.name().into()], format!("error: {err}")),
        }
    }
    write!(out, "{}", t.render())?;
    writeln!(
        out,
        "  A 0.4 × 0.3 × 0.2 m box tossed onto the ground for 2 s with all five effects listed (\"on\"), and"
    )?;
    writeln!(
        out,
        "  with only the named effect removed (\"off\"). evaluations: that effect's counter in the last run"
    )?;
    writeln!(
        out,
        "  (gravity/drag: closed-form flight evaluations, gyroscopic: right-hand sides of the rotation ODE,"
    )?;
    writeln!(
        out,
        "  collisions: contact queries, friction: frictional impulses). 0 when off: unused effects cost nothing."
    )?;
    Ok(())
}
