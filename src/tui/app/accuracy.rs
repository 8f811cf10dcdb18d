//! What accuracy costs, from the editor (`A`, `:accuracy`): a few
//! integrator settings around the current one are measured on a background
//! thread, as `nudge bench --only work-precision` measures the paper scenes
//! (`crate::bench::accuracy`, one code path), with progress on the status
//! line (Esc cancels). The results open in a popup: the current setting is
//! marked, the Pareto-optimal ones highlighted, `j`/`k` choose and Enter
//! picks one (an undoable edit).

use super::job::Job;
use super::*;
use crate::bench::accuracy::{
    self as bench, Case, Clock, Measured, Plan, Ticking, Wall, accuracy_label, guarded,
    prepare_with,
};
use crate::explore::Start;
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

/// Which clock times the measurements.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Timer {
    /// The wall clock.
    #[default]
    Wall,
    /// A deterministic stub ([`Ticking`]): headless replays and tests,
    /// whose screens must not depend on timing.
    Stub,
}

/// One tick of the stub clock (its k-th reading is k² ticks).
const STUB_TICK: Duration = Duration::from_millis(1);

/// One measured setting.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SettingRow {
    pub accuracy: Accuracy,
    /// The scene's setting when the measurement started.
    pub current: bool,
    pub result: Result<Measured, String>,
}

/// The measured settings, shown by the popup.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurements {
    pub(crate) rows: Vec<SettingRow>,
    /// Per row: on the Pareto front, off it, or not placed.
    pub(crate) front: Vec<Option<bool>>,
    /// The reference setting the errors are against.
    pub(crate) reference: String,
    /// When Jacobians are compared and the timed drag happens, s.
    pub(crate) t_eval: f64,
    pub(crate) t_drag: f64,
    /// Every body's initial state was freed to time the update (the scene
    /// has no free controls).
    pub(crate) freed: bool,
    /// The row `j`/`k` chose.
    pub(crate) selected: usize,
    /// The motion was edited while these were measured: they describe the
    /// scene as it was when measuring started.
    pub(crate) stale: bool,
}

/// Why a measurement has no results.
#[derive(Debug, Clone, PartialEq)]
enum Stopped {
    Cancelled,
    Failed(String),
}

impl std::fmt::Display for Stopped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Stopped::Cancelled => f.write_str("accuracy: cancelled"),
            Stopped::Failed(why) => write!(f, "accuracy: could not measure: {why}"),
        }
    }
}

/// What the thread has said so far.
#[derive(Debug, Default)]
pub struct Shared {
    /// Settings measured, of how many.
    progress: Option<(usize, usize)>,
    done: Option<Result<Measurements, Stopped>>,
    /// The motion was edited since measuring started.
    edited: bool,
}

/// Measuring, from start to choice.
#[derive(Debug, Clone, PartialEq, Default)]
pub enum Measuring {
    #[default]
    Idle,
    Running(Job<Shared>),
    /// The results; `shown` once the popup has opened on them.
    Done {
        results: Measurements,
        shown: bool,
    },
}

/// Measure the settings around `start`'s on `clock`, reporting after each.
fn measure_all(
    start: Start,
    clock: &dyn Clock,
    cancel: &AtomicBool,
    report: &dyn Fn(usize, usize),
) -> Result<Measurements, Stopped> {
    let current = start.scene.accuracy;
    let settings = bench::around(current, start.scene.duration);
    let n = settings.len();
    // As the bench: a scene without free controls has its initial states
    // freed, so that a drag can be timed (its constraints then do not apply).
    let (case, constraints) = if start.controls.m() > 0 {
        let case = Case {
            scene: start.scene,
            controls: start.controls,
            freed: false,
        };
        (case, start.constraints)
    } else {
        (Case::new(start.scene), Vec::new())
    };
    report(0, n);
    let prep = guarded(|| prepare_with(&case, clock)).map_err(Stopped::Failed)?;
    let plan = Plan::new(true);
    let mut rows = Vec::with_capacity(n);
    for (k, accuracy) in settings.into_iter().enumerate() {
        if cancel.load(Ordering::Relaxed) {
            return Err(Stopped::Cancelled);
        }
        let result =
            guarded(|| bench::measure_setting(&plan, clock, &case, &prep, &constraints, accuracy));
        rows.push(SettingRow {
            accuracy,
            current: accuracy == current,
            result,
        });
        report(k + 1, n);
    }
    let points: Vec<_> = rows.iter().map(|r| bench::point(&r.result)).collect();
    let selected = rows.iter().position(|r| r.current).unwrap_or(0);
    Ok(Measurements {
        front: bench::front(&points),
        rows,
        reference: accuracy_label(&prep.reference.accuracy),
        t_eval: prep.t_eval,
        t_drag: prep.t_drag,
        freed: case.freed,
        selected,
        stale: false,
    })
}

impl App {
    /// Start measuring the settings around the core's on a background thread.
    pub(super) fn measure_accuracy(&mut self, core: &mut impl Core) {
        if matches!(self.measuring, Measuring::Running(_)) {
            self.say(Level::Warning, "already measuring accuracy: Esc cancels");
            return;
        }
        let Some(start) = core.explore_start() else {
            self.say(Level::Error, "this editor cannot measure accuracy");
            return;
        };
        let n = bench::around(start.scene.accuracy, start.scene.duration).len();
        let timer = self.timer;
        let spawned = Job::spawn("nudge-accuracy", move |s: &Mutex<Shared>, c| {
            let report = |k: usize, n: usize| {
                if let Ok(mut sh) = s.lock() {
                    sh.progress = Some((k, n));
                }
            };
            let clock: Box<dyn Clock> = match timer {
                Timer::Wall => Box::new(Wall::new()),
                Timer::Stub => Box::new(Ticking::new(STUB_TICK)),
            };
            let done = measure_all(start, clock.as_ref(), c, &report);
            if let Ok(mut sh) = s.lock() {
                sh.done = Some(done);
            }
        });
        match spawned {
            Ok(job) => {
                self.measuring = Measuring::Running(job);
                self.say(
                    Level::Info,
                    format!("accuracy: the reference run, then {n} settings… (Esc cancels)"),
                );
            }
            Err(e) => self.say(Level::Error, format!("could not start measuring: {e}")),
        }
    }

    /// Whether a measurement is running in the background.
    pub fn measuring(&self) -> bool {
        matches!(self.measuring, Measuring::Running(_))
    }

    /// Whether any background work runs (its progress wants polling).
    pub fn busy(&self) -> bool {
        self.exploring() || self.measuring()
    }

    /// Take what the measurement has said: progress on the status line, or
    /// its results, which open the popup once keys go to the editor again.
    /// Returns whether the screen changed.
    pub(super) fn poll_accuracy(&mut self) -> bool {
        let job = match &mut self.measuring {
            Measuring::Running(job) => job.clone(),
            Measuring::Done { shown, .. } if !*shown && self.input == Input::Normal => {
                *shown = true;
                self.open(PopupKind::Accuracy);
                return true;
            }
            _ => return false,
        };
        let (progress, done, edited) = job
            .with(|sh| (sh.progress, sh.done.take(), sh.edited))
            .unwrap_or_else(|| {
                (
                    None,
                    Some(Err(Stopped::Failed("the measuring thread failed".into()))),
                    false,
                )
            });
        let Some(result) = done else {
            let Some((k, n)) = progress else {
                return false;
            };
            let text = format!("accuracy: {k}/{n} settings (Esc cancels)");
            let changed = self.message.as_ref().is_none_or(|m| m.text != text);
            if changed {
                // Progress is not logged: only where it ends is.
                self.message = Some(Message {
                    text,
                    level: Level::Info,
                });
            }
            return changed;
        };
        job.join();
        match result {
            Ok(mut results) => {
                results.stale = edited;
                let n = results.rows.len();
                self.measuring = Measuring::Done {
                    results,
                    shown: false,
                };
                self.say(
                    Level::Info,
                    format!("accuracy: {n} settings measured: j/k choose, Enter picks"),
                );
                self.poll_accuracy();
            }
            Err(stopped) => {
                self.measuring = Measuring::Idle;
                let level = match stopped {
                    Stopped::Cancelled => Level::Info,
                    Stopped::Failed(_) => Level::Error,
                };
                self.say(level, stopped.to_string());
            }
        }
        true
    }

    /// Wait for a running measurement to end (headless replays), then take
    /// its results.
    pub(super) fn wait_accuracy(&mut self) {
        if let Measuring::Running(job) = &self.measuring {
            job.join();
            self.poll_accuracy();
        }
    }

    /// The motion changed while measuring: the results will say they
    /// describe the scene as it was.
    pub(super) fn note_edit_while_measuring(&self) {
        if let Measuring::Running(job) = &self.measuring {
            job.with(|sh| sh.edited = true);
        }
    }

    /// Esc while measuring: stop after the current setting.
    pub(super) fn cancel_accuracy(&mut self) -> bool {
        if let Measuring::Running(job) = &self.measuring {
            job.cancel();
            self.say(Level::Info, "accuracy: cancelling after this setting");
            return true;
        }
        false
    }

    /// The measured settings, if any.
    pub fn measurements(&self) -> Option<&Measurements> {
        match &self.measuring {
            Measuring::Done { results, .. } => Some(results),
            _ => None,
        }
    }

    /// `j`/`k` in the popup: choose another row.
    pub(super) fn step_accuracy(&mut self, sense: Sense, count: u32) {
        if let Measuring::Done { results, .. } = &mut self.measuring {
            let n = results.rows.len().max(1) as i64;
            let k = results.selected as i64 + sense.sign() * i64::from(count.min(100));
            results.selected = k.clamp(0, n - 1) as usize;
        }
    }

    /// Enter in the popup: make the chosen setting the scene's (undoable).
    pub(super) fn pick_accuracy(&mut self, core: &mut impl Core) {
        if !matches!(
            self.input,
            Input::Popup {
                kind: PopupKind::Accuracy,
                ..
            }
        ) {
            return;
        }
        let Some(chosen) = self
            .measurements()
            .and_then(|m| m.rows.get(m.selected))
            .map(|r| r.accuracy)
        else {
            return;
        };
        self.input = Input::Normal;
        let label = accuracy_label(&chosen);
        if core.view().accuracy == chosen {
            self.say(Level::Info, format!("accuracy: {label} already"));
            return;
        }
        if self.apply(core, Edit::SetAccuracy(chosen)).is_some() {
            self.remember(chosen.method);
            self.root_tol = chosen.root_tol;
            self.say_info(format!("accuracy: now {label} (u undoes)"));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::controls::Controls;

    fn bounce() -> Start {
        let text = include_str!("../../../scenes/bounce.toml");
        let scene = crate::scene::load_str(text, "scenes/bounce.toml").expect("loads");
        Start {
            controls: Controls::new(&scene),
            scene,
            constraints: Vec::new(),
            goal: None,
        }
    }

    fn run(cancelled: bool) -> (Result<Measurements, Stopped>, Vec<(usize, usize)>) {
        let said = Mutex::new(Vec::new());
        let report = |k, n| {
            if let Ok(mut s) = said.lock() {
                s.push((k, n));
            }
        };
        let clock = Ticking::new(STUB_TICK);
        let result = measure_all(bounce(), &clock, &AtomicBool::new(cancelled), &report);
        (result, said.into_inner().unwrap_or_default())
    }

    #[test]
    fn progress_is_reported_per_setting_and_cancelling_stops_before_the_next() {
        let (result, said) = run(false);
        assert_eq!(said, (0..=5).map(|k| (k, 5)).collect::<Vec<_>>());
        let m = result.expect("measured");
        assert_eq!(m.rows.iter().filter(|r| r.current).count(), 1);
        assert!(
            m.rows[m.selected].current,
            "the popup opens on the current row"
        );
        assert_eq!(m.front.len(), m.rows.len());
        assert_eq!(
            run(false).0.ok(),
            Some(m),
            "the stub clock makes it reproducible"
        );

        let (result, said) = run(true);
        assert_eq!(result, Err(Stopped::Cancelled));
        assert_eq!(said, [(0, 5)]);
    }

    /// Measure the bounce scene from a real editor, applying `edit` while
    /// the measurement runs (it is not polled in between, so it still runs
    /// as far as the app knows, however fast the thread is).
    fn measured_with(edit: Option<Edit>) -> Measurements {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/bounce.toml");
        let mut editor = crate::edit::Editor::open(&path).expect("scene opens");
        let mut app = crate::tui::fixtures::app(&editor.view(), 80, 24);
        app.measure_accuracy(&mut editor);
        assert!(app.measuring());
        if let Some(edit) = edit {
            assert!(app.apply(&mut editor, edit).is_some());
        }
        app.wait_accuracy();
        app.measurements().cloned().expect("measured")
    }

    #[test]
    fn results_measured_across_an_edit_say_they_are_stale() {
        assert!(!measured_with(None).stale);
        assert!(!measured_with(Some(Edit::SelectTime(0.5))).stale);
        let tighter = Accuracy {
            method: crate::scene::Method::Rk4 { step: 5e-4 },
            ..Accuracy::default()
        };
        let m = measured_with(Some(Edit::SetAccuracy(tighter)));
        assert!(m.stale, "an edit during the measurement marks it");
        let text: String = crate::tui::popup::accuracy::lines(&m, Theme::PLAIN, 76)
            .iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join("\n");
        assert!(
            text.contains("before the last edit: A measures again"),
            "{text}"
        );
    }
}
