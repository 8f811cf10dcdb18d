//! The mouse: a click on a trace selects that body at that moment, a drag
//! nudges it in the view plane (the same differential edits as the keys,
//! accumulated and flushed the same way), the wheel zooms.

use super::*;

/// How close (in cells) a click must be to a trace to pick it.
const PICK_CELLS: f64 = 2.5;

impl App {
    /// One mouse event. Ignored while a popup, prompt or the command line
    /// has the keys, and when mouse editing is off.
    pub fn handle_mouse(&mut self, core: &mut impl Core, m: Mouse) {
        if !self.mouse || self.input != Input::Normal {
            return;
        }
        let canvas = layout::canvas_inner(self.area);
        let inside = m.col >= canvas.x
            && m.col < canvas.right()
            && m.row >= canvas.y
            && m.row < canvas.bottom();
        match m.kind {
            MouseKind::Press if inside => {
                self.message = None;
                self.flush(core);
                // A drag needs a body in hand: only a click on a trace starts one.
                self.drag = self.pick(core, m.col, m.row).then_some((m.col, m.row));
            }
            MouseKind::Drag => {
                let Some((c0, r0)) = self.drag else {
                    return;
                };
                let (dc, dr) = (
                    f64::from(m.col) - f64::from(c0),
                    f64::from(r0) - f64::from(m.row),
                );
                if dc == 0.0 && dr == 0.0 {
                    return;
                }
                self.drag = Some((m.col, m.row));
                self.message = None;
                let delta = self.drag_delta(dc, dr);
                self.add_nudge(core, delta);
            }
            MouseKind::Release => {
                self.drag = None;
                self.flush(core);
            }
            MouseKind::ScrollUp | MouseKind::ScrollDown if inside => {
                let sense = if m.kind == MouseKind::ScrollUp {
                    Sense::Forward
                } else {
                    Sense::Back
                };
                self.handle_action(core, Action::Zoom(sense));
            }
            _ => {}
        }
    }

    /// The cell's world position on the screen plane through the camera's
    /// target: `(right, up)` offsets in world units from the centre.
    fn cell_to_screen(&self, col: u16, row: u16) -> (f64, f64) {
        let canvas = layout::canvas_inner(self.area);
        let (xb, yb) = self.camera.bounds(canvas.width, canvas.height);
        let fx = (f64::from(col - canvas.x) + 0.5) / f64::from(canvas.width.max(1));
        let fy = (f64::from(row - canvas.y) + 0.5) / f64::from(canvas.height.max(1));
        (xb[0] + fx * (xb[1] - xb[0]), yb[1] - fy * (yb[1] - yb[0]))
    }

    /// World units per cell, horizontally and vertically.
    fn cell_size(&self) -> (f64, f64) {
        let canvas = layout::canvas_inner(self.area);
        let (xb, yb) = self.camera.bounds(canvas.width, canvas.height);
        (
            (xb[1] - xb[0]) / f64::from(canvas.width.max(1)),
            (yb[1] - yb[0]) / f64::from(canvas.height.max(1)),
        )
    }

    /// Select the body whose trace passes nearest the cell, at the time it
    /// passes there. Says what was picked, or that nothing is near; `true`
    /// if a body was picked.
    fn pick(&mut self, core: &mut impl Core, col: u16, row: u16) -> bool {
        let view = core.view();
        let (x, y) = self.cell_to_screen(col, row);
        let (cw, ch) = self.cell_size();
        let mut best: Option<(f64, usize, f64)> = None;
        for path in &view.paths {
            for (p, t) in path.points.iter().zip(&path.times) {
                let Some((u, v)) = self.camera.project(p) else {
                    continue;
                };
                // Distance in cells, so a tall cell counts as one.
                let d = ((u - x) / cw).hypot((v - y) / ch);
                if best.is_none_or(|(bd, ..)| d < bd) {
                    best = Some((d, path.body, *t));
                }
            }
        }
        match best {
            Some((d, body, t)) if d <= PICK_CELLS => {
                if body != view.selected && self.apply(core, Edit::SelectBody(body)).is_none() {
                    return false;
                }
                if self.apply(core, Edit::SelectTime(t)).is_none() {
                    return false;
                }
                {
                    let name = view.bodies.get(body).cloned().unwrap_or_default();
                    self.say(
                        Level::Info,
                        format!(
                            "{name} at t={}: drag to nudge its {}",
                            crate::tui::format::num(t, 6),
                            self.mode.name()
                        ),
                    );
                }
                true
            }
            _ => {
                self.say(
                    Level::Info,
                    "no trace here: click on a body's trace to select it at that moment",
                );
                false
            }
        }
    }

    /// The nudge a drag of `(dc, dr)` cells (right, up) asks for. In
    /// position mode the body follows the pointer in the view plane; in
    /// the other modes a cell counts as one key press.
    fn drag_delta(&self, dc: f64, dr: f64) -> Vec3 {
        let right = self.camera.right();
        let up = self.camera.up();
        match self.mode {
            StateQuantity::Position => {
                let (cw, ch) = self.cell_size();
                right * (dc * cw) + up * (dr * ch)
            }
            StateQuantity::Velocity => (right * dc + up * dr) * self.step(),
            StateQuantity::Orientation | StateQuantity::AngularVelocity => {
                -(self.camera.toward_viewer() * dc + right * dr) * self.step()
            }
        }
    }
}
