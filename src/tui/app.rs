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
use super::theme::Theme;
use super::widgets;
use crate::edit::{Core, Edit, Expression, Outcome, Side, Vertical};
use crate::files::WriteMode;
use crate::math::Vec3;
use crate::scene::{Accuracy, Block, Method, StateQuantity};
use crate::view::{ControlRow, View};
use ratatui::layout::Rect;
use std::time::Instant;

/// Where keys go.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Input {
    Normal,
    /// After `b`, waiting for a block letter.
    Block,
    /// Typing a `:` command (the text so far, without the `:`).
    Command(String),
    /// The help popup, scrolled this many lines.
    Help {
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
            Input::Normal => Context::Normal,
            Input::Block => Context::Block,
            Input::Command(_) => Context::Command,
            Input::Help { .. } => Context::Help,
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
        let canvas = widgets::canvas_inner(self.area);
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
        if let Some(action) = keymap::lookup(context, key) {
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
            Action::Cancel => self.input = Input::Normal,
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
            Action::Help => self.input = Input::Help { scroll: 0 },
            Action::HelpScroll(sense) => {
                if let Input::Help { scroll } = &mut self.input {
                    let step = u16::try_from(count).unwrap_or(u16::MAX);
                    // Clamped, so scrolling back after overshooting the end
                    // moves at once.
                    let max = super::widgets::HelpPopup::max_scroll(self.area);
                    *scroll = match sense {
                        Sense::Forward => scroll.saturating_add(step),
                        Sense::Back => scroll.saturating_sub(step),
                    }
                    .min(max);
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
        let start = Instant::now();
        let result = core.apply(edit);
        self.apply_ms.push(start.elapsed().as_secs_f64() * 1e3);
        match result {
            Ok(outcome) => {
                self.edits += 1;
                if !outcome.diagnostics.is_empty() {
                    self.say(Level::Warning, outcome.diagnostics.join("; "));
                }
                Some(outcome)
            }
            Err(e) => {
                self.say(Level::Error, e.to_string());
                None
            }
        }
    }

    fn say(&mut self, level: Level, text: impl Into<String>) {
        self.message = Some(Message {
            text: text.into(),
            level,
        });
    }

    /// An informational message, unless the edit already left a diagnostic.
    fn say_info(&mut self, text: impl Into<String>) {
        if self.message.is_none() {
            self.say(Level::Info, text);
        }
    }

    fn repeat(&mut self, core: &mut impl Core, edit: Edit, count: u32) {
        for _ in 0..count {
            if self.apply(core, edit.clone()).is_none() {
                break;
            }
        }
    }

    fn step_event(&mut self, core: &mut impl Core, sense: Sense, count: usize) {
        let view = core.view();
        let mut events: Vec<_> = view.events.iter().filter(|e| e.t.is_finite()).collect();
        events.sort_by(|a, b| a.t.total_cmp(&b.t));
        let tol = 1e-9 * view.duration.abs().max(1.0);
        let t = view.time;
        let target = match sense {
            Sense::Forward => {
                let later: Vec<_> = events.iter().filter(|e| e.t > t + tol).collect();
                later
                    .get(count.saturating_sub(1).min(later.len().saturating_sub(1)))
                    .map(|e| e.index)
            }
            Sense::Back => {
                let earlier: Vec<_> = events.iter().filter(|e| e.t < t - tol).collect();
                let k = earlier.len().saturating_sub(count);
                earlier.get(k).map(|e| e.index)
            }
        };
        match target {
            Some(k) => {
                self.apply(core, Edit::SelectEvent(k));
            }
            None => {
                let which = if sense == Sense::Forward {
                    "later"
                } else {
                    "earlier"
                };
                self.say(Level::Warning, format!("no {which} collision event"));
            }
        }
    }

    fn nail(
        &mut self,
        core: &mut impl Core,
        quantities: Vec<StateQuantity>,
        exact: Vec<(StateQuantity, Vec3)>,
    ) {
        let names = quantity_names(&quantities);
        let typed = !exact.is_empty();
        if self.apply(core, Edit::Nail { quantities, exact }).is_some() {
            let view = core.view();
            let body = view.bodies.get(view.selected).cloned().unwrap_or_default();
            self.say_info(format!(
                "nailed {names} of {body} at t={}{}",
                super::format::num(view.time, 8),
                settle_hint(typed, &view)
            ));
        }
    }

    /// A floating constraint at the selected body's collision nearest the
    /// current time; without an explicit side, `pre` if that collision is
    /// still ahead and `post` otherwise.
    fn float(
        &mut self,
        core: &mut impl Core,
        side: Option<Side>,
        quantities: Vec<StateQuantity>,
        exact: Vec<(StateQuantity, Vec3)>,
    ) {
        let view = core.view();
        let body = view.bodies.get(view.selected).cloned().unwrap_or_default();
        // The body's collisions, numbered as the constraints panel does.
        let nearest = view
            .events
            .iter()
            .filter(|e| e.t.is_finite() && (e.a == body || e.b == body))
            .enumerate()
            .min_by(|x, y| {
                (x.1.t - view.time)
                    .abs()
                    .total_cmp(&(y.1.t - view.time).abs())
            });
        let side = side.unwrap_or(match nearest {
            Some((_, e)) if view.time < e.t => Side::Pre,
            _ => Side::Post,
        });
        let names = quantity_names(&quantities);
        let typed = !exact.is_empty();
        if self
            .apply(
                core,
                Edit::Float {
                    quantities,
                    exact,
                    side,
                },
            )
            .is_some()
        {
            let at = nearest
                .map(|(k, e)| format!(" at its collision #{k} (event {})", e.index))
                .unwrap_or_default();
            let side = if side == Side::Pre { "pre" } else { "post" };
            let hint = settle_hint(typed, &core.view());
            self.say_info(format!("floating {names} of {body}{at} ({side}){hint}"));
        }
    }

    fn delete_constraint(&mut self, core: &mut impl Core, row: Option<usize>) {
        let n = core.view().constraints.len();
        let row = row.unwrap_or(self.selected_constraint.min(n.saturating_sub(1)));
        if n == 0 {
            self.say(Level::Warning, "no constraint to delete");
        } else if row >= n {
            self.say(
                Level::Error,
                format!("no constraint row {row}; rows are 0 to {}", n - 1),
            );
        } else if self.apply(core, Edit::RemoveConstraint(row)).is_some() {
            let left = core.view().constraints.len();
            self.selected_constraint = self.selected_constraint.min(left.saturating_sub(1));
            self.say_info(format!("deleted constraint {row}"));
        }
    }

    fn set_block(&mut self, core: &mut impl Core, body: usize, block: Block, free: bool) {
        if self
            .apply(core, Edit::SetBlock { body, block, free })
            .is_some()
        {
            let view = core.view();
            let name = view.bodies.get(body).cloned().unwrap_or_default();
            let state = if free { "free" } else { "fixed" };
            self.say_info(format!("{name}.{} is {state}", block.name()));
        }
    }

    /// Fix or free an event's controls and say which entries changed.
    fn set_event_controls(
        &mut self,
        core: &mut impl Core,
        event: Option<usize>,
        free: Option<bool>,
    ) {
        let before = core.view().controls;
        if self
            .apply(core, Edit::SetEventControls { event, free })
            .is_some()
        {
            let after = core.view().controls;
            let changed: Vec<&ControlRow> = after
                .iter()
                .filter(|r| before.iter().any(|b| b.name == r.name && b.free != r.free))
                .collect();
            match changed.first() {
                Some(first) => {
                    let state = if first.free { "free" } else { "fixed" };
                    let names: Vec<&str> = changed.iter().map(|r| r.name.as_str()).collect();
                    self.say_info(format!("{state}: {}", names.join(" ")));
                }
                None => {
                    let state = if free == Some(true) { "free" } else { "fixed" };
                    self.say_info(format!("the event's controls were already {state}"));
                }
            }
        }
    }

    fn settle(&mut self, core: &mut impl Core, budget_ms: u64) {
        if let Some(o) = self.apply(core, Edit::Settle { budget_ms }) {
            let residual = super::format::num(core.view().status.residual, 8);
            self.say_info(format!(
                "settled: {} updates, residual {residual}",
                o.updates
            ));
        }
    }

    fn write(
        &mut self,
        core: &mut impl Core,
        path: Option<&std::path::Path>,
        force: bool,
        then_quit: bool,
    ) {
        let start = Instant::now();
        let mode = if force {
            WriteMode::Force
        } else {
            WriteMode::Normal
        };
        let result = core.save(path, mode);
        self.apply_ms.push(start.elapsed().as_secs_f64() * 1e3);
        match result {
            Ok(saved) => {
                let path = saved.path.display();
                match saved.layout_lost {
                    None => self.say(Level::Info, format!("wrote {path}")),
                    Some(why) => self.say(
                        Level::Warning,
                        format!("wrote {path} as new text, without its comments ({why})"),
                    ),
                }
                self.quit |= then_quit;
            }
            Err(e) => self.say(Level::Error, e.to_string()),
        }
    }

    /// Body index from a name or an index.
    fn body_index(&mut self, view: &View, word: &str) -> Option<usize> {
        if let Some(i) = view.bodies.iter().position(|b| b == word) {
            return Some(i);
        }
        match word.parse::<usize>() {
            Ok(i) if i < view.bodies.len() => Some(i),
            _ => {
                let names = view.bodies.join(", ");
                self.say(Level::Error, format!("no body {word}; bodies: {names}"));
                None
            }
        }
    }

    fn remember(&mut self, method: Method) {
        match method {
            Method::Rk4 { step } => self.rk4_step = step,
            Method::Adaptive { tol, max_step } => {
                self.tolerance = tol;
                self.max_step = max_step;
            }
        }
    }

    fn run_command(&mut self, core: &mut impl Core, line: &str) {
        let cmd = match command::parse(line) {
            Ok(cmd) => cmd,
            Err(e) => {
                self.say(Level::Error, e.to_string());
                return;
            }
        };
        let view = core.view();
        // The core's settings are the truth (a scene may set its own root
        // tolerance); remember them so a `:set` changes only what it names.
        self.remember(view.accuracy.method);
        self.root_tol = view.accuracy.root_tol;
        let current = view.accuracy.method;
        let accuracy = |app: &App, method: Method| Accuracy {
            method,
            root_tol: app.root_tol,
        };
        match cmd {
            Command::Nail { quantities, exact } => self.nail(core, quantities, exact),
            Command::Vertical(goal, side) => {
                if self.apply(core, Edit::Vertical { goal, side }).is_some() {
                    let view = core.view();
                    let body = view.bodies.get(view.selected).cloned().unwrap_or_default();
                    let at = match side {
                        None => format!("at t={}", super::format::num(view.time, 8)),
                        Some(Side::Pre) => "just before its nearest collision".to_string(),
                        Some(Side::Post) => "just after its nearest collision".to_string(),
                    };
                    let hint = settle_hint(true, &view);
                    let what = match goal {
                        Vertical::Upright => "upright",
                        Vertical::Steady => "spins about the vertical only",
                    };
                    self.say_info(format!("{body} {what} {at}{hint}"));
                }
            }
            Command::Float {
                side,
                quantities,
                exact,
            } => self.float(core, side, quantities, exact),
            Command::SetTol(tol) => {
                let method = Method::Adaptive {
                    tol,
                    max_step: self.max_step,
                };
                if self
                    .apply(core, Edit::SetAccuracy(accuracy(self, method)))
                    .is_some()
                {
                    self.remember(method);
                }
            }
            Command::SetStep(step) => {
                let method = Method::Rk4 { step };
                if self
                    .apply(core, Edit::SetAccuracy(accuracy(self, method)))
                    .is_some()
                {
                    self.remember(method);
                }
            }
            Command::SetMethod(name) => {
                let method = match name {
                    MethodName::Rk4 => Method::Rk4 {
                        step: self.rk4_step,
                    },
                    MethodName::Adaptive => Method::Adaptive {
                        tol: self.tolerance,
                        max_step: self.max_step,
                    },
                };
                self.apply(core, Edit::SetAccuracy(accuracy(self, method)));
            }
            Command::SetRootTol(root_tol) => {
                let method = current;
                if self
                    .apply(core, Edit::SetAccuracy(Accuracy { method, root_tol }))
                    .is_some()
                {
                    self.root_tol = root_tol;
                }
            }
            Command::SetScale { kind, value } => {
                self.apply(core, Edit::SetScale { kind, value });
            }
            Command::SetNudge(step) => {
                self.steps[quantity_index(self.mode)] = step.clamp(STEP_RANGE.0, STEP_RANGE.1);
            }
            Command::SetBlock { body, block, free } => {
                if let Some(i) = self.body_index(&view, &body) {
                    self.set_block(core, i, block, free);
                }
            }
            Command::SetEventControls { event, free } => {
                self.set_event_controls(core, event, Some(free));
            }
            Command::Time(t) => {
                self.apply(core, Edit::SelectTime(t));
            }
            Command::Event(k) => {
                self.apply(core, Edit::SelectEvent(k));
            }
            Command::Body(b) => {
                if let Some(i) = self.body_index(&view, &b) {
                    self.apply(core, Edit::SelectBody(i));
                }
            }
            Command::Delete(k) => self.delete_constraint(core, Some(k)),
            Command::EqualSpeed(other) => {
                if let Some(other) = self.body_index(&view, &other) {
                    let body = view.bodies.get(view.selected).cloned().unwrap_or_default();
                    if other == view.selected {
                        self.say(
                            Level::Error,
                            format!("{body} always has its own speed: name another body"),
                        );
                    } else if self
                        .apply(core, Edit::Expression(Expression::EqualSpeed { other }))
                        .is_some()
                    {
                        let hint = settle_hint(true, &core.view());
                        self.say_info(format!(
                            "{body} as fast as {} at t={}{hint}",
                            view.bodies[other],
                            super::format::num(view.time, 8)
                        ));
                    }
                }
            }
            Command::Spin(value) => {
                if self
                    .apply(core, Edit::Expression(Expression::AngularSpeed { value }))
                    .is_some()
                {
                    let body = view.bodies.get(view.selected).cloned().unwrap_or_default();
                    let hint = settle_hint(true, &core.view());
                    self.say_info(format!(
                        "{body} spinning at {} rad/s at t={}{hint}",
                        super::format::num(value, 8),
                        super::format::num(view.time, 8)
                    ));
                }
            }
            Command::Settle(ms) => self.settle(core, ms),
            Command::Undo => self.repeat(core, Edit::Undo, 1),
            Command::Redo => self.repeat(core, Edit::Redo, 1),
            Command::Write { path, force } => self.write(core, path.as_deref(), force, false),
            Command::WriteQuit { path, force } => self.write(core, path.as_deref(), force, true),
            Command::Quit => {
                if core.dirty() {
                    self.say(Level::Error, "unsaved edits: :w saves, :q! discards them");
                } else {
                    self.quit = true;
                }
            }
            Command::ForceQuit => self.quit = true,
            Command::Help => self.input = Input::Help { scroll: 0 },
        }
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
mod tests {
    use super::*;
    use crate::script::parse_keys;
    use crate::tui::fixtures::{self, FakeCore};

    fn session(script: &str) -> (App, FakeCore) {
        let mut core = fixtures::core();
        let mut app = fixtures::app(&core.view(), 80, 24);
        for key in parse_keys(script, "test").unwrap_or_default() {
            app.handle_key(&mut core, key);
            app.flush(&mut core);
        }
        (app, core)
    }

    fn only_edit(core: &FakeCore) -> &Edit {
        match core.log.as_slice() {
            [e] => e,
            other => panic!("expected one edit, got {other:?}"),
        }
    }

    fn nudge_delta(core: &FakeCore) -> Vec3 {
        match only_edit(core) {
            Edit::Nudge { delta, .. } => *delta,
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn counts_start_with_5_to_9_and_continue_with_any_digit() {
        let (app, core) = session("50l");
        assert!((nudge_delta(&core) - Vec3::x() * 50.0 * app.step()).norm() < 1e-12);
        let (app, core) = session("1");
        assert!(core.log.is_empty() && app.count.is_none());
        assert_eq!(app.camera.kind, ViewKind::Front);
    }

    #[test]
    fn escape_abandons_a_count_without_quitting() {
        let (app, core) = session("7<Esc>l");
        assert!(!app.quit);
        assert!((nudge_delta(&core) - Vec3::x() * app.step()).norm() < 1e-12);
    }

    #[test]
    fn big_nudges_follow_the_camera() {
        let (app, core) = session("2K");
        assert_eq!(app.camera.kind, ViewKind::Side);
        assert!((nudge_delta(&core) - Vec3::z() * 10.0 * app.step()).norm() < 1e-12);
        let (app, core) = session("3<S-Left>");
        assert!((nudge_delta(&core) + Vec3::x() * 10.0 * app.step()).norm() < 1e-12);
    }

    #[test]
    fn orientation_nudges_turn_about_the_line_of_sight() {
        // Front view: the line of sight is +y, so `l` (clockwise as seen)
        // is a positive turn about +y.
        let (app, core) = session("Ol");
        let d = nudge_delta(&core);
        assert!((d - Vec3::y() * app.step()).norm() < 1e-12, "{d:?}");
        assert!(matches!(
            only_edit(&core),
            Edit::Nudge {
                quantity: StateQuantity::Orientation,
                ..
            }
        ));
    }

    #[test]
    fn time_events_and_bodies() {
        let (_, core) = session("]");
        assert_eq!(only_edit(&core), &Edit::SelectTime(0.8 + 0.02));
        let (_, core) = session("}");
        assert_eq!(only_edit(&core), &Edit::SelectEvent(0));
        let (app, core) = session("{");
        assert!(core.log.is_empty());
        assert_eq!(
            app.message.map(|m| m.text),
            Some("no earlier collision event".to_string())
        );
        let (_, core) = session("<S-Tab>");
        assert_eq!(only_edit(&core), &Edit::SelectBody(1));
    }

    #[test]
    fn block_prefix_toggles_from_what_the_view_shows() {
        // ball.velocity.* rows are free in the fixture: `b v` fixes them.
        let (app, core) = session("bv");
        assert_eq!(
            only_edit(&core),
            &Edit::SetBlock {
                body: 0,
                block: Block::Velocity,
                free: false
            }
        );
        assert_eq!(app.input, Input::Normal);
        let (_, core) = session("bm");
        assert_eq!(
            only_edit(&core),
            &Edit::SetBlock {
                body: 0,
                block: Block::Mass,
                free: true
            }
        );
        let (app, core) = session("bq");
        assert!(core.log.is_empty() && app.input == Input::Normal && app.message.is_some());
    }

    #[test]
    fn float_picks_the_side_from_the_current_time() {
        let (_, core) = session("f");
        assert_eq!(
            only_edit(&core),
            &Edit::Float {
                quantities: StateQuantity::ALL.to_vec(),
                exact: vec![],
                side: Side::Pre
            }
        );
        let (_, core) = session(":float<Space>post<Space>pos<CR>");
        assert_eq!(
            only_edit(&core),
            &Edit::Float {
                quantities: vec![StateQuantity::Position],
                exact: vec![],
                side: Side::Post
            }
        );
    }

    #[test]
    fn accuracy_commands_keep_the_other_settings() {
        let (_, core) = session(":set<Space>tol<Space>1e-9<CR>");
        let expected = Accuracy {
            method: Method::Adaptive {
                tol: 1e-9,
                max_step: 1e-2,
            },
            root_tol: 1e-12,
        };
        assert_eq!(only_edit(&core), &Edit::SetAccuracy(expected));
        let (_, core) = session(":set<Space>method<Space>rk4<CR>");
        let expected = Accuracy {
            method: Method::Rk4 { step: 1e-3 },
            root_tol: 1e-12,
        };
        assert_eq!(only_edit(&core), &Edit::SetAccuracy(expected));
    }

    #[test]
    fn delete_needs_a_constraint_and_keeps_the_selection_in_range() {
        let (app, core) = session("cx");
        assert_eq!(only_edit(&core), &Edit::RemoveConstraint(0));
        assert_eq!(app.selected_constraint, 0);
        let (app, core) = session("xx");
        assert_eq!(core.log.len(), 1);
        assert_eq!(
            app.message.map(|m| m.text),
            Some("no constraint to delete".to_string())
        );
    }

    #[test]
    fn quitting_with_unsaved_edits_asks_and_can_save() {
        let (app, core) = session("l q");
        assert_eq!(app.input, Input::Prompt);
        assert!(!app.quit && core.saved.is_empty());
        let (app, core) = session("l q w");
        assert!(app.quit);
        assert_eq!(core.saved, vec![None]);
        let (app, core) = session(":w<Space>out.toml<CR>");
        assert!(!app.quit);
        assert_eq!(core.saved, vec![Some(std::path::PathBuf::from("out.toml"))]);
    }

    #[test]
    fn command_line_editing() {
        let (app, _) = session(":se<BS><BS><BS>");
        assert_eq!(app.input, Input::Normal);
        let (app, _) = session(":set<C-u>ab");
        assert_eq!(app.input, Input::Command("ab".into()));
        let (app, core) = session(":body<Space>box<CR>");
        assert_eq!(only_edit(&core), &Edit::SelectBody(1));
        assert!(app.message.is_none());
        let (app, core) = session(":free<Space>crate<Space>mass<CR>");
        assert!(core.log.is_empty());
        assert_eq!(
            app.message.map(|m| m.text),
            Some("no body crate; bodies: ball, box".to_string())
        );
    }

    #[test]
    fn step_ladder() {
        assert_eq!(ladder(0.046), 0.02);
        assert_eq!(ladder(0.1), 0.1);
        assert_eq!(ladder(f64::NAN), 1.0);
        let mut v = 1.0;
        let mut seen = Vec::new();
        for _ in 0..3 {
            v = ladder_up(v);
            seen.push(v);
        }
        assert_eq!(seen, [2.0, 5.0, 10.0]);
        assert!((ladder_down(0.1) - 0.05).abs() < 1e-15);
        assert!(ladder_up(1e9) <= 1e9 && ladder_down(1e-9) >= 1e-9);
    }

    #[test]
    fn zoom_and_pan_stop_following_the_scene_until_reset() {
        let (app, _) = session("z");
        assert!(!app.auto_fit);
        let (app, _) = session("<C-Left>0");
        assert!(app.auto_fit);
        let (app, _) = session("4<lt>^");
        assert!(matches!(app.camera.kind, ViewKind::Orbit { .. }));
    }
}
