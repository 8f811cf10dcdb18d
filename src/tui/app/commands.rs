//! The App's edits and commands: what an action or a `:` command asks of
//! the core (nails, floating constraints, blocks, event controls, settles,
//! saves), and the command line's dispatch.

use super::*;

impl App {
    /// Undo or redo `count` times, saying what was undone or redone.
    pub(super) fn repeat(&mut self, core: &mut impl Core, edit: Edit, count: u32) {
        let mut done = Vec::new();
        for _ in 0..count {
            match self.apply(core, edit.clone()) {
                Some(o) => done.extend(o.reverted),
                None => break,
            }
        }
        let verb = if edit == Edit::Undo { "undid" } else { "redid" };
        match done.as_slice() {
            [] => {}
            [one] => self.say_info(format!("{verb} the {one}")),
            [first, .., last] => self.say_info(format!(
                "{verb} {} edits, from the {first} to the {last}",
                done.len()
            )),
        }
    }

    /// Go to event `k` and say what collided there.
    pub(super) fn go_to_event(&mut self, core: &mut impl Core, k: usize) {
        if self.apply(core, Edit::SelectEvent(k)).is_some() {
            let view = core.view();
            if let Some(e) = view.events.iter().find(|e| e.index == k) {
                self.say_info(e.describe());
            }
        }
    }

    pub(super) fn step_event(&mut self, core: &mut impl Core, sense: Sense, count: usize) {
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
            Some(k) => self.go_to_event(core, k),
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

    pub(super) fn nail(
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
                crate::tui::format::num(view.time, 8),
                settle_hint(typed, &view)
            ));
        }
    }

    /// A floating constraint at the selected body's collision nearest the
    /// current time; without an explicit side the core picks `pre` if that
    /// collision is still ahead and `post` otherwise, and says which.
    pub(super) fn float(
        &mut self,
        core: &mut impl Core,
        side: Option<Side>,
        quantities: Vec<StateQuantity>,
        exact: Vec<(StateQuantity, Vec3)>,
    ) {
        let view = core.view();
        let body = view.bodies.get(view.selected).cloned().unwrap_or_default();
        let names = quantity_names(&quantities);
        let typed = !exact.is_empty();
        let edit = Edit::Float {
            quantities,
            exact,
            side,
        };
        if let Some(outcome) = self.apply(core, edit) {
            let (at, side) = match outcome.anchored {
                Some(crate::edit::Anchored::Collision {
                    collision,
                    event,
                    side,
                }) => (
                    format!(" at its collision #{collision} (event {event})"),
                    side.word(),
                ),
                _ => (String::new(), "—"),
            };
            let hint = settle_hint(typed, &core.view());
            self.say_info(format!("floating {names} of {body}{at} ({side}){hint}"));
        }
    }

    pub(super) fn delete_constraint(&mut self, core: &mut impl Core, row: Option<usize>) {
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

    pub(super) fn set_block(
        &mut self,
        core: &mut impl Core,
        body: usize,
        block: Block,
        free: bool,
    ) {
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
    pub(super) fn set_event_controls(
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

    pub(super) fn settle(&mut self, core: &mut impl Core, budget_ms: u64) {
        if let Some(o) = self.apply(core, Edit::Settle { budget_ms })
            // A settle going on in the pauses shows its own progress.
            && core.view().status.busy.is_none()
        {
            let residual = crate::tui::format::num(core.view().status.residual, 8);
            let updates = match o.updates {
                1 => "1 update".to_string(),
                n => format!("{n} updates"),
            };
            self.tell(format!("settled: {updates}, residual {residual}"));
        }
    }

    pub(super) fn write(
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
    pub(super) fn body_index(&mut self, view: &View, word: &str) -> Option<usize> {
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

    pub(super) fn remember(&mut self, method: Method) {
        match method {
            Method::Rk4 { step } => self.rk4_step = step,
            Method::Adaptive { tol, max_step } => {
                self.tolerance = tol;
                self.max_step = max_step;
            }
        }
    }

    pub(super) fn run_command(&mut self, core: &mut impl Core, line: &str) {
        let cmd = match command::parse(line) {
            Ok(cmd) => cmd,
            Err(e) => {
                self.say(Level::Error, e.to_string());
                self.command_error = Some(e);
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
                        None => format!("at t={}", crate::tui::format::num(view.time, 8)),
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
            Command::Event(k) => self.go_to_event(core, k),
            Command::Release { row, quantities } => {
                let names = quantity_names(&quantities);
                if self
                    .apply(core, Edit::Release { row, quantities })
                    .is_some()
                {
                    self.say_info(format!("constraint row {row} no longer holds {names}"));
                }
            }
            Command::Messages => self.open(PopupKind::Messages),
            Command::Notes => self.open(PopupKind::Notes),
            Command::Explore(n) => self.explore(core, n),
            Command::Accuracy => self.measure_accuracy(core),
            Command::Export(path) => match core.export_gltf(&path, crate::export::DEFAULT_FPS) {
                Ok(bytes) => self.say(
                    Level::Info,
                    format!(
                        "wrote {} ({bytes} bytes of glTF, y up, {} keys/s and every collision)",
                        path.display(),
                        crate::export::DEFAULT_FPS
                    ),
                ),
                Err(e) => self.say(Level::Error, e.to_string()),
            },
            Command::Jacobian => self.handle_action(core, Action::Popup(PopupKind::Jacobian)),
            Command::SetMouse(on) => {
                self.mouse = on;
                self.say(
                    Level::Info,
                    if on {
                        "mouse on: click a trace to select, drag to nudge, wheel zooms"
                    } else {
                        "mouse off: the terminal selects text (:set mouse on to edit with it)"
                    },
                );
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
                            crate::tui::format::num(view.time, 8)
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
                        crate::tui::format::num(value, 8),
                        crate::tui::format::num(view.time, 8)
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
            Command::Help => self.open(PopupKind::Help),
        }
    }
}
