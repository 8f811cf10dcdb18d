//! One accuracy setting measured against a tight reference: the error of
//! the final state and of the Jacobian, and the time of one simulation and
//! of one differential update. Section `work-precision` measures the paper
//! scenes with it and the editor's `:accuracy` popup the current scene
//! (with its controls and constraints): one code path, the same numbers.
//! Timings go through a [`Clock`], a stub in tests and headless replays.

use super::cases::{ADAPTIVE_MAX_STEP, DRAG_OFFSET, agreeing, final_state_error, signature_until};
pub(crate) use super::cases::{Case, Prepared, accuracy_label, prepare_with};
use super::fd::{relative_error, stacked};
use super::measure::measure_with;
pub(crate) use super::measure::{Clock, Plan, Ticking, Timing, Wall, guarded};
use super::table::sci;
use crate::scene::{Accuracy, Method, StateQuantity};
use crate::sim::{Side, SimOptions, Trajectory, simulate};
use crate::solve::{Anchor, Constraint, Kind, UpdateOptions, update};

/// An error, or why there is no number.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Error {
    Value(f64),
    /// The collision sequence differs from the reference: `agree` of the
    /// reference's `total` events match in order.
    DifferentEvents {
        agree: usize,
        total: usize,
    },
    Unavailable(String),
}

impl Error {
    /// The bench table's cell.
    pub(crate) fn cell(&self) -> String {
        match self {
            Error::Value(v) => sci(*v),
            Error::DifferentEvents { agree, total } => {
                format!("different events ({agree}/{total})")
            }
            Error::Unavailable(_) => "—".into(),
        }
    }

    /// The CSV field.
    pub(crate) fn csv(&self) -> String {
        match self {
            Error::Value(v) if v.is_finite() => format!("{v:e}"),
            Error::Value(_) => String::new(),
            Error::DifferentEvents { .. } => "different events".into(),
            Error::Unavailable(m) => m.clone(),
        }
    }

    /// The error, if it is a finite number.
    pub(crate) fn value(&self) -> Option<f64> {
        match self {
            Error::Value(v) if v.is_finite() => Some(*v),
            _ => None,
        }
    }
}

/// What one setting costs and how far it is from the reference.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Measured {
    pub state: Error,
    pub jacobian: Error,
    /// One simulation with tangents.
    pub simulation: Timing,
    /// One simulation with tangents and one differential update.
    pub update: Timing,
    /// Diagnostics of the timed update (e.g. a pop), shown in the notes.
    pub diagnostics: Vec<String>,
}

/// A drag of body 0 at `t` by `DRAG_OFFSET` in x and z from where it is.
pub(crate) fn drag(traj: &Trajectory, t: f64) -> Constraint {
    let x = traj.state(0, t, Side::Post).x;
    Constraint {
        body: 0,
        anchor: Anchor::Time(t),
        kind: Kind::State {
            quantities: vec![StateQuantity::Position],
            target: vec![x.x + DRAG_OFFSET, x.y, x.z + DRAG_OFFSET],
        },
        drag: true,
    }
}

/// Measure `case` at `accuracy` against its prepared reference. The timed
/// update is the drag of [`drag`] on top of `constraints` (the editor's;
/// none for the paper scenes).
pub(crate) fn measure_setting(
    plan: &Plan,
    clock: &dyn Clock,
    case: &Case,
    prep: &Prepared,
    constraints: &[Constraint],
    accuracy: Accuracy,
) -> Result<Measured, String> {
    let scene = case.with_accuracy(accuracy);
    let controls = &case.controls;
    let (t, t_drag) = (prep.t_eval, prep.t_drag);
    let (simulation, traj) = measure_with(plan, clock, || {
        simulate(&scene, controls, &SimOptions::default())
    })
    .map_err(|e| e.to_string())?;
    // An update as the editor runs it: the current motion (with tangents)
    // is the previous update's accepted trial, so the timed work is the
    // solve plus its trial simulations with tangents.
    let mut all = constraints.to_vec();
    all.push(drag(&traj, t_drag));
    let (timing, diagnostics) = measure_with(plan, clock, || {
        let r = update(&scene, controls, &traj, &all, &UpdateOptions::default())
            .map_err(|e| format!("update: {e}"))?;
        Ok::<_, String>(
            r.diagnostics
                .iter()
                .map(ToString::to_string)
                .collect::<Vec<_>>(),
        )
    })?;
    let reference = &prep.reference.traj;
    let (sig, rsig) = (traj.signature(), reference.signature());
    let state = if sig == rsig {
        Error::Value(final_state_error(&traj, reference))
    } else {
        Error::DifferentEvents {
            agree: agreeing(&sig, &rsig),
            total: rsig.len(),
        }
    };
    let (psig, prsig) = (signature_until(&traj, t), signature_until(reference, t));
    let jacobian = if psig != prsig {
        Error::DifferentEvents {
            agree: agreeing(&psig, &prsig),
            total: prsig.len(),
        }
    } else {
        match (stacked(&traj, t), stacked(reference, t)) {
            (Ok(j), Ok(jr)) => relative_error(&j, &jr, &vec![true; j.ncols()])
                .map(Error::Value)
                .unwrap_or_else(|| Error::Unavailable("no Jacobian".into())),
            (Err(e), _) | (_, Err(e)) => Error::Unavailable(e.to_string()),
        }
    };
    Ok(Measured {
        state,
        jacobian,
        simulation,
        update: timing,
        diagnostics,
    })
}

/// State errors below this are round-off: equally accurate for the front.
const ROUNDOFF: f64 = 1e-13;
/// "More accurate" means a smaller error by at least this factor ...
const ACCURACY_MARGIN: f64 = 2.0;
/// ... and "faster" a shorter median update by at least this fraction, so
/// timing noise and round-off differences do not move the front. Rows are
/// timed one after another, and on this project's 2-core VM the same row's
/// median moves by up to about 20 % from run to run (at 10 % the front
/// changed between two runs of the same build).
const SPEED_MARGIN: f64 = 0.25;

/// The Pareto front of one scene's settings, each given as its update time
/// (ms) and final-state error: `Some(true)` when no other setting is both
/// faster and more accurate (by the margins above), `None` for a setting
/// with no numbers to place.
pub(crate) fn front(points: &[Option<(f64, f64)>]) -> Vec<Option<bool>> {
    points
        .iter()
        .enumerate()
        .map(|(k, me)| {
            let (ms, err) = (*me)?;
            if !err.is_finite() {
                return None;
            }
            let err = err.max(ROUNDOFF);
            let dominated = points.iter().enumerate().any(|(j, o)| {
                j != k
                    && o.is_some_and(|(oms, oerr)| {
                        oms < (1.0 - SPEED_MARGIN) * ms
                            && oerr.is_finite()
                            && ACCURACY_MARGIN * oerr.max(ROUNDOFF) <= err
                    })
            });
            Some(!dominated)
        })
        .collect()
}

/// A measured setting as [`front`] places it.
pub(crate) fn point(m: &Result<Measured, String>) -> Option<(f64, f64)> {
    let m = m.as_ref().ok()?;
    Some((m.update.ms, m.state.value()?))
}

/// A handful of settings around `current` for a motion of `duration` s:
/// the same integrator looser and tighter, a looser root tolerance and the
/// other integrator, each usable (`Accuracy::problem`), `current` among
/// them once.
pub(crate) fn around(current: Accuracy, duration: f64) -> Vec<Accuracy> {
    let with = |method| Accuracy { method, ..current };
    let (looser, tighter, other) = match current.method {
        Method::Rk4 { step } => (
            with(Method::Rk4 { step: 2.0 * step }),
            with(Method::Rk4 { step: 0.5 * step }),
            with(Method::Adaptive {
                tol: 1e-9,
                max_step: ADAPTIVE_MAX_STEP,
            }),
        ),
        Method::Adaptive { tol, max_step } => (
            with(Method::Adaptive {
                tol: 100.0 * tol,
                max_step,
            }),
            with(Method::Adaptive {
                tol: 0.01 * tol,
                max_step,
            }),
            with(Method::Rk4 { step: 1e-3 }),
        ),
    };
    let root = Accuracy {
        root_tol: 1e3 * current.root_tol,
        ..current
    };
    let mut out: Vec<Accuracy> = Vec::new();
    for a in [looser, current, tighter, root, other] {
        let usable = a == current || a.problem(duration).is_none();
        if usable && !out.contains(&a) {
            out.push(a);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_front_ignores_noise_and_round_off() {
        let points = [
            Some((10.0, 1e-6)),
            Some((5.0, 1e-8)),   // dominates the first
            Some((5.2, 0.9e-8)), // not 25 % slower and not 2x less accurate than row 1
            Some((1.0, 1e-3)),
            Some((20.0, 1e-16)),
            Some((30.0, 0.0)), // round-off like row 4: not dominated by it
            None,
            Some((0.1, f64::NAN)),
        ];
        assert_eq!(
            front(&points),
            [
                Some(false),
                Some(true),
                Some(true),
                Some(true),
                Some(true),
                Some(true),
                None,
                None
            ]
        );
    }

    #[test]
    fn settings_around_the_current_one_include_it_once() {
        let current = Accuracy {
            method: Method::Adaptive {
                tol: 1e-9,
                max_step: 0.01,
            },
            root_tol: 1e-12,
        };
        let s = around(current, 2.0);
        assert_eq!(s.len(), 5);
        assert_eq!(s.iter().filter(|a| **a == current).count(), 1);
        assert_eq!(s[0].label(), "dopri5 tol=1e-7");
        assert_eq!(s[2].label(), "dopri5 tol=1e-11");
        assert_eq!(s[3].root_tol, 1e-9);
        assert_eq!(s[4].label(), "rk4 h=1e-3");
        // Too tight a tolerance is left out.
        let tight = Accuracy {
            method: Method::Adaptive {
                tol: 1e-13,
                max_step: 0.01,
            },
            root_tol: 1e-12,
        };
        assert_eq!(around(tight, 2.0).len(), 4);
    }
}
