//! The paper's scenes as benchmark cases, each with its tight reference
//! run and the time at which Jacobians are compared.

use super::measure::{Clock, Wall};
use crate::controls::Controls;
use crate::scene::{Accuracy, Method, Scene, load_str};
use crate::sim::{Side, SimOptions, Trajectory, simulate};
use crate::testkit;

/// The scenes of the paper (Popović et al. 2000, §3.2, §5, §6), compiled
/// in so the benchmark does not depend on the working directory.
pub(crate) const PAPER_SCENES: [(&str, &str); 7] = [
    ("eggs", include_str!("../../scenes/eggs.toml")),
    ("plank", include_str!("../../scenes/plank.toml")),
    ("mug", include_str!("../../scenes/mug.toml")),
    ("scissors", include_str!("../../scenes/scissors.toml")),
    (
        "scissors-bounce",
        include_str!("../../scenes/scissors-bounce.toml"),
    ),
    (
        "particle-parabola",
        include_str!("../../scenes/particle-parabola.toml"),
    ),
    (
        "particle-polygon",
        include_str!("../../scenes/particle-polygon.toml"),
    ),
];

/// Largest step of every adaptive setting the benchmark uses, s.
pub(crate) const ADAPTIVE_MAX_STEP: f64 = 0.05;

/// The reference accuracies: the faster of the two is used.
pub(crate) const REFERENCES: [Accuracy; 2] = [
    Accuracy {
        method: Method::Adaptive {
            tol: 1e-12,
            max_step: ADAPTIVE_MAX_STEP,
        },
        root_tol: 1e-14,
    },
    Accuracy {
        method: Method::Rk4 { step: 1e-4 },
        root_tol: 1e-14,
    },
];

/// Offset of the drag constraint of a timed update, m (x and z).
pub(crate) const DRAG_OFFSET: f64 = 1e-3;

/// A scene ready to benchmark.
#[derive(Debug, Clone)]
pub(crate) struct Case {
    pub scene: Scene,
    pub controls: Controls,
    /// The scene had no free controls; every body's initial state was freed.
    pub freed: bool,
}

impl Case {
    pub(crate) fn new(mut scene: Scene) -> Case {
        let mut freed = false;
        if Controls::new(&scene).m() == 0 {
            testkit::free_state(&mut scene);
            freed = true;
        }
        let controls = Controls::new(&scene);
        Case {
            scene,
            controls,
            freed,
        }
    }

    /// The scene at another accuracy.
    pub(crate) fn with_accuracy(&self, accuracy: Accuracy) -> Scene {
        let mut s = self.scene.clone();
        s.accuracy = accuracy;
        s
    }
}

/// The tight reference run of a case.
#[derive(Debug, Clone)]
pub(crate) struct Reference {
    /// The reference setting.
    pub accuracy: Accuracy,
    /// With tangents.
    pub traj: Trajectory,
    /// Which reference and why, e.g. `dopri5 tol=1e-12 root=1e-14 (78 ms; rk4 h=1e-4 147 ms)`.
    pub note: String,
}

/// What every section needs to know about a case beyond the scene.
#[derive(Debug, Clone)]
pub(crate) struct Prepared {
    pub reference: Reference,
    /// Jacobians are compared (and the timed drag applied) at this time, s:
    /// the final time, or before the first contact where tangents stop
    /// being available (a grazing contact).
    pub t_eval: f64,
    /// `final` or why the time is earlier.
    pub eval_note: String,
    /// The timed drag is applied at this time, s: halfway between the last
    /// event with free event controls (or the start) and `t_eval`.
    pub t_drag: f64,
}

/// A paper scene by name, loaded (or the load error).
pub(crate) struct Entry {
    pub name: &'static str,
    pub case: Result<Case, String>,
    pub prepared: Option<Result<Prepared, String>>,
}

/// Label of an accuracy setting, e.g. `rk4 h=1e-3 root=1e-12`.
pub(crate) fn accuracy_label(a: &Accuracy) -> String {
    format!("{} root={:.0e}", a.label(), a.root_tol)
}

/// Load the paper scenes.
pub(crate) fn paper() -> Vec<Entry> {
    PAPER_SCENES
        .iter()
        .map(|(name, text)| Entry {
            name,
            case: load_str(text, &format!("scenes/{name}.toml"))
                .map(Case::new)
                .map_err(|e| e.to_string()),
            prepared: None,
        })
        .collect()
}

/// Simulate the faster of the reference accuracies (timed on `clock`)
/// with tangents.
pub(crate) fn reference(case: &Case, clock: &dyn Clock) -> Result<Reference, String> {
    let mut tried: Vec<(Accuracy, Result<f64, String>)> = Vec::new();
    for acc in REFERENCES {
        let s = case.with_accuracy(acc);
        let t = clock.now();
        let r = simulate(&s, &case.controls, &SimOptions::without_tangents());
        tried.push((
            acc,
            r.map(|_| clock.now().saturating_sub(t).as_secs_f64() * 1e3)
                .map_err(|e| e.to_string()),
        ));
    }
    let best = tried
        .iter()
        .filter_map(|(a, r)| r.as_ref().ok().map(|ms| (*a, *ms)))
        .min_by(|a, b| a.1.total_cmp(&b.1));
    let Some((accuracy, _)) = best else {
        let errs: Vec<String> = tried
            .iter()
            .filter_map(|(a, r)| {
                r.as_ref()
                    .err()
                    .map(|e| format!("{}: {e}", accuracy_label(a)))
            })
            .collect();
        return Err(format!("no reference run: {}", errs.join("; ")));
    };
    let traj = simulate(
        &case.with_accuracy(accuracy),
        &case.controls,
        &SimOptions::default(),
    )
    .map_err(|e| format!("reference {}: {e}", accuracy_label(&accuracy)))?;
    let others: Vec<String> = tried
        .iter()
        .filter(|(a, _)| *a != accuracy)
        .map(|(a, r)| match r {
            Ok(ms) => format!("{} {} ms", a.label(), super::table::ms(*ms)),
            Err(e) => format!("{} failed: {e}", a.label()),
        })
        .collect();
    let own = tried
        .iter()
        .find(|(a, _)| *a == accuracy)
        .and_then(|(_, r)| r.as_ref().ok().copied())
        .unwrap_or(f64::NAN);
    let note = format!(
        "{} ({} ms; {})",
        accuracy_label(&accuracy),
        super::table::ms(own),
        others.join(", ")
    );
    Ok(Reference {
        accuracy,
        traj,
        note,
    })
}

/// The comparison time for a case: the final time when tangents exist to
/// the end in both the default and the reference run, otherwise halfway
/// between the last event before the first tangent failure and that failure.
pub(crate) fn evaluation_time(
    case: &Case,
    default: &Trajectory,
    reference: &Trajectory,
) -> (f64, String) {
    let duration = case.scene.duration;
    let failure = [default, reference]
        .iter()
        .filter_map(|t| t.tangent_error)
        .min_by(|a, b| a.time().total_cmp(&b.time()));
    match failure {
        Some(e) if e.time() < duration => {
            let horizon = e.time().max(0.0);
            let prev = [default, reference]
                .iter()
                .flat_map(|t| t.events.iter().map(|e| e.t))
                .filter(|&t| t < horizon)
                .fold(0.0, f64::max);
            (
                0.5 * (prev + horizon),
                format!("before the grazing contact at {horizon:.3} s"),
            )
        }
        _ => (duration, "final time".into()),
    }
}

/// Where a timed drag happens: halfway between the last event whose
/// controls are free (the drag must be reachable from them) and `t_eval`,
/// so it falls inside the motion rather than at an edge of it.
pub(crate) fn drag_time(case: &Case, default: &Trajectory, t_eval: f64) -> f64 {
    let after = case
        .scene
        .event_controls
        .iter()
        .filter(|c| !c.fixed)
        .filter_map(|c| default.events.get(c.event).map(|e| e.t))
        .filter(|&t| t < t_eval)
        .fold(0.0, f64::max);
    0.5 * (after + t_eval)
}

/// Reference run and evaluation time of a case.
pub(crate) fn prepare(case: &Case) -> Result<Prepared, String> {
    prepare_with(case, &Wall::new())
}

/// [`prepare`], the reference runs timed on `clock`.
pub(crate) fn prepare_with(case: &Case, clock: &dyn Clock) -> Result<Prepared, String> {
    let default = simulate(&case.scene, &case.controls, &SimOptions::default())
        .map_err(|e| format!("default run: {e}"))?;
    let reference = reference(case, clock)?;
    let (t_eval, eval_note) = evaluation_time(case, &default, &reference.traj);
    let t_drag = drag_time(case, &default, t_eval);
    Ok(Prepared {
        reference,
        t_eval,
        eval_note,
        t_drag,
    })
}

/// The collision signature of the events up to time `t` (inclusive).
pub(crate) fn signature_until(traj: &Trajectory, t: f64) -> Vec<String> {
    traj.signature()
        .into_iter()
        .zip(&traj.events)
        .filter(|(_, e)| e.t <= t)
        .map(|(s, _)| s)
        .collect()
}

/// How many leading events two signatures share.
pub(crate) fn agreeing(a: &[String], b: &[String]) -> usize {
    a.iter().zip(b).take_while(|(x, y)| x == y).count()
}

/// Largest norm over bodies of the tangent-space difference between two
/// runs' final states.
pub(crate) fn final_state_error(a: &Trajectory, b: &Trajectory) -> f64 {
    let t = a.duration.min(b.duration);
    (0..a.tracks.len().min(b.tracks.len()))
        .map(|i| {
            crate::tangent::state_difference(&b.state(i, t, Side::Post), &a.state(i, t, Side::Post))
                .norm()
        })
        .fold(0.0, |m: f64, v| {
            if v.is_nan() || m.is_nan() {
                f64::NAN
            } else {
                m.max(v)
            }
        })
}
