//! UI state and the one place input changes it: key → [`Action`] (through
//! the key map) → [`App::handle_action`] → [`Edit`]s on the [`Core`] or a
//! change of UI state. Rendering reads the App and a [`View`]; it never
//! changes either.
//!
//! Nudges are *accumulated*: [`App::handle_action`] adds them to a pending
//! nudge and [`App::flush`] applies the sum as one edit. The event loop
//! flushes after draining every pending key, so holding a key drags instead
//! of queueing one solve per key repeat. Any other action flushes first, so
//! edits reach the core in the order they were typed.

use super::camera::{Camera, ViewKind};
use super::command::{self, Command, MethodName, SETTLE_MS};
use super::key::{Key, KeyCode, Mods};
use super::keymap::{self, Action, Context, Sense};
use super::layout;
use super::mouse::{Mouse, MouseKind};
use super::popup::{self, PopupKind};
use super::theme::Theme;
use crate::edit::{Core, Edit, Expression, Outcome, Side, Vertical};
use crate::files::WriteMode;
use crate::math::Vec3;
use crate::scene::{Accuracy, Block, Method, StateQuantity};
use crate::view::{ControlRow, View};
use ratatui::layout::Rect;
use std::time::Instant;

mod accuracy;
mod commands;
mod explore;
mod job;
mod messages;
mod mouse;

pub use accuracy::{Measurements, Measuring, Timer};
pub use explore::Exploring;

/// Where keys go.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Input {
    Normal,
    /// After `b`, waiting for a block letter.
    Block,
    /// Typing a `:` command (the text so far, without the `:`).
    Command(String),
    /// A popup (help, messages, notes), scrolled this many lines.
    Popup {
        kind: PopupKind,
        scroll: u16,
    },
    /// Asking whether to quit with unsaved edits.
    Prompt,
}

/// How a message is shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Level {
    Info,
    Warning,
    Error,
}

/// A message for the user, shown until the next key.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Message {
    pub text: String,
    pub level: Level,
}

/// Worlds `X` explores (`:explore N` for another number).
pub const EXPLORE_SAMPLES: usize = 2048;

/// Messages kept for `:messages` (the oldest go first).
const LOG_LIMIT: usize = 1000;

/// Largest count prefix.
pub const MAX_COUNT: u32 = 9999;
/// Smallest and largest nudge step (any unit).
const STEP_RANGE: (f64, f64) = (1e-9, 1e9);
/// One orbit key press, radians (15°).
const ORBIT_STEP: f64 = std::f64::consts::PI / 12.0;
/// One zoom key press.
const ZOOM_STEP: f64 = 1.25;
/// One pan key press, as a fraction of the window's half-height.
const PAN_STEP: f64 = 0.1;
/// Largest adaptive step when switching to the adaptive integrator (s).
const DEFAULT_MAX_STEP: f64 = 1e-2;

/// The UI state. Equal states over the same core draw equal screens.
#[derive(Debug, Clone, PartialEq)]
pub struct App {
    pub camera: Camera,
    /// Whether the camera follows the scene bounds (until panned or zoomed).
    pub auto_fit: bool,
    /// The quantity nudges change.
    pub mode: StateQuantity,
    /// Nudge step per quantity, in `StateQuantity::ALL` order (m, rad, m/s, rad/s).
    pub steps: [f64; 4],
    /// Count prefix typed so far.
    pub count: Option<u32>,
    pub input: Input,
    /// Whether the current time is being animated.
    pub playing: bool,
    pub message: Option<Message>,
    /// Selected row of the constraints panel.
    pub selected_constraint: usize,
    /// Set once the user has quit.
    pub quit: bool,
    /// The terminal area last drawn to.
    pub area: Rect,
    pub theme: Theme,
    /// Whether the status line shows the frame render time (off in
    /// headless runs, whose screens must be deterministic).
    pub show_render_ms: bool,
    /// Wall time of the last frame render, ms.
    pub render_ms: Option<f64>,
    /// Whether the terminal reports the mouse to the editor (`:set mouse`).
    pub mouse: bool,
    /// Whether the motion before the last edit is drawn (`g`).
    pub show_ghost: bool,
    /// What times `:accuracy` (a stub in headless runs).
    pub timer: Timer,
    /// Every message so far, oldest first (at most [`LOG_LIMIT`]).
    log: Vec<Message>,
    /// The cell where the current mouse drag was last seen.
    drag: Option<(u16, u16)>,
    /// An exploration running in the background, or its alternatives.
    exploring: Exploring,
    /// `:accuracy` measuring in the background, or its results.
    measuring: Measuring,
    /// The Jacobian columns shown by the open `:jacobian` popup.
    sensitivity: Option<Result<crate::view::Sensitivity, String>>,
    /// The last command line that did not parse, until taken.
    command_error: Option<command::CommandError>,
    pending: Option<(StateQuantity, Vec3)>,
    rk4_step: f64,
    tolerance: f64,
    max_step: f64,
    root_tol: f64,
    edits: usize,
    apply_ms: Vec<f64>,
}

impl App {
    /// A fresh UI for `view` on a terminal of `area`, the camera fitted to
    /// the scene.
    pub fn new(view: &View, area: Rect, theme: Theme) -> App {
        let accuracy = Accuracy::default();
        let extent = scene_extent(view);
        let duration = if view.duration.is_finite() && view.duration > 0.0 {
            view.duration
        } else {
            1.0
        };
        let mut app = App {
            camera: Camera::default(),
            auto_fit: true,
            mode: StateQuantity::Position,
            steps: [
                ladder(extent / 100.0),
                0.01,
                ladder(extent / (100.0 * duration)),
                0.05,
            ],
            count: None,
            input: Input::Normal,
            playing: false,
            message: None,
            selected_constraint: 0,
            quit: false,
            area,
            theme,
            show_render_ms: true,
            render_ms: None,
            mouse: true,
            show_ghost: true,
            timer: Timer::Wall,
            log: Vec::new(),
            drag: None,
            command_error: None,
            sensitivity: None,
            exploring: Exploring::Idle,
            measuring: Measuring::Idle,
            pending: None,
            rk4_step: accuracy.window(),
            tolerance: 1e-9,
            max_step: DEFAULT_MAX_STEP,
            root_tol: accuracy.root_tol,
            edits: 0,
            apply_ms: Vec::new(),
        };
        app.remember(view.accuracy.method);
        app.root_tol = view.accuracy.root_tol;
        app.refit(view);
        // What the scene is about, until the first key.
        if !view.notes.trim().is_empty() {
            app.say(Level::Info, view.notes.trim());
        }
        app
    }

    /// Which key-map context keys go to.
    pub fn context(&self) -> Context {
        match self.input {
            Input::Normal if matches!(self.exploring, Exploring::Browsing { .. }) => {
                Context::Explore
            }
            Input::Normal => Context::Normal,
            Input::Block => Context::Block,
            Input::Command(_) => Context::Command,
            Input::Popup { .. } => Context::Help,
            Input::Prompt => Context::Prompt,
        }
    }

    /// The nudge step of the current mode.
    pub fn step(&self) -> f64 {
        self.steps[quantity_index(self.mode)]
    }

    /// Successful `core.apply` calls so far.
    pub fn edits(&self) -> usize {
        self.edits
    }

    /// Wall times (ms) of the `core.apply` calls since the last call.
    pub fn take_apply_ms(&mut self) -> Vec<f64> {
        std::mem::take(&mut self.apply_ms)
    }

    /// Whether a nudge is waiting for [`App::flush`].
    pub fn has_pending_nudge(&self) -> bool {
        self.pending.is_some()
    }

    /// The terminal was resized.
    pub fn resize(&mut self, area: Rect, view: &View) {
        self.area = area;
        if self.auto_fit {
            self.refit(view);
        }
    }

    /// Fit the camera to the scene for the current terminal size.
    pub fn refit(&mut self, view: &View) {
        let canvas = layout::canvas_inner(self.area);
        let points = view
            .paths
            .iter()
            .flat_map(|p| p.points.iter())
            .chain(view.obstacles.iter().flat_map(|(a, b)| [a, b]))
            .chain(view.selected_outline.iter().flat_map(|(a, b)| [a, b]))
            .chain(view.body_outlines.iter().flat_map(|(a, b)| [a, b]));
        self.camera.fit(points, canvas.width, canvas.height);
    }

    /// One key press.
    pub fn handle_key(&mut self, core: &mut impl Core, key: Key) {
        let key = key.normalized();
        self.message = None;
        let context = self.context();
        if let (Context::Normal, Some(n)) = (context, self.count) {
            // Any digit continues a count; Esc abandons it.
            if let (true, KeyCode::Char(c)) = (key.mods == Mods::default(), key.code)
                && let Some(digit) = c.to_digit(10)
            {
                self.count = Some(n.saturating_mul(10).saturating_add(digit).min(MAX_COUNT));
                return;
            }
            if key == Key::new(KeyCode::Esc) {
                self.count = None;
                return;
            }
        }
        // Browsing alternatives keeps the editing keys it does not rebind
        // (time, views, the command line...).
        let action = keymap::lookup(context, key).or_else(|| {
            (context == Context::Explore)
                .then(|| keymap::lookup(Context::Normal, key))
                .flatten()
        });
        if let Some(action) = action {
            self.handle_action(core, action);
            return;
        }
        match context {
            Context::Normal => {
                self.count = None;
                self.say(
                    Level::Warning,
                    format!("{key} does nothing here; ? lists the keys"),
                );
            }
            Context::Command => {
                if let (Some(c), Input::Command(buf)) = (key.typed_char(), &mut self.input) {
                    buf.push(c);
                }
            }
            Context::Block => {
                self.input = Input::Normal;
                self.say(
                    Level::Warning,
                    format!("{key} is not a block; b then p o v w m i"),
                );
            }
            Context::Explore => self.say(
                Level::Warning,
                format!("{key} does nothing here: j/k other alternatives, Enter takes one, Esc dismisses"),
            ),
            Context::Help | Context::Prompt => {}
        }
    }

    /// Carry out one action. Everything but a nudge first applies any
    /// pending nudge, so edits reach the core in the order typed.
    pub fn handle_action(&mut self, core: &mut impl Core, action: Action) {
        if !matches!(action, Action::Nudge { .. }) {
            self.flush(core);
        }
        let count = if action.takes_count() {
            self.count.take().unwrap_or(1)
        } else {
            1
        };
        if !matches!(action, Action::Count(_)) {
            self.count = None;
        }
        let times = i64::from(count);
        match action {
            Action::Nudge { dir, big } => {
                let (dx, dy) = dir.unit();
                let magnitude = self.step() * f64::from(count) * if big { 10.0 } else { 1.0 };
                let delta = match self.mode {
                    StateQuantity::Position | StateQuantity::Velocity => {
                        (self.camera.right() * dx + self.camera.up() * dy) * magnitude
                    }
                    // `l` turns clockwise as seen on screen; `k` tilts the top away.
                    StateQuantity::Orientation | StateQuantity::AngularVelocity => {
                        -(self.camera.toward_viewer() * dx + self.camera.right() * dy) * magnitude
                    }
                };
                self.add_nudge(core, delta);
            }
            Action::Count(d) => self.count = Some(u32::from(d)),
            Action::Scrub(sense) => {
                let view = core.view();
                let dt = if view.duration.is_finite() && view.duration > 0.0 {
                    view.duration / 100.0
                } else {
                    0.01
                };
                let t = view.time + (sense.sign() * times) as f64 * dt;
                let t = if view.duration.is_finite() {
                    t.clamp(0.0, view.duration.max(0.0))
                } else {
                    t.max(0.0)
                };
                if t.is_finite() {
                    self.apply(core, Edit::SelectTime(t));
                } else {
                    self.say(Level::Error, "the current time is not a number; try :t 0");
                }
            }
            Action::Event(sense) => self.step_event(core, sense, count as usize),
            Action::Body(sense) => {
                let view = core.view();
                let n = view.bodies.len() as i64;
                if n == 0 {
                    self.say(Level::Warning, "the scene has no bodies");
                } else {
                    let next = (view.selected as i64 + sense.sign() * times).rem_euclid(n);
                    self.apply(core, Edit::SelectBody(next as usize));
                }
            }
            Action::Constraint(sense) => {
                let n = core.view().constraints.len() as i64;
                if n == 0 {
                    self.say(Level::Warning, "no constraints yet: a nails, f floats");
                } else {
                    let sel = (self.selected_constraint as i64).min(n - 1);
                    self.selected_constraint = (sel + sense.sign() * times).rem_euclid(n) as usize;
                }
            }
            Action::Mode(q) => self.mode = q,
            Action::StepSize(sense) => {
                let i = quantity_index(self.mode);
                for _ in 0..count.min(100) {
                    self.steps[i] = match sense {
                        Sense::Forward => ladder_up(self.steps[i]),
                        Sense::Back => ladder_down(self.steps[i]),
                    };
                }
                self.say(Level::Info, step_words(self.mode, self.steps[i]));
            }
            Action::Nail => self.nail(core, StateQuantity::ALL.to_vec(), Vec::new()),
            Action::Float => self.float(core, None, StateQuantity::ALL.to_vec(), Vec::new()),
            Action::EventControls => {
                if self
                    .apply(
                        core,
                        Edit::AddEventControls {
                            normal: true,
                            restitution: true,
                        },
                    )
                    .is_some()
                {
                    self.say_info("added normal and restitution controls at the nearest event");
                }
            }
            Action::ToggleEventControls => self.set_event_controls(core, None, None),
            Action::DeleteConstraint => self.delete_constraint(core, None),
            Action::BlockPrefix => self.input = Input::Block,
            Action::ToggleBlock(block) => {
                self.input = Input::Normal;
                let view = core.view();
                let free = !block_is_free(&view, view.selected, block);
                self.set_block(core, view.selected, block, free);
            }
            Action::Cancel => {
                if self.input == Input::Normal && !self.cancel_accuracy() {
                    self.cancel_exploring();
                    if let Some(stopped) = core.stop() {
                        self.say_info(stopped);
                    }
                }
                self.input = Input::Normal;
                self.drag = None;
            }
            Action::Explore => self.explore(core, EXPLORE_SAMPLES),
            Action::Accuracy => self.measure_accuracy(core),
            Action::PickAccuracy => self.pick_accuracy(core),
            Action::Alternative(sense) => self.step_alternative(sense),
            Action::AcceptAlternative { settle } => {
                if self.accept_alternative(core, settle) && settle {
                    self.settle(core, SETTLE_MS);
                }
            }
            Action::ToggleGhost => {
                self.show_ghost = !self.show_ghost;
                let shown = if self.show_ghost { "shown" } else { "hidden" };
                self.say(
                    Level::Info,
                    format!("the motion before the last edit is {shown} (g toggles)"),
                );
            }
            Action::Settle => self.settle(core, SETTLE_MS),
            Action::Undo => self.repeat(core, Edit::Undo, count),
            Action::Redo => self.repeat(core, Edit::Redo, count),
            Action::Play => {
                self.playing = !self.playing;
            }
            Action::View(kind) => {
                self.camera.kind = kind;
                if self.auto_fit {
                    self.refit(&core.view());
                }
            }
            Action::Yaw(sense) | Action::Pitch(sense) => {
                let angle = (sense.sign() * times.min(24)) as f64 * ORBIT_STEP;
                match action {
                    Action::Yaw(_) => self.camera.orbit(angle, 0.0),
                    _ => self.camera.orbit(0.0, angle),
                }
                if self.auto_fit {
                    self.refit(&core.view());
                }
            }
            Action::Pan(dir) => {
                let (dx, dy) = dir.unit();
                let k = PAN_STEP * f64::from(count.min(1000));
                self.camera.pan(dx * k, dy * k);
                self.auto_fit = false;
            }
            Action::Zoom(sense) => {
                let n = times.min(100) as i32 * sense.sign() as i32;
                self.camera.zoom(ZOOM_STEP.powi(n));
                self.auto_fit = false;
            }
            Action::ResetView => {
                if matches!(self.camera.kind, ViewKind::Orbit { .. }) {
                    self.camera.kind = ViewKind::DEFAULT_ORBIT;
                }
                self.auto_fit = true;
                self.refit(&core.view());
            }
            Action::CommandLine => self.input = Input::Command(String::new()),
            Action::CommandRun => {
                let line = match std::mem::replace(&mut self.input, Input::Normal) {
                    Input::Command(line) => line,
                    _ => String::new(),
                };
                self.run_command(core, &line);
            }
            Action::CommandBackspace => {
                if let Input::Command(buf) = &mut self.input
                    && buf.pop().is_none()
                {
                    self.input = Input::Normal;
                }
            }
            Action::CommandClear => {
                if let Input::Command(buf) = &mut self.input {
                    buf.clear();
                }
            }
            Action::Popup(kind) => {
                if kind == PopupKind::Jacobian {
                    self.sensitivity = Some(core.sensitivity());
                }
                self.open(kind);
            }
            Action::Scroll(sense) => {
                if let Input::Popup { kind, scroll } = self.input {
                    if kind == PopupKind::Accuracy {
                        self.step_accuracy(sense, count);
                        return;
                    }
                    let step = u16::try_from(count).unwrap_or(u16::MAX);
                    // Clamped, so scrolling back after overshooting the end
                    // moves at once.
                    let notes = core.view().notes;
                    let max = popup::max_scroll(kind, self.popup_data(&notes), self.area);
                    let scroll = match sense {
                        Sense::Forward => scroll.saturating_add(step),
                        Sense::Back => scroll.saturating_sub(step),
                    }
                    .min(max);
                    self.input = Input::Popup { kind, scroll };
                }
            }
            Action::Quit => {
                if core.dirty() {
                    self.input = Input::Prompt;
                } else {
                    self.quit = true;
                }
            }
            Action::ConfirmQuit => self.quit = true,
            Action::SaveQuit => {
                self.input = Input::Normal;
                self.write(core, None, false, true);
            }
        }
    }

    /// Apply the accumulated nudge, if any, as one edit.
    pub fn flush(&mut self, core: &mut impl Core) {
        if let Some((quantity, delta)) = self.pending.take() {
            self.apply(core, Edit::Nudge { quantity, delta });
        }
    }

    /// Advance the animation by `dt` seconds of motion time (looping at the
    /// end). Does nothing unless playing.
    pub fn tick(&mut self, core: &mut impl Core, dt: f64) {
        if !self.playing {
            return;
        }
        self.flush(core);
        let view = core.view();
        if !(view.duration.is_finite()
            && view.duration > 0.0
            && dt.is_finite()
            && view.time.is_finite())
        {
            self.playing = false;
            return;
        }
        let mut t = view.time + dt;
        if t > view.duration {
            t = 0.0;
        }
        if self.apply(core, Edit::SelectTime(t)).is_none() {
            self.playing = false;
        }
    }

    fn add_nudge(&mut self, core: &mut impl Core, delta: Vec3) {
        if !delta.iter().all(|v| v.is_finite()) {
            self.say(Level::Error, "nudge too large; - makes the step smaller");
            return;
        }
        match &mut self.pending {
            Some((q, sum)) if *q == self.mode => *sum += delta,
            _ => {
                self.flush(core);
                self.pending = Some((self.mode, delta));
            }
        }
    }

    /// Apply an edit, timing it; report errors and diagnostics.
    fn apply(&mut self, core: &mut impl Core, edit: Edit) -> Option<Outcome> {
        // Alternatives explored from a motion no longer apply once it changes.
        let changes_motion = !matches!(
            edit,
            Edit::SelectBody(_) | Edit::SelectTime(_) | Edit::SelectEvent(_)
        );
        if changes_motion && matches!(self.exploring, Exploring::Browsing { .. }) {
            self.exploring = Exploring::Idle;
        }
        if changes_motion {
            self.note_edit_while_measuring();
        }
        let start = Instant::now();
        let result = core.apply(edit);
        self.apply_ms.push(start.elapsed().as_secs_f64() * 1e3);
        match result {
            Ok(outcome) => {
                self.edits += 1;
                if !outcome.notes.is_empty() {
                    let mut text: Vec<String> =
                        outcome.notes.iter().map(ToString::to_string).collect();
                    let blocked = outcome.notes.iter().any(|n| {
                        matches!(
                            n,
                            crate::edit::Note::Solver(crate::solve::Diagnostic::Blocked)
                        )
                    });
                    if blocked {
                        text.push("X explores further afield".into());
                    }
                    self.say(Level::Warning, text.join("; "));
                }
                Some(outcome)
            }
            Err(e) => {
                self.say(Level::Error, e.to_string());
                None
            }
        }
    }

    /// The last command line that did not parse, if any since the last
    /// call (a key script stops there).
    pub fn take_command_error(&mut self) -> Option<command::CommandError> {
        self.command_error.take()
    }

    /// What the popups show, with the scene's `notes`.
    pub fn popup_data<'a>(&'a self, notes: &'a str) -> popup::PopupData<'a> {
        popup::PopupData {
            log: &self.log,
            notes,
            sensitivity: self.sensitivity.as_ref(),
            accuracy: self.measurements(),
        }
    }

    /// Open a popup at its top.
    fn open(&mut self, kind: PopupKind) {
        self.input = Input::Popup { kind, scroll: 0 };
    }
}

/// Whether any control row of `body`'s `block` is free. Control rows are
/// named `body.block` or `body.block.component`.
pub fn block_is_free(view: &View, body: usize, block: Block) -> bool {
    let Some(name) = view.bodies.get(body) else {
        return false;
    };
    let prefix = format!("{name}.{}", block.name());
    view.controls
        .iter()
        .any(|c| c.free && (c.name == prefix || c.name.starts_with(&format!("{prefix}."))))
}

/// What one nudge key does now, in the quantity's units.
fn step_words(mode: StateQuantity, step: f64) -> String {
    let n = |v: f64| super::format::num(v, 8);
    let what = match mode {
        StateQuantity::Position => format!("moves the body {} m", n(step)),
        StateQuantity::Orientation => {
            format!("turns the body {}° ({} rad)", n(step.to_degrees()), n(step))
        }
        StateQuantity::Velocity => format!("changes its velocity by {} m/s", n(step)),
        StateQuantity::AngularVelocity => format!(
            "changes its angular velocity by {} rad/s ({}°/s)",
            n(step),
            n(step.to_degrees())
        ),
    };
    format!("nudge step: one key {what} (H J K L: 10×)")
}

fn quantity_index(q: StateQuantity) -> usize {
    StateQuantity::ALL.iter().position(|x| *x == q).unwrap_or(0)
}

/// After a constraint with typed values: how far off it is, and how to
/// meet it (the constraint is added as typed; `s` iterates towards it).
fn settle_hint(typed: bool, view: &View) -> String {
    match view.constraints.last() {
        Some(c) if typed && c.residual > 1e-9 => format!(
            "; residual {}: s settles",
            super::format::num(c.residual, 6)
        ),
        _ => String::new(),
    }
}

fn quantity_names(qs: &[StateQuantity]) -> String {
    if qs.len() == StateQuantity::ALL.len() {
        return "the state".to_string();
    }
    qs.iter().map(|q| q.name()).collect::<Vec<_>>().join(", ")
}

/// Size of the scene: the largest side of the bounding box of every path
/// and obstacle point (1 if there is nothing finite).
fn scene_extent(view: &View) -> f64 {
    let pts = view
        .paths
        .iter()
        .flat_map(|p| p.points.iter())
        .chain(view.obstacles.iter().flat_map(|(a, b)| [a, b]));
    let mut lo = Vec3::repeat(f64::INFINITY);
    let mut hi = Vec3::repeat(f64::NEG_INFINITY);
    for p in pts.filter(|p| p.iter().all(|c| c.is_finite())) {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let e = (hi - lo).max();
    if e.is_finite() && e > 0.0 { e } else { 1.0 }
}

/// The largest value of the 1-2-5 ladder (…, 0.1, 0.2, 0.5, 1, 2, 5, …) not
/// above `v`, within the step range.
pub fn ladder(v: f64) -> f64 {
    if !(v.is_finite() && v > 0.0) {
        return 1.0;
    }
    let v = v.clamp(STEP_RANGE.0, STEP_RANGE.1);
    let mut decade = 10f64.powf(v.log10().floor());
    // `log10` may land a hair off an exact power of ten.
    if v / decade >= 10.0 - 1e-9 {
        decade *= 10.0;
    } else if v / decade < 1.0 - 1e-9 {
        decade /= 10.0;
    }
    let m = v / decade;
    let mantissa = if m >= 5.0 - 1e-9 {
        5.0
    } else if m >= 2.0 - 1e-9 {
        2.0
    } else {
        1.0
    };
    mantissa * decade
}

/// The next value up the 1-2-5 ladder.
pub fn ladder_up(v: f64) -> f64 {
    let v = ladder(v);
    ladder((v * 2.6).min(STEP_RANGE.1))
}

/// The next value down the 1-2-5 ladder.
pub fn ladder_down(v: f64) -> f64 {
    let v = ladder(v);
    ladder((v / 1.9).max(STEP_RANGE.0))
}

#[cfg(test)]
mod tests;
