//! `nudge bench`: what accuracy costs in time (docs/design.md §8). A benchmark
//! that prints tables — never a timed assertion in a test.
//!
//! Sections (select with `--only`):
//! - `jacobian`: one simulation with its tangent Jacobian against central
//!   and forward finite differences, time and error, per paper scene;
//! - `work-precision`: error of the final state and Jacobian against a
//!   tight reference versus time per differential update, per accuracy
//!   setting, with the Pareto front and a log-log braille plot (`--csv`
//!   writes the rows);
//! - `methods`: tangent, central and forward differences against the
//!   reference, in time and error;
//! - `scaling`: growth with bodies, horizon and free controls;
//! - `effects`: each effect off and on, with its evaluation count;
//! - `latency`: replay of every paper editing session, with where the
//!   update time goes;
//! - `cliffs`: scenes whose cost is out of proportion (a fine ellipsoid
//!   rocking to rest), with their event counts;
//! - `explore`: sampled worlds per second when exploring, per paper scene,
//!   and the distinct collision sequences found.
//!
//! The last line is always the summary: how much faster and more accurate
//! tangents are than central differences (median over paper scenes).
//! Every row is measured on its own: a failure prints in its row and the
//! run goes on. `--quick` runs fewer repetitions, settings and sizes.

pub(crate) mod accuracy;
mod cases;
mod cliffs;
mod effects;
mod explore;
mod fd;
mod held;
mod jacobian;
mod latency;
mod measure;
mod plot;
mod precision;
mod rocking;
mod scaling;
mod table;

pub use latency::{profile_table, without_saves};

use cases::Entry;
use jacobian::Study;
use measure::Plan;
use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

/// Options of `nudge bench`.
#[derive(Debug, Clone, Default)]
pub struct BenchArgs {
    /// A reduced run that finishes in under a minute.
    pub quick: bool,
    /// Also write the work-precision rows as CSV.
    pub csv: Option<PathBuf>,
    /// Only the sections whose name contains this.
    pub only: Option<String>,
}

/// Section names, in run order.
pub const SECTIONS: [&str; 8] = [
    "jacobian",
    "work-precision",
    "methods",
    "scaling",
    "effects",
    "latency",
    "cliffs",
    "explore",
];

/// State shared by the sections: the paper scenes with their reference
/// runs, and the Jacobian study (printed by two sections, run once).
struct Bench {
    plan: Plan,
    paper: Option<Vec<Entry>>,
    studies: Option<Vec<(&'static str, Result<Study, String>)>>,
}

impl Bench {
    fn paper(&mut self) -> &[Entry] {
        self.paper.get_or_insert_with(|| {
            let mut entries = cases::paper();
            for e in &mut entries {
                if let Ok(case) = &e.case {
                    e.prepared = Some(measure::guarded(|| cases::prepare(case)));
                }
            }
            entries
        })
    }

    fn studies(&mut self) -> &[(&'static str, Result<Study, String>)] {
        if self.studies.is_none() {
            let plan = self.plan;
            let s = jacobian::studies(&plan, self.paper());
            self.studies = Some(s);
        }
        self.studies.as_deref().unwrap_or_default()
    }
}

fn heading(out: &mut dyn Write, name: &str, what: &str) -> std::io::Result<()> {
    writeln!(out)?;
    writeln!(out, "== {name}: {what}")
}

/// Run the benchmark, printing tables to `out`.
pub fn run(args: &BenchArgs, out: &mut dyn Write) -> std::io::Result<()> {
    let start = Instant::now();
    let plan = Plan::new(args.quick);
    let selected: Vec<&str> = SECTIONS
        .iter()
        .copied()
        .filter(|s| args.only.as_deref().is_none_or(|o| s.contains(o)))
        .collect();
    let threads = std::thread::available_parallelism()
        .map(|n| n.get())
        .unwrap_or(1);
    writeln!(
        out,
        "nudge bench{}: {} build, {threads} hardware threads; medians of at least {} timed runs per cell (or {:.1} s)",
        if args.quick { " --quick" } else { "" },
        if cfg!(debug_assertions) {
            "DEBUG (times are not representative)"
        } else {
            "release"
        },
        plan.min_reps,
        plan.budget.as_secs_f64()
    )?;
    if selected.is_empty() {
        writeln!(
            out,
            "no section matches --only {:?}; sections: {}",
            args.only.as_deref().unwrap_or(""),
            SECTIONS.join(", ")
        )?;
    }
    let mut bench = Bench {
        plan,
        paper: None,
        studies: None,
    };
    for name in &selected {
        match *name {
            "jacobian" => {
                heading(
                    out,
                    name,
                    "tangent Jacobian vs finite differences, per paper scene",
                )?;
                jacobian::print_jacobian(out, bench.studies())?;
            }
            "work-precision" => {
                heading(
                    out,
                    name,
                    "error vs time per differential update, per accuracy setting",
                )?;
                let rows = precision::rows(&plan, bench.paper());
                precision::print(out, &rows, bench.paper(), args.csv.as_deref())?;
            }
            "methods" => {
                heading(
                    out,
                    name,
                    "tangents vs central vs forward differences against the reference",
                )?;
                jacobian::print_methods(out, bench.studies())?;
            }
            "scaling" => {
                heading(out, name, "growth with bodies, horizon and free controls")?;
                scaling::print(out, &plan)?;
            }
            "effects" => {
                heading(out, name, "each effect switched off and on")?;
                effects::print(out, &plan)?;
            }
            "latency" => {
                heading(out, name, "replay of every paper editing session")?;
                latency::print(out)?;
            }
            "cliffs" => {
                heading(out, name, "scenes whose cost is out of proportion")?;
                cliffs::print(out, &plan)?;
            }
            "explore" => {
                heading(out, name, "sampled worlds per second when exploring")?;
                explore::print(out, &plan, &cases::paper())?;
            }
            _ => {}
        }
    }
    writeln!(out)?;
    writeln!(out, "total time {:.1} s", start.elapsed().as_secs_f64())?;
    match bench.studies.as_deref().map(jacobian::summary) {
        Some((Some(speed), Some(accuracy))) => writeln!(
            out,
            "summary: tangent vs central differences: {}x faster, {}x more accurate (median over scenes)",
            summary_number(speed),
            summary_number(accuracy)
        ),
        Some((speed, accuracy)) => writeln!(
            out,
            "summary: tangent vs central differences: {}x faster, {}x more accurate (median over scenes; — = not measurable)",
            speed
                .map(summary_number)
                .unwrap_or_else(|| table::MISSING.into()),
            accuracy
                .map(summary_number)
                .unwrap_or_else(|| table::MISSING.into())
        ),
        None => writeln!(
            out,
            "summary: tangent vs central differences: not measured (run the jacobian or methods section)"
        ),
    }
}

/// A ratio for the summary line: `3.2e4`, `12`, `3.4`, `0.52`.
fn summary_number(v: f64) -> String {
    if v >= 1e4 {
        format!("{v:.1e}")
    } else if v >= 10.0 {
        format!("{v:.0}")
    } else if v >= 1.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}
