//! Section `scaling`: how the time of one simulation with its Jacobian
//! grows with the number of bodies, the horizon and the number of free
//! controls, on balls bouncing in a box (ground and four walls, every
//! body–body pair listed, seeded random velocities).

use super::measure::{Plan, Timing, guarded, loglog_slope, measure};
use super::table::{Align, Table, ms, num};
use crate::controls::Controls;
use crate::scene::Scene;
use crate::sim::{SimOptions, simulate};
use crate::testkit;
use std::io::{self, Write};

/// Ball radius, m.
const RADIUS: f64 = crate::testkit::BALL_RADIUS;

/// `n` balls in a box of restitution 1 (see [`testkit::balls_in_box`]).
pub(crate) fn balls_in_box(
    n: usize,
    horizon: f64,
    free: usize,
    seed: u64,
) -> Result<Scene, String> {
    testkit::balls_in_box(n, horizon, free, seed, 1.0)
}

struct Point {
    sweep: &'static str,
    value: f64,
    bodies: usize,
    horizon: f64,
    m: usize,
    result: Result<(Timing, usize), String>,
}

fn run_point(
    plan: &Plan,
    n: usize,
    horizon: f64,
    free: usize,
) -> (usize, Result<(Timing, usize), String>) {
    let scene = match balls_in_box(n, horizon, free, 0x5ca1_ab1e) {
        Ok(s) => s,
        Err(e) => return (0, Err(e)),
    };
    let controls = Controls::new(&scene);
    let m = controls.m();
    let r = guarded(|| {
        let (t, tr) = measure(plan, || simulate(&scene, &controls, &SimOptions::default()))
            .map_err(|e| e.to_string())?;
        Ok((t, tr.events.len()))
    });
    (m, r)
}

/// Print the section.
pub(crate) fn print(out: &mut dyn Write, plan: &Plan) -> io::Result<()> {
    let (ns, horizons, frees, n_h, n_m): (&[usize], &[f64], &[usize], usize, usize) = if plan.quick
    {
        (&[1, 4, 16], &[0.5, 1.0, 2.0, 4.0], &[1, 2, 4], 4, 4)
    } else {
        (
            &[1, 4, 16, 64],
            &[0.5, 1.0, 2.0, 4.0, 8.0],
            &[1, 2, 4, 8],
            16,
            8,
        )
    };
    let mut points = Vec::new();
    for &n in ns {
        let (m, result) = run_point(plan, n, 1.0, 1);
        points.push(Point {
            sweep: "bodies N",
            value: n as f64,
            bodies: n,
            horizon: 1.0,
            m,
            result,
        });
    }
    for &h in horizons {
        let (m, result) = run_point(plan, n_h, h, 1);
        points.push(Point {
            sweep: "horizon T",
            value: h,
            bodies: n_h,
            horizon: h,
            m,
            result,
        });
    }
    for &f in frees {
        let (m, result) = run_point(plan, n_m, 1.0, f);
        points.push(Point {
            sweep: "controls m",
            value: m as f64,
            bodies: n_m,
            horizon: 1.0,
            m,
            result,
        });
    }
    let mut t = Table::new(&[
        ("sweep", Align::Left),
        ("N", Align::Right),
        ("T [s]", Align::Right),
        ("m", Align::Right),
        ("pairs", Align::Right),
        ("events", Align::Right),
        ("sim+J [ms]", Align::Right),
        ("per event [ms]", Align::Right),
        ("reps", Align::Right),
    ]);
    let mut last = "";
    for p in &points {
        let name = if p.sweep == last {
            String::new()
        } else {
            p.sweep.to_string()
        };
        last = p.sweep;
        let lead = vec![
            name,
            p.bodies.to_string(),
            num(p.horizon, 1),
            p.m.to_string(),
            (p.bodies * (p.bodies - 1) / 2 + 5 * p.bodies).to_string(),
        ];
        match &p.result {
            Ok((timing, events)) => {
                let mut c = lead;
                c.extend([
                    events.to_string(),
                    ms(timing.ms),
                    ms(timing.ms / (*events).max(1) as f64),
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
        "  Balls of radius {RADIUS} m, restitution 1, in a box of floor area ≈ N m² (ground + 4 walls), all"
    )?;
    writeln!(
        out,
        "  body–body pairs listed (pairs = body–body + body–obstacle); time of one simulation with tangents"
    )?;
    writeln!(
        out,
        "  (a drag update would add a few trial simulations and a small m×m solve, and its sampling fallback"
    )?;
    writeln!(
        out,
        "  makes the time depend on the collision sequence). Growth exponents (log-log least squares):"
    )?;
    for (sweep, what) in [("bodies N", "N"), ("horizon T", "T"), ("controls m", "m")] {
        let pts: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.sweep == sweep)
            .filter_map(|p| p.result.as_ref().ok().map(|(t, _)| (p.value, t.ms)))
            .collect();
        let k = loglog_slope(&pts);
        let events: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.sweep == sweep)
            .filter_map(|p| p.result.as_ref().ok().map(|(_, e)| (p.value, *e as f64)))
            .collect();
        let ke = loglog_slope(&events);
        let verdict = if !k.is_finite() {
            "not measured"
        } else if k < 1.15 {
            "near-linear or better"
        } else if k < 1.5 {
            "mildly super-linear"
        } else if k < 1.8 {
            "super-linear"
        } else {
            "about quadratic or worse"
        };
        writeln!(
            out,
            "  time ∝ {what}^{}: {verdict}; events ∝ {what}^{}, time per event ∝ {what}^{}",
            num(k, 2),
            num(ke, 2),
            num(k - ke, 2)
        )?;
    }
    settling(out, plan)?;
    super::rocking::print(out, plan)
}

/// Balls that settle: restitution 0.5 and 0.8, N up to 256, a horizon of
/// [`SETTLE_T`] s, without tangents (the states alone: what a solver trial
/// costs); slow contacts between balls are micro-collisions or islands
/// that rest (`sim::run::islands`).
const SETTLE_T: f64 = 4.0;

fn settling(out: &mut dyn Write, plan: &Plan) -> io::Result<()> {
    let ns: &[usize] = if plan.quick {
        &[1, 4, 16, 64]
    } else {
        &[1, 4, 16, 64, 256]
    };
    let mut t = Table::new(&[
        ("e", Align::Right),
        ("N", Align::Right),
        ("events", Align::Right),
        ("micro", Align::Right),
        ("resting", Align::Right),
        ("ms per sim. s", Align::Right),
        ("per event [ms]", Align::Right),
        ("reps", Align::Right),
    ]);
    for e in [0.5, 0.8] {
        for &n in ns {
            let lead = vec![num(e, 1), n.to_string()];
            let scene = match testkit::balls_in_box(n, SETTLE_T, 0, 0x5ca1_ab1e, e) {
                Ok(s) => s,
                Err(err) => {
                    t.message(lead, format!("error: {err}"));
                    continue;
                }
            };
            let controls = Controls::new(&scene);
            let r = guarded(|| {
                measure(plan, || {
                    simulate(&scene, &controls, &SimOptions::without_tangents())
                })
                .map_err(|err| err.to_string())
            });
            match r {
                Ok((timing, tr)) => {
                    let events = tr.events.len();
                    let resting = (0..n)
                        .filter(|&i| tr.resting(i, SETTLE_T, crate::sim::Side::Post))
                        .count();
                    let mut c = lead;
                    c.extend([
                        events.to_string(),
                        tr.events.iter().filter(|ev| ev.micro).count().to_string(),
                        resting.to_string(),
                        ms(timing.ms / SETTLE_T),
                        ms(timing.ms / events.max(1) as f64),
                        timing.reps.to_string(),
                    ]);
                    t.row(c);
                }
                Err(err) => t.message(lead, format!("error: {err}")),
            }
        }
    }
    writeln!(out)?;
    write!(out, "{}", t.render())?;
    writeln!(
        out,
        "  Balls in a box at restitution e for {SETTLE_T} s, states only (no tangents); micro: micro-collisions,"
    )?;
    writeln!(
        out,
        "  resting: balls frozen at the end (alone or as an island of balls resting on balls)."
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn balls_fill_a_box_with_all_pairs() {
        let s = balls_in_box(5, 1.0, 2, 1).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s.bodies.len(), 5);
        assert_eq!(s.pairs.len(), 10);
        assert_eq!(s.obstacles.len(), 5);
        assert_eq!(Controls::new(&s).m(), 12);
        // Every ball starts inside the walls, above the ground, apart from the others.
        for (i, a) in s.bodies.iter().enumerate() {
            assert!(
                a.position.x.abs() < 1.5 - RADIUS
                    && a.position.y.abs() < 1.5 - RADIUS
                    && a.position.z > RADIUS
            );
            for b in &s.bodies[i + 1..] {
                assert!((a.position - b.position).norm() > 2.0 * RADIUS);
            }
        }
        let again = balls_in_box(5, 1.0, 2, 1).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(again.bodies[3].velocity, s.bodies[3].velocity, "seeded");
    }
}
