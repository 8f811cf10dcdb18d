//! Section `work-precision` (docs/design.md §8): for each paper scene and
//! accuracy setting, the error of the final state and of the Jacobian
//! against the reference run, versus the median time of one differential
//! update (a drag constraint's solve and its trial simulations with
//! tangents, from the current motion, as in the editor).
//!
//! The measurement of one setting is [`super::accuracy`]'s, shared with
//! the editor's `:accuracy` popup.

use super::accuracy::{Measured, Wall, front, measure_setting, point};
use super::cases::{ADAPTIVE_MAX_STEP, DRAG_OFFSET, Entry, accuracy_label};
use super::measure::{Plan, guarded};
use super::plot::{Series, loglog};
use super::table::{Align, Table, csv_field, ms};
use crate::scene::{Accuracy, Method};
use std::io::{self, Write};
use std::path::Path;

/// One measured setting.
#[derive(Debug, Clone)]
pub(crate) struct Row {
    pub scene: &'static str,
    pub accuracy: Accuracy,
    pub default: bool,
    pub result: Result<Measured, String>,
}

/// The settings measured for a scene: RK4 steps, adaptive tolerances and
/// root tolerances (fewer with `quick`), plus the scene's own setting.
pub(crate) fn settings(quick: bool, default: Accuracy) -> Vec<(Accuracy, bool)> {
    let (steps, tols, roots): (&[f64], &[f64], &[f64]) = if quick {
        (&[1e-2, 1e-3], &[1e-6, 1e-8, 1e-10], &[1e-12])
    } else {
        (
            &[1e-2, 3e-3, 1e-3, 3e-4],
            &[1e-6, 1e-8, 1e-10],
            &[1e-9, 1e-12],
        )
    };
    let mut out: Vec<(Accuracy, bool)> = Vec::new();
    for &root_tol in roots {
        for &step in steps {
            out.push((
                Accuracy {
                    method: Method::Rk4 { step },
                    root_tol,
                },
                false,
            ));
        }
        for &tol in tols {
            out.push((
                Accuracy {
                    method: Method::Adaptive {
                        tol,
                        max_step: ADAPTIVE_MAX_STEP,
                    },
                    root_tol,
                },
                false,
            ));
        }
    }
    if quick {
        // The looser root tolerance at the scene's own integrator setting.
        out.push((
            Accuracy {
                root_tol: 1e-9,
                ..default
            },
            false,
        ));
    }
    match out.iter_mut().find(|(a, _)| *a == default) {
        Some(d) => d.1 = true,
        None => out.push((default, true)),
    }
    out
}

/// Measure every setting of every paper scene.
pub(crate) fn rows(plan: &Plan, entries: &[Entry]) -> Vec<Row> {
    let mut rows = Vec::new();
    for e in entries {
        let (case, prep) = match (&e.case, &e.prepared) {
            (Ok(c), Some(Ok(p))) => (c, p),
            (Err(err), _) | (_, Some(Err(err))) => {
                rows.push(Row {
                    scene: e.name,
                    accuracy: Accuracy::default(),
                    default: false,
                    result: Err(err.clone()),
                });
                continue;
            }
            (_, None) => continue,
        };
        for (accuracy, default) in settings(plan.quick, case.scene.accuracy) {
            let result = guarded(|| measure_setting(plan, &Wall::new(), case, prep, &[], accuracy));
            rows.push(Row {
                scene: e.name,
                accuracy,
                default,
                result,
            });
        }
    }
    rows
}

/// Whether a row is on its scene's Pareto front ([`front`]): no other
/// setting of the scene is both faster per update and more accurate in the
/// final state. `None` when the row has no numeric state error.
fn pareto(rows: &[Row], k: usize) -> Option<bool> {
    let mine: Vec<usize> = (0..rows.len())
        .filter(|&j| rows[j].scene == rows[k].scene)
        .collect();
    let points: Vec<Option<(f64, f64)>> = mine.iter().map(|&j| point(&rows[j].result)).collect();
    let at = mine.iter().position(|&j| j == k)?;
    front(&points).get(at).copied().flatten()
}

fn method_setting(a: &Accuracy) -> (&'static str, String) {
    match a.method {
        Method::Rk4 { step } => ("rk4", format!("h={step:.0e}")),
        Method::Adaptive { tol, .. } => ("dopri5", format!("tol={tol:.0e}")),
    }
}

/// Print the section (table, notes, plot) and write the CSV if asked.
pub(crate) fn print(
    out: &mut dyn Write,
    rows: &[Row],
    entries: &[Entry],
    csv: Option<&Path>,
) -> io::Result<()> {
    let mut t = Table::new(&[
        ("scene", Align::Left),
        ("method", Align::Left),
        ("setting", Align::Left),
        ("root tol", Align::Right),
        ("state error", Align::Right),
        ("J error", Align::Right),
        ("sim+J [ms]", Align::Right),
        ("update [ms]", Align::Right),
        ("reps", Align::Right),
        ("default", Align::Left),
        ("pareto", Align::Left),
    ]);
    let mut last = "";
    for (k, r) in rows.iter().enumerate() {
        let name = if r.scene == last {
            String::new()
        } else {
            r.scene.to_string()
        };
        last = r.scene;
        let (method, setting) = method_setting(&r.accuracy);
        let lead = vec![
            name,
            method.into(),
            setting,
            format!("{:.0e}", r.accuracy.root_tol),
        ];
        match &r.result {
            Ok(m) => {
                let mut cells = lead;
                cells.extend([
                    m.state.cell(),
                    m.jacobian.cell(),
                    ms(m.simulation.ms),
                    ms(m.update.ms),
                    format!("{}/{}", m.simulation.reps, m.update.reps),
                    if r.default {
                        "default".into()
                    } else {
                        String::new()
                    },
                    match pareto(rows, k) {
                        Some(true) => "front".into(),
                        Some(false) => String::new(),
                        None => "—".into(),
                    },
                ]);
                t.row(cells);
            }
            Err(e) => t.message(lead, format!("error: {e}")),
        }
    }
    write!(out, "{}", t.render())?;
    write!(
        out,
        "  state error: largest ‖Δq‖ over bodies at the final time (tangent coordinates, SI units); J error:
  largest column-wise relative error of the Jacobian at the comparison time; both against the reference
  run. \"different events (k/n)\": the collision sequence differs from the reference (k of its n events
  agree in order), so no error is computed. sim+J: one simulation with tangents; update: one
  differential update from the current motion, as the editor runs it (drag of body 0 by {DRAG_OFFSET} m in
  x and z at the drag time: KKT solve, trial simulations with tangents, any step halving and sampling); reps: timed runs of each. pareto: front = no other setting of the scene
  is both faster per update (by 25 %) and more accurate (state error smaller by 2x; errors below
  1e-13 count as equal); — = no state error to place.
"
    )?;
    for e in entries {
        let Some(Ok(prep)) = &e.prepared else {
            continue;
        };
        let mine: Vec<usize> = (0..rows.len())
            .filter(|&k| rows[k].scene == e.name)
            .collect();
        let verdict = match mine.iter().find(|&&k| rows[k].default) {
            Some(&k) => match (&rows[k].result, pareto(rows, k)) {
                (Err(_), _) => "failed".to_string(),
                (Ok(_), Some(true)) => "on the Pareto front".into(),
                (Ok(_), Some(false)) => "not on the Pareto front".into(),
                (Ok(m), None) => format!("not placed (state error: {})", m.state.cell()),
            },
            None => "not measured".into(),
        };
        let default = e
            .case
            .as_ref()
            .map(|c| accuracy_label(&c.scene.accuracy))
            .unwrap_or_default();
        writeln!(
            out,
            "  {}: default {default}: {verdict}; comparison at t = {:.3} s, drag at {:.3} s; reference {}",
            e.name, prep.t_eval, prep.t_drag, prep.reference.note
        )?;
        let pops: Vec<String> = mine
            .iter()
            .filter_map(|&k| rows[k].result.as_ref().ok().map(|m| (k, m)))
            .filter(|(_, m)| !m.diagnostics.is_empty())
            .map(|(k, m)| {
                format!(
                    "{}: {}",
                    accuracy_label(&rows[k].accuracy),
                    m.diagnostics.join("; ")
                )
            })
            .collect();
        if !pops.is_empty() {
            writeln!(out, "    update diagnostics: {}", pops.join(" | "))?;
        }
    }
    // The plot: state error against update time, one letter per scene.
    let marks = ['a', 'b', 'c', 'd', 'e', 'f', 'g', 'h'];
    let series: Vec<Series> = entries
        .iter()
        .enumerate()
        .map(|(i, e)| Series {
            label: e.name.to_string(),
            mark: marks[i % marks.len()],
            points: rows
                .iter()
                .filter(|r| r.scene == e.name)
                .filter_map(|r| r.result.as_ref().ok())
                .filter_map(|m| m.state.value().map(|v| (m.update.ms, v.max(1e-16))))
                .collect(),
        })
        .collect();
    writeln!(out)?;
    writeln!(
        out,
        "  final-state error vs time per update (log-log; settings with different events are not drawn; 0 drawn at 1e-16)"
    )?;
    write!(
        out,
        "{}",
        loglog(&series, 64, 16, "update time [ms]", "error")
    )?;
    if let Some(path) = csv {
        match write_csv(path, rows) {
            Ok(()) => writeln!(out, "  wrote {} rows to {}", rows.len(), path.display())?,
            Err(e) => writeln!(out, "  could not write {}: {e}", path.display())?,
        }
    }
    Ok(())
}

fn write_csv(path: &Path, rows: &[Row]) -> io::Result<()> {
    let mut s =
        String::from("scene,method,setting,root_tol,state_error,jacobian_error,update_ms\n");
    for r in rows {
        let (method, _) = method_setting(&r.accuracy);
        let setting = match r.accuracy.method {
            Method::Rk4 { step } => format!("{step:e}"),
            Method::Adaptive { tol, .. } => format!("{tol:e}"),
        };
        let (state, jac, update) = match &r.result {
            Ok(m) => (
                m.state.csv(),
                m.jacobian.csv(),
                if m.update.ms.is_finite() {
                    format!("{:.6}", m.update.ms)
                } else {
                    String::new()
                },
            ),
            Err(e) => (format!("error: {e}"), format!("error: {e}"), String::new()),
        };
        let fields = [
            r.scene.to_string(),
            method.to_string(),
            setting,
            format!("{:e}", r.accuracy.root_tol),
            state,
            jac,
            update,
        ];
        s.push_str(
            &fields
                .iter()
                .map(|f| csv_field(f))
                .collect::<Vec<_>>()
                .join(","),
        );
        s.push('\n');
    }
    std::fs::write(path, s)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_setting_is_marked_once() {
        let d = Accuracy {
            method: Method::Adaptive {
                tol: 1e-9,
                max_step: ADAPTIVE_MAX_STEP,
            },
            root_tol: 1e-12,
        };
        let s = settings(true, d);
        assert_eq!(s.iter().filter(|(_, def)| *def).count(), 1);
        assert_eq!(
            s.last().map(|x| x.0),
            Some(d),
            "appended when not among the settings"
        );
        let d = Accuracy {
            method: Method::Rk4 { step: 1e-3 },
            root_tol: 1e-12,
        };
        let s = settings(false, d);
        assert_eq!(s.len(), 14, "4 steps + 3 tolerances, at 2 root tolerances");
        assert_eq!(s.iter().filter(|(_, def)| *def).count(), 1);
    }

    use crate::bench::accuracy::Error;
    use crate::bench::measure::Timing;

    fn row(ms: f64, state: Error) -> Row {
        let t = Timing { ms, reps: 1 };
        Row {
            scene: "s",
            accuracy: Accuracy::default(),
            default: false,
            result: Ok(Measured {
                state,
                jacobian: Error::Value(0.0),
                simulation: t,
                update: t,
                diagnostics: Vec::new(),
            }),
        }
    }

    #[test]
    fn the_front_ignores_noise_and_round_off() {
        let rows = vec![
            row(10.0, Error::Value(1e-6)),
            row(5.0, Error::Value(1e-8)),   // dominates the first
            row(5.2, Error::Value(0.9e-8)), // not 25 % slower and not 2x less accurate than row 1
            row(1.0, Error::Value(1e-3)),
            row(20.0, Error::Value(1e-16)),
            row(30.0, Error::Value(0.0)), // round-off like row 4: not dominated by it
            row(0.5, Error::DifferentEvents { agree: 1, total: 2 }),
        ];
        let front: Vec<Option<bool>> = (0..rows.len()).map(|k| pareto(&rows, k)).collect();
        assert_eq!(
            front,
            [
                Some(false),
                Some(true),
                Some(true),
                Some(true),
                Some(true),
                Some(true),
                None
            ]
        );
    }
}
