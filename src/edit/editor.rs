//! The one editing core: owns the scene (and so the control vector), the
//! constraints, the current motion and the undo history. Every change goes
//! through [`Core::apply`] and is atomic.

use super::{
    Anchored, BlockedBy, Core, Edit, EditError, Expression, Note, Outcome, Saved, Side, Vertical,
};
use crate::controls::Controls;
use crate::files::{WriteError, WriteMode};
use crate::math::{Vec3, exp_so3, log_so3};
use crate::report::{self, ConstraintRow};
use crate::scene::{self, ConstraintKind, ConstraintSpec, EventControl, Scene, StateQuantity};
use crate::sim::{Party, SimOptions, Trajectory, simulate};
use crate::solve::{self, Anchor, Constraint, Diagnostic, Kind, UpdateOptions};
use crate::view::{self, View};
use nalgebra::{Isometry3, Point3, Translation3};
use std::path::{Path, PathBuf};
use std::time::Instant;

mod apply;
mod explain;
mod interface;
mod motion;
mod readout;
mod settle;
mod spec;

use spec::{from_spec, to_spec};

/// Most differential updates one settle makes.
pub const MAX_SETTLE_UPDATES: usize = 100;

/// Step halvings a settling update tries (a drag tries
/// `UpdateOptions::halvings`): after an off-centre collision the linear
/// model can hold for 1/64 of the Gauss–Newton step only.
const SETTLE_HALVINGS: usize = 8;

/// What undo and redo restore.
#[derive(Clone)]
struct Snapshot {
    /// What the edit that left this state behind was (for undo's message).
    label: String,
    scene: Scene,
    constraints: Vec<Constraint>,
    /// The revision this state had: undoing back to the saved state makes
    /// the editor clean again.
    revision: u64,
}

/// The editor core.
pub struct Editor {
    scene: Scene,
    path: Option<PathBuf>,
    controls: Controls,
    constraints: Vec<Constraint>,
    traj: Trajectory,
    selected: usize,
    time: f64,
    undo: Vec<Snapshot>,
    redo: Vec<Snapshot>,
    revision: u64,
    saved_revision: u64,
    /// Last revision number handed out (each change gets a fresh one).
    revisions: u64,
    /// Change of every control entry made by the last edit.
    last_delta: Vec<f64>,
    status: view::Status,
    /// Wall time of every differential update, ms.
    update_ms: Vec<f64>,
    updates: usize,
    edits: usize,
    opts: UpdateOptions,
    /// Whether `settle` also stops at its wall-time budget (interactive
    /// use) or only by convergence and [`MAX_SETTLE_UPDATES`] (replays,
    /// whose results must not depend on the machine's speed).
    wall_clock: bool,
    paths: Vec<view::Path>,
    /// `paths` before the last edit that changed the motion.
    ghost: Vec<view::Path>,
    /// A nudge changed the motion and its integration error has not been
    /// estimated since: done when the user pauses ([`Core::idle`]) or at
    /// the next other edit, so a drag's frames do not wait for it.
    estimate_due: bool,
    obstacle_lines: Vec<(Vec3, Vec3)>,
    /// The drag of the last nudge when it was blocked: the goal the
    /// gradients could not reach, kept for exploring (`crate::explore`)
    /// until an edit other than a selection or another nudge.
    pending_drag: Option<Constraint>,
    /// The motion is an explored alternative the user accepted: nudges
    /// stay in its collision sequence (no pops) until another edit.
    held: bool,
    /// Keep a nudge's simulated prefix until a pause (`motion`).
    defer_motion: bool,
    /// `traj` is a prefix: the rest of the motion waits for a pause.
    motion_due: bool,
    /// While `motion_due`: the undo entry holding the last state whose
    /// motion was whole.
    whole_at: Option<usize>,
    /// Motions simulated so far ([`Editor::set_motion`]).
    motions: u64,
    /// A settle going on in the pauses (`settle`).
    settling: Option<settle::Settling>,
}

/// Every traced point's path on `traj`, as the screen draws it.
pub fn paths_of(scene: &Scene, traj: &Trajectory) -> Vec<view::Path> {
    let mut paths = Vec::new();
    for (i, b) in scene.bodies.iter().enumerate() {
        for p in &b.traced {
            let (times, points) = traj.path(i, p, 240).into_iter().unzip();
            paths.push(view::Path {
                body: i,
                points,
                times,
            });
        }
    }
    paths
}

fn invalid(msg: impl Into<String>) -> EditError {
    EditError::Invalid(msg.into())
}

fn finite3(v: &Vec3, what: &str) -> Result<(), EditError> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(())
    } else {
        Err(invalid(format!(
            "{what} must be finite numbers, got [{}, {}, {}]",
            v.x, v.y, v.z
        )))
    }
}

/// A state constraint's target: the current values of `quantities` in
/// `state`, except those given in `exact`.
fn targets(
    state: &crate::sim::BodyState,
    quantities: &[StateQuantity],
    exact: &[(StateQuantity, Vec3)],
) -> Result<Vec<f64>, EditError> {
    let mut target = Constraint::current_values(state, quantities);
    for (q, v) in exact {
        finite3(v, &format!("the {} to hold", q.name()))?;
        let k = quantities.iter().position(|x| x == q).ok_or_else(|| {
            invalid(format!(
                "a value for {} was given, but it is not among the held quantities",
                q.name()
            ))
        })?;
        let v = if *q == StateQuantity::Orientation {
            // The same rotation with |r| ≤ π, as the residual measures it.
            log_so3(&exp_so3(v))
        } else {
            *v
        };
        target[3 * k..3 * k + 3].copy_from_slice(v.as_slice());
    }
    Ok(target)
}

fn simulate_with_tangent(scene: &Scene, controls: &Controls) -> Result<Trajectory, EditError> {
    simulate(scene, controls, &SimOptions::default()).map_err(|e| invalid(e.to_string()))
}

impl Editor {
    /// Open a scene for editing (`path` is where `:w` saves by default).
    pub fn new(scene: Scene, path: Option<PathBuf>) -> Result<Editor, EditError> {
        let controls = Controls::new(&scene);
        let traj = simulate_with_tangent(&scene, &controls)?;
        let constraints = scene
            .constraints
            .iter()
            .filter_map(|c| from_spec(&scene, c))
            .collect();
        let accuracy = scene.accuracy.label();
        let mut e = Editor {
            last_delta: vec![0.0; controls.entries.len()],
            scene,
            path,
            controls,
            constraints,
            traj,
            selected: 0,
            time: 0.0,
            undo: Vec::new(),
            redo: Vec::new(),
            revision: 0,
            saved_revision: 0,
            revisions: 0,
            status: view::Status {
                accuracy,
                step: 1.0,
                ..Default::default()
            },
            update_ms: Vec::new(),
            updates: 0,
            edits: 0,
            opts: UpdateOptions::default(),
            wall_clock: true,
            paths: Vec::new(),
            ghost: Vec::new(),
            estimate_due: false,
            obstacle_lines: Vec::new(),
            pending_drag: None,
            held: false,
            defer_motion: false,
            motion_due: false,
            whole_at: None,
            motions: 0,
            settling: None,
        };
        e.refresh_geometry();
        e.status.residual = e.residual();
        e.status.message = e.estimate_error();
        Ok(e)
    }

    /// Estimate the motion's integration error (one more simulation,
    /// without tangents, at twice the accuracy: see `estimate`); the
    /// diagnostic when it exceeds the threshold.
    fn estimate_error(&mut self) -> Option<String> {
        let _span = crate::profile::span(crate::profile::Part::Estimate);
        match crate::estimate::error_estimate(&self.scene, &self.controls, &self.traj) {
            Ok(e) => {
                self.status.integration_error = Some(e.per_quantity);
                e.diagnostic()
            }
            Err(_) => {
                self.status.integration_error = None;
                None
            }
        }
    }

    /// Let `settle` stop at its wall-time budget (the default, for
    /// interactive use), or only when it converges, stalls or has made
    /// [`MAX_SETTLE_UPDATES`] updates (`false`: deterministic replays).
    pub fn set_wall_clock(&mut self, on: bool) {
        self.wall_clock = on;
    }

    /// Open a scene file.
    pub fn open(path: &Path) -> Result<Editor, EditError> {
        let scene = scene::load(path).map_err(|e| invalid(e.to_string()))?;
        Editor::new(scene, Some(path.to_path_buf()))
    }

    /// The scene being edited.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// The current motion (with tangents).
    pub fn trajectory(&self) -> &Trajectory {
        &self.traj
    }

    /// The control layout.
    pub fn controls(&self) -> &Controls {
        &self.controls
    }

    /// The constraints (nails, floating, expressions).
    pub fn constraints(&self) -> &[Constraint] {
        &self.constraints
    }

    /// The drag of the last nudge if it was blocked (see [`Edit::Nudge`]
    /// and `crate::explore`): what the user asked for and the gradients
    /// could not reach.
    pub fn pending_drag(&self) -> Option<&Constraint> {
        self.pending_drag.as_ref()
    }

    /// Wall times of all differential updates so far, ms.
    pub fn update_times(&self) -> &[f64] {
        &self.update_ms
    }

    /// Number of differential updates performed so far.
    pub fn updates(&self) -> usize {
        self.updates
    }

    /// Current selection: body and time.
    pub fn selection(&self) -> (usize, f64) {
        (self.selected, self.time)
    }

    fn residual(&self) -> f64 {
        solve::residual_norm(&self.traj, &self.constraints)
    }

    fn snapshot(&self) -> Snapshot {
        Snapshot {
            label: String::new(),
            scene: self.scene.clone(),
            constraints: self.constraints.clone(),
            revision: self.revision,
        }
    }

    /// Rebuild the control layout and the motion after the scene changed.
    fn rebuild(&mut self) -> Result<(), EditError> {
        let controls = Controls::new(&self.scene);
        let traj = simulate_with_tangent(&self.scene, &controls)?;
        if controls.entries.len() != self.last_delta.len() {
            self.last_delta = vec![0.0; controls.entries.len()];
        }
        self.controls = controls;
        self.set_motion(traj);
        self.motion_due = false;
        self.whole_at = None;
        self.refresh_geometry();
        Ok(())
    }

    fn restore(&mut self, s: Snapshot) -> Result<(), EditError> {
        self.scene = s.scene;
        self.constraints = s.constraints;
        self.revision = s.revision;
        self.status.accuracy = self.scene.accuracy.label();
        self.rebuild()
    }

    /// Record a completed change for undo.
    fn commit(&mut self, before: Snapshot, old_values: Vec<f64>) {
        self.undo.push(before);
        self.redo.clear();
        self.revisions += 1;
        self.revision = self.revisions;
        self.last_delta = self.deltas(&old_values);
    }

    /// Change of every control entry since `old_values` (0 where either
    /// is missing, as after a block was freed).
    fn deltas(&self, old_values: &[f64]) -> Vec<f64> {
        (0..self.controls.entries.len())
            .map(|i| self.controls.get(&self.scene, i) - old_values.get(i).copied().unwrap_or(0.0))
            .map(|d| if d.is_finite() { d } else { 0.0 })
            .collect()
    }

    fn values(&self) -> Vec<f64> {
        (0..self.controls.entries.len())
            .map(|i| self.controls.get(&self.scene, i))
            .collect()
    }

    fn refresh_geometry(&mut self) {
        self.paths = paths_of(&self.scene, &self.traj);
        let extent = self.extent();
        self.obstacle_lines = self
            .scene
            .obstacles
            .iter()
            .flat_map(|o| {
                o.geometry.outline(extent).into_iter().map(move |(a, b)| {
                    (
                        (o.pose * Point3::from(a)).coords,
                        (o.pose * Point3::from(b)).coords,
                    )
                })
            })
            .collect();
    }

    /// Half-size of the region the motion covers (for drawing planes).
    fn extent(&self) -> f64 {
        let mut r: f64 = 1.0;
        for p in &self.paths {
            for x in &p.points {
                r = r.max(x.x.abs()).max(x.y.abs());
            }
        }
        1.2 * r
    }

    fn body_lines(&self, i: usize) -> Vec<(Vec3, Vec3)> {
        let s = self.traj.state(i, self.time, Side::Post);
        let iso = Isometry3::from_parts(Translation3::from(s.x), s.q);
        self.scene.bodies[i]
            .geometry
            .outline(1.0)
            .into_iter()
            .map(|(a, b)| {
                (
                    (iso * Point3::from(a)).coords,
                    (iso * Point3::from(b)).coords,
                )
            })
            .collect()
    }

    /// The selected body's events, nearest to the current time first.
    fn nearest_collision(&self) -> Option<(usize, usize)> {
        let events = self.traj.body_events(self.selected);
        events
            .iter()
            .enumerate()
            .min_by(|a, b| {
                (a.1.t - self.time)
                    .abs()
                    .total_cmp(&(b.1.t - self.time).abs())
            })
            .map(|(k, e)| (k, e.index))
    }

    /// One differential update towards `constraints`; applies it when it
    /// lowers the residual. Returns the diagnostics.
    /// `defer`: a nudge's step, whose simulated prefix may stand for the
    /// motion until a pause (`motion`).
    fn step(
        &mut self,
        constraints: &[Constraint],
        defer: bool,
    ) -> Result<(bool, Vec<Diagnostic>, f64), EditError> {
        let start = Instant::now();
        let res = solve::update(
            &self.scene,
            &self.controls,
            &self.traj,
            constraints,
            &UpdateOptions {
                pop: !self.held,
                ..self.opts
            },
        )
        .map_err(|e| invalid(e.to_string()))?;
        let moved = res.trajectory.is_some();
        if let Some(tr) = res.trajectory {
            self.controls.write(&mut self.scene, &res.u);
            // Writing u may reparameterise an orientation (|r| > π); the
            // trial's motion is the same, but its Jacobian columns refer to
            // the old parameters, so simulate afresh in that case.
            let same = self.controls.values(&self.scene) == res.u;
            // The solver simulates only up to its horizon; the editor shows
            // (and the next edit may constrain) the whole motion.
            let whole = tr.duration >= self.scene.duration;
            if tr.tangent && same && whole {
                self.set_motion(tr);
                self.motion_due = false;
                self.whole_at = None;
            } else if same && defer && self.prefix_suffices(&tr) {
                self.keep_prefix(tr);
            } else {
                let _span = crate::profile::span(crate::profile::Part::Resimulate);
                self.set_motion(simulate_with_tangent(&self.scene, &self.controls)?);
                self.motion_due = false;
                self.whole_at = None;
            }
        }
        self.updates += 1;
        self.update_ms.push(start.elapsed().as_secs_f64() * 1e3);
        for d in &res.diagnostics {
            match d {
                Diagnostic::Pop { .. } => self.status.pops += 1,
                Diagnostic::Blocked => self.status.blocks += 1,
                _ => {}
            }
        }
        self.status.step = res.step;
        self.status.update_ms = *self.update_ms.last().unwrap_or(&0.0);
        Ok((moved, res.diagnostics, res.after))
    }

    fn nudge(&mut self, quantity: StateQuantity, delta: Vec3) -> Result<Vec<Note>, EditError> {
        finite3(&delta, "a nudge")?;
        if self.controls.m() == 0 {
            return Err(invalid(format!(
                "no free controls: free a block of {} first (b then p/o/v/w, or :free {} velocity)",
                self.scene.bodies[self.selected].name, self.scene.bodies[self.selected].name
            )));
        }
        let s = self.traj.state(self.selected, self.time, Side::Post);
        let target: Vec3 = match quantity {
            StateQuantity::Position => s.x + delta,
            StateQuantity::Orientation => log_so3(&(exp_so3(&delta) * s.q)),
            StateQuantity::Velocity => s.v + delta,
            StateQuantity::AngularVelocity => s.w + delta,
        };
        let drag = Constraint {
            body: self.selected,
            anchor: Anchor::Time(self.time),
            kind: Kind::State {
                quantities: vec![quantity],
                target: target.iter().cloned().collect(),
            },
            drag: true,
        };
        let mut all = self.constraints.clone();
        all.push(drag.clone());
        let (moved, mut diags, _) = self.step(&all, true)?;
        let fraction = self.status.step;
        let blocked = diags.iter().any(|d| {
            matches!(
                d,
                Diagnostic::Conflicting { .. }
                    | Diagnostic::Blocked
                    | Diagnostic::PartialDrag { .. }
            )
        });
        let blockers = if blocked && !self.constraints.is_empty() {
            self.blocked_by(&all)
        } else {
            Vec::new()
        };
        self.pending_drag = diags
            .iter()
            .any(|d| matches!(d, Diagnostic::Blocked))
            .then_some(drag);
        if self.constraints.is_empty() {
            // Only the drag: nothing conflicts, the controls just cannot
            // follow it all the way.
            for d in &mut diags {
                if let Diagnostic::Conflicting { residual } = *d {
                    *d = Diagnostic::PartialDrag { residual };
                }
            }
        }
        // The drag step satisfies the nails to first order only; a couple of
        // Newton corrections on the persistent constraints alone put them
        // back to tolerance (quadratic convergence), so nails hold.
        if moved && !self.constraints.is_empty() {
            let persistent = self.constraints.clone();
            for _ in 0..2 {
                if self.residual() < 1e-9 {
                    break;
                }
                let (again, d, _) = self.step(&persistent, true)?;
                diags.extend(d);
                if !again {
                    break;
                }
            }
        }
        let mut notes: Vec<Note> = diags.into_iter().map(Note::Solver).collect();
        if moved && fraction < 1.0 - 1e-9 && fraction > 0.0 {
            notes.push(Note::PartialStep { fraction });
        }
        if !blockers.is_empty() {
            notes.push(Note::BlockedBy(blockers));
        }
        Ok(notes)
    }

    /// Write `u` (values of the free controls, in column order) into the
    /// scene and simulate the motion it gives.
    fn set_controls(&mut self, u: &[f64]) -> Result<(), EditError> {
        let m = self.controls.m();
        if u.len() != m {
            return Err(invalid(format!(
                "{} control values given, but the scene has {m} free controls",
                u.len()
            )));
        }
        let (lo, hi) = self.controls.bounds();
        for (k, &v) in u.iter().enumerate() {
            let name = &self.controls.entries[self.controls.free[k]].name;
            if !v.is_finite() {
                return Err(invalid(format!("{name} must be a finite number")));
            }
            if v < lo[k] {
                return Err(invalid(format!(
                    "{name} = {v} is below its least value {}",
                    lo[k]
                )));
            }
            if v > hi[k] {
                return Err(invalid(format!(
                    "{name} = {v} is above its greatest value {}",
                    hi[k]
                )));
            }
        }
        self.controls
            .write(&mut self.scene, &nalgebra::DVector::from_column_slice(u));
        self.set_motion(simulate_with_tangent(&self.scene, &self.controls)?);
        Ok(())
    }

    fn constraint_rows(&self) -> Vec<ConstraintRow> {
        self.constraint_rows_with(&self.position_targets())
    }

    /// The constraint rows, with the gaps of [`Editor::position_targets`]
    /// already computed.
    fn constraint_rows_with(&self, gaps: &[(view::Target, Option<f64>)]) -> Vec<ConstraintRow> {
        self.constraints
            .iter()
            .enumerate()
            .map(|(row, c)| {
                let residual = c
                    .evaluate(&self.traj, false)
                    .map(|(r, _)| r.norm())
                    .unwrap_or(f64::INFINITY);
                let at = match c.anchor {
                    Anchor::Time(t) => format!("t={t:.3}"),
                    Anchor::Event { collision, side } => {
                        format!("hit#{collision} {}", side.word())
                    }
                };
                ConstraintRow {
                    kind: c.label().to_string(),
                    body: self
                        .scene
                        .bodies
                        .get(c.body)
                        .map(|b| b.name.clone())
                        .unwrap_or_default(),
                    at,
                    residual,
                    gap: gaps
                        .iter()
                        .find(|(t, _)| t.row == row)
                        .and_then(|(_, g)| *g),
                }
            })
            .collect()
    }

    /// The edited scene with its constraints, ready to save.
    pub fn scene_to_save(&self) -> Scene {
        let mut s = self.scene.clone();
        s.constraints = self
            .constraints
            .iter()
            .filter(|c| !c.drag)
            .map(|c| to_spec(&self.scene, c))
            .collect();
        s
    }
}
