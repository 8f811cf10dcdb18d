//! The render model: a plain-data snapshot of everything the screen (or a
//! headless report) shows. The editor core fills it; the TUI only draws it.
//! Rendering never runs the simulator (docs/design.md §9).

use crate::math::Vec3;

/// A traced point's whole path, in world coordinates, in time order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Path {
    /// Index of the body the traced point belongs to.
    pub body: usize,
    /// World positions at increasing times.
    pub points: Vec<Vec3>,
}

/// A collision event as drawn.
#[derive(Debug, Clone, PartialEq)]
pub struct EventMark {
    /// Global event index.
    pub index: usize,
    /// Time, s.
    pub t: f64,
    /// World contact point.
    pub point: Vec3,
    /// Names of the two parties, e.g. `egg1` and `ground`.
    pub a: String,
    pub b: String,
    /// Whether the event was flagged grazing.
    pub grazing: bool,
}

/// One row of the control-vector panel.
#[derive(Debug, Clone, PartialEq)]
pub struct ControlRow {
    /// e.g. `egg1.velocity.x`.
    pub name: String,
    pub value: f64,
    /// Change made by the last edit.
    pub delta: f64,
    pub free: bool,
    pub scale: f64,
}

/// One row of the constraints panel.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintRow {
    /// `nail`, `floating`, `drag`, or an expression kind.
    pub kind: String,
    pub body: String,
    /// `t=1.250` or `hit#3 post`.
    pub at: String,
    pub residual: f64,
}

/// The status line's contents.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Status {
    /// Wall time of the last differential update, ms.
    pub update_ms: f64,
    /// Weighted residual of all constraints after the last update.
    pub residual: f64,
    /// Step size ε accepted by the last update.
    pub step: f64,
    /// Signature changes accepted (pops) and refused (blocks) so far.
    pub pops: usize,
    pub blocks: usize,
    /// Accuracy setting label, e.g. `rk4 h=1e-3`.
    pub accuracy: String,
    /// The latest diagnostic or error, if any.
    pub message: Option<String>,
    /// The motion's estimated integration error (position m, orientation
    /// rad, velocity m/s, angular velocity rad/s; see `estimate`), if it
    /// could be estimated.
    pub integration_error: Option<[f64; 4]>,
}

/// Everything the screen shows, as plain data.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct View {
    pub scene: String,
    /// The scene's one-line description of the motion and its edit.
    pub notes: String,
    pub duration: f64,
    /// Current (selected) time, s.
    pub time: f64,
    /// Body names, in scene order.
    pub bodies: Vec<String>,
    /// Index of the selected body.
    pub selected: usize,
    /// Every traced point's path.
    pub paths: Vec<Path>,
    /// Obstacle outlines as world-space segments.
    pub obstacles: Vec<(Vec3, Vec3)>,
    /// The selected body's outline at the current time, world space.
    pub selected_outline: Vec<(Vec3, Vec3)>,
    /// Outlines of the other bodies at the current time.
    pub body_outlines: Vec<(Vec3, Vec3)>,
    /// Collision events.
    pub events: Vec<EventMark>,
    pub controls: Vec<ControlRow>,
    pub constraints: Vec<ConstraintRow>,
    pub status: Status,
    /// Whether there are edits not yet saved.
    pub dirty: bool,
    /// The accuracy settings in force (the status line shows their label).
    pub accuracy: crate::scene::Accuracy,
}
