//! Sections `jacobian` and `methods`: the tangent
//! Jacobian against central and forward finite differences, in time and in
//! error, per paper scene. Both sections print from one shared study.

use super::cases::{Case, Entry, Prepared, signature_until};
use super::fd::{FdRuns, relative_error, stacked};
use super::measure::{Plan, Timing, guarded, measure, median};
use super::table::{Align, MISSING, Table, ms, ratio, sci};
use crate::sim::{SimOptions, simulate};
use crate::tangent::Scheme;
use std::io::{self, Write};

/// Smallest error used in accuracy ratios: relative Jacobian errors below
/// this are round-off (the event times themselves are only found to about
/// 1e-12), so an "exact" tangent does not make the ratio astronomical.
const ERROR_FLOOR: f64 = 1e-12;

/// One scene's Jacobian study.
#[derive(Debug, Clone)]
pub(crate) struct Study {
    pub m: usize,
    /// Collision events of the default run.
    pub events: usize,
    pub bodies: usize,
    pub freed: bool,
    pub t_eval: f64,
    pub eval_note: String,
    pub reference: String,
    /// One simulation with tangents and the stacked Jacobian read at `t_eval`.
    pub tangent: Timing,
    /// One simulation without tangents.
    pub plain: Timing,
    pub central: Timing,
    pub forward: Timing,
    pub central_sims: usize,
    pub forward_sims: usize,
    /// Comparable columns of each scheme (events up to `t_eval` unchanged).
    pub central_cols: usize,
    pub forward_cols: usize,
    pub central_vs_tangent: Option<f64>,
    pub forward_vs_tangent: Option<f64>,
    /// Against the reference run's tangent Jacobian (or why not).
    pub tangent_vs_ref: Result<f64, String>,
    /// The tangent against the reference over central differences'
    /// comparable columns only: the like-for-like accuracy comparison.
    pub tangent_vs_ref_central_cols: Result<f64, String>,
    pub central_vs_ref: Result<f64, String>,
    pub forward_vs_ref: Result<f64, String>,
}

fn run_study(plan: &Plan, case: &Case, prep: &Prepared) -> Result<Study, String> {
    let (scene, controls, t) = (&case.scene, &case.controls, prep.t_eval);
    let (tangent, (traj, jt)) = measure(plan, || {
        let tr = simulate(scene, controls, &SimOptions::default()).map_err(|e| e.to_string())?;
        let j = stacked(&tr, t).map_err(|e| e.to_string())?;
        Ok::<_, String>((tr, j))
    })?;
    let (plain, _) = measure(plan, || {
        simulate(scene, controls, &SimOptions::without_tangents())
    })
    .map_err(|e| e.to_string())?;
    let (central, fc) = measure(plan, || FdRuns::new(scene, controls, Scheme::Central))
        .map_err(|e| format!("central differences: {e}"))?;
    let (forward, ff) = measure(plan, || FdRuns::new(scene, controls, Scheme::Forward))
        .map_err(|e| format!("forward differences: {e}"))?;
    let (jc, mc) = fc.jacobian(t);
    let (jf, mf) = ff.jacobian(t);
    let reference = &prep.reference.traj;
    let ref_sig = signature_until(reference, t);
    let own_sig = signature_until(&traj, t);
    let against_ref = |j: &nalgebra::DMatrix<f64>, mask: &[bool]| -> Result<f64, String> {
        if ref_sig != own_sig {
            return Err(format!(
                "different events ({} vs {} before t)",
                own_sig.len(),
                ref_sig.len()
            ));
        }
        let jr = stacked(reference, t).map_err(|e| format!("reference: {e}"))?;
        relative_error(j, &jr, mask).ok_or_else(|| "no comparable column".to_string())
    };
    let all = vec![true; controls.m()];
    Ok(Study {
        m: controls.m(),
        events: traj.events.len(),
        bodies: scene.bodies.len(),
        freed: case.freed,
        t_eval: t,
        eval_note: prep.eval_note.clone(),
        reference: prep.reference.note.clone(),
        tangent,
        plain,
        central,
        forward,
        central_sims: fc.simulations(),
        forward_sims: ff.simulations(),
        central_cols: mc.iter().filter(|c| **c).count(),
        forward_cols: mf.iter().filter(|c| **c).count(),
        central_vs_tangent: relative_error(&jc, &jt, &mc),
        forward_vs_tangent: relative_error(&jf, &jt, &mf),
        tangent_vs_ref: against_ref(&jt, &all),
        tangent_vs_ref_central_cols: against_ref(&jt, &mc),
        central_vs_ref: against_ref(&jc, &mc),
        forward_vs_ref: against_ref(&jf, &mf),
    })
}

/// Run the study for every paper scene (each row's failure is kept as its error).
pub(crate) fn studies(
    plan: &Plan,
    entries: &[Entry],
) -> Vec<(&'static str, Result<Study, String>)> {
    entries
        .iter()
        .map(|e| {
            let r = match (&e.case, &e.prepared) {
                (Err(err), _) => Err(err.clone()),
                (_, None) => Err("not prepared".into()),
                (_, Some(Err(err))) => Err(err.clone()),
                (Ok(case), Some(Ok(prep))) => guarded(|| run_study(plan, case, prep)),
            };
            (e.name, r)
        })
        .collect()
}

fn err_cell(e: &Result<f64, String>) -> String {
    match e {
        Ok(v) => sci(*v),
        Err(m) if m.starts_with("different events") => "diff. events".into(),
        Err(_) => MISSING.into(),
    }
}

fn opt_sci(e: Option<f64>) -> String {
    e.map(sci).unwrap_or_else(|| MISSING.into())
}

fn scene_label(name: &str, s: &Study) -> String {
    if s.freed {
        format!("{name}*")
    } else {
        name.to_string()
    }
}

/// Section `jacobian`.
pub(crate) fn print_jacobian(
    out: &mut dyn Write,
    studies: &[(&'static str, Result<Study, String>)],
) -> io::Result<()> {
    let mut t = Table::new(&[
        ("scene", Align::Left),
        ("m", Align::Right),
        ("events", Align::Right),
        ("at t [s]", Align::Right),
        ("sim+J [ms]", Align::Right),
        ("sim [ms]", Align::Right),
        ("J cost", Align::Right),
        ("central [ms]", Align::Right),
        ("forward [ms]", Align::Right),
        ("central/tangent", Align::Right),
        ("cols c/f", Align::Right),
        ("fwd vs tan", Align::Right),
        ("cen vs tan", Align::Right),
        ("tan vs ref", Align::Right),
        ("reps", Align::Right),
    ]);
    for (name, s) in studies {
        match s {
            Ok(s) => t.row(vec![
                scene_label(name, s),
                s.m.to_string(),
                s.events.to_string(),
                format!("{:.3}", s.t_eval),
                ms(s.tangent.ms),
                ms(s.plain.ms),
                ratio(s.tangent.ms / s.plain.ms),
                ms(s.central.ms),
                ms(s.forward.ms),
                ratio(s.central.ms / s.tangent.ms),
                format!("{}/{} of {}", s.central_cols, s.forward_cols, s.m),
                opt_sci(s.forward_vs_tangent),
                opt_sci(s.central_vs_tangent),
                err_cell(&s.tangent_vs_ref),
                format!(
                    "{}/{}/{}/{}",
                    s.tangent.reps, s.plain.reps, s.central.reps, s.forward.reps
                ),
            ]),
            Err(e) => t.message(vec![name.to_string()], format!("error: {e}")),
        }
    }
    write!(out, "{}", t.render())?;
    write!(
        out,
        "  Times: medians of `reps` timed runs (sim+J / sim / central / forward) after one warm-up.
  sim+J: one simulation with tangents, plus reading every body's Jacobian at t; sim: without tangents;
  J cost = sim+J / sim, the price of the tangents (central differences cost 2m+1 sims: the nominal
  run and 2m perturbed runs, step ε^(1/3)·max(|u|,1); forward: nominal + m runs, step ε^(1/2)·max(|u|,1)).
  Errors: largest column-wise relative error ‖a−b‖/‖b‖ of the stacked Jacobian at t over comparable
  columns (cols c/f: columns whose perturbed runs keep the events up to t, central/forward);
  tan vs ref: tangents at the scene's own accuracy against tangents of the reference run (see methods).
"
    )?;
    for (name, s) in studies {
        if let Ok(s) = s {
            if s.eval_note != "final time" {
                writeln!(out, "  {name}: t = {:.3} s, {}.", s.t_eval, s.eval_note)?;
            }
            if s.freed {
                writeln!(
                    out,
                    "  {name}*: the scene has no free controls; the initial state of every body was freed."
                )?;
            }
            if let Err(e) = &s.tangent_vs_ref {
                writeln!(out, "  {name}: tan vs ref not compared: {e}.")?;
            }
        }
    }
    // Issue 3 targets.
    let ok: Vec<(&str, &Study)> = studies
        .iter()
        .filter_map(|(n, s)| s.as_ref().ok().map(|s| (*n, s)))
        .collect();
    let slow: Vec<String> = ok
        .iter()
        .filter(|(_, s)| {
            let r = s.central.ms / s.tangent.ms;
            r.is_nan() || r < 10.0
        })
        .map(|(n, s)| format!("{n} {}", ratio(s.central.ms / s.tangent.ms)))
        .collect();
    writeln!(
        out,
        "  target: tangent ≥ 10x faster than central differences: met on {}/{} scenes{}",
        ok.len() - slow.len(),
        ok.len(),
        if slow.is_empty() {
            String::new()
        } else {
            format!(" (missed: {})", slow.join(", "))
        }
    )?;
    let single: Vec<&(&str, &Study)> = ok.iter().filter(|(_, s)| s.bodies == 1).collect();
    let over: Vec<String> = single
        .iter()
        .filter(|(_, s)| s.tangent.ms.is_nan() || s.tangent.ms >= 1.0)
        .map(|(n, s)| format!("{n} {} ms", ms(s.tangent.ms)))
        .collect();
    writeln!(
        out,
        "  target: one simulation with Jacobian < 1 ms for single-body scenes: met on {}/{}{}",
        single.len() - over.len(),
        single.len(),
        if over.is_empty() {
            String::new()
        } else {
            format!(" (missed: {})", over.join(", "))
        }
    )?;
    Ok(())
}

/// Section `methods`.
pub(crate) fn print_methods(
    out: &mut dyn Write,
    studies: &[(&'static str, Result<Study, String>)],
) -> io::Result<()> {
    let mut t = Table::new(&[
        ("scene", Align::Left),
        ("m", Align::Right),
        ("tangent [ms]", Align::Right),
        ("error", Align::Right),
        ("central [ms]", Align::Right),
        ("error", Align::Right),
        ("tangent, same cols", Align::Right),
        ("forward [ms]", Align::Right),
        ("error", Align::Right),
        ("sims c/f", Align::Right),
    ]);
    for (name, s) in studies {
        match s {
            Ok(s) => t.row(vec![
                scene_label(name, s),
                s.m.to_string(),
                ms(s.tangent.ms),
                err_cell(&s.tangent_vs_ref),
                ms(s.central.ms),
                err_cell(&s.central_vs_ref),
                err_cell(&s.tangent_vs_ref_central_cols),
                ms(s.forward.ms),
                err_cell(&s.forward_vs_ref),
                format!("{}/{}", s.central_sims, s.forward_sims),
            ]),
            Err(e) => t.message(vec![name.to_string()], format!("error: {e}")),
        }
    }
    write!(out, "{}", t.render())?;
    writeln!(
        out,
        "  Each method at the scene's own accuracy; error: largest column-wise relative error of its"
    )?;
    writeln!(
        out,
        "  Jacobian at the comparison time (see jacobian) against the tangent Jacobian of the reference run;"
    )?;
    writeln!(
        out,
        "  the tangent's over all columns, the differences' over their comparable columns (see jacobian);"
    )?;
    writeln!(
        out,
        "  tangent, same cols: the tangent's error over central's comparable columns, which the summary uses."
    )?;
    writeln!(
        out,
        "  The summary's accuracy ratio floors errors at {ERROR_FLOOR:.0e} (round-off). References:"
    )?;
    for (name, s) in studies {
        if let Ok(s) = s {
            writeln!(out, "  {name}: reference {}", s.reference)?;
        }
    }
    Ok(())
}

/// Median over scenes of (central time / tangent time) and (central error
/// / tangent error), both against the reference over the same (central's
/// comparable) columns; `None` without data.
pub(crate) fn summary(
    studies: &[(&'static str, Result<Study, String>)],
) -> (Option<f64>, Option<f64>) {
    let mut speed = Vec::new();
    let mut accuracy = Vec::new();
    for s in studies.iter().filter_map(|(_, s)| s.as_ref().ok()) {
        let r = s.central.ms / s.tangent.ms;
        if r.is_finite() {
            speed.push(r);
        }
        if let (Ok(c), Ok(t)) = (&s.central_vs_ref, &s.tangent_vs_ref_central_cols) {
            accuracy.push(c.max(ERROR_FLOOR) / t.max(ERROR_FLOOR));
        }
    }
    let m = |v: &[f64]| Some(median(v)).filter(|x| x.is_finite());
    (m(&speed), m(&accuracy))
}
