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
    /// The time of each point, s.
    pub times: Vec<f64>,
}

/// A collision event as drawn.
#[derive(Debug, Clone, Default, PartialEq)]
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
    /// The touching features in words, e.g. `vertex 3 on plane`.
    pub features: String,
    /// Normal speed of approach before and of separation after, m/s (≥ 0).
    pub approach: f64,
    pub separation: f64,
    /// A micro-contact: the body came to rest, or left slower than the
    /// scene's rest speed (rocking, settling).
    pub micro: bool,
}

impl EventMark {
    /// One line saying what collided, e.g. `event 3 t=0.812: egg1 hit
    /// bucket_b (vertex 3 on plane), 2.31 → 0.92 m/s`.
    pub fn describe(&self) -> String {
        let speed = |v: f64| crate::tui::format_number(v, 3);
        let mut s = format!(
            "event {} t={}: {} hit {} ({}), normal speed {} → {} m/s",
            self.index,
            crate::tui::format_number(self.t, 4),
            self.a,
            self.b,
            self.features,
            speed(self.approach),
            speed(self.separation)
        );
        if self.micro {
            s.push_str(", a resting micro-contact");
        }
        if self.grazing {
            s.push_str(", grazing: no Jacobian from here on, edits sample");
        }
        s
    }
}

/// A collision next to the current time, for the pose readout.
#[derive(Debug, Clone, PartialEq)]
pub struct Neighbour {
    /// Global event index.
    pub index: usize,
    pub t: f64,
    /// The other party's name.
    pub other: String,
}

/// The selected body's state at the current time, for the readout.
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    /// Centre of mass, m.
    pub position: Vec3,
    /// Rotation from the rest orientation: angle (degrees) about a unit axis.
    pub angle_deg: f64,
    pub axis: Vec3,
    /// Angle of the body's up (z) axis from the world vertical, degrees.
    pub tilt_deg: f64,
    /// m/s and rad/s.
    pub velocity: Vec3,
    pub angular_velocity: Vec3,
    /// The body's last collision at or before, and next after, the time.
    pub previous: Option<Neighbour>,
    pub next: Option<Neighbour>,
}

/// How each free control moves the selected body at the current time: the
/// columns of its Jacobian `∂q(t)/∂u`, position and orientation rows.
#[derive(Debug, Clone, PartialEq)]
pub struct Sensitivity {
    pub body: String,
    pub t: f64,
    pub rows: Vec<SensitivityRow>,
}

/// One free control's column.
#[derive(Debug, Clone, PartialEq)]
pub struct SensitivityRow {
    /// The control, e.g. `egg1.velocity.x`.
    pub control: String,
    /// `∂x/∂u` (m per unit of the control) and `∂θ/∂u` (rad per unit, a
    /// world-frame rotation).
    pub position: Vec3,
    pub orientation: Vec3,
}

/// Where a constraint holds its body's position, for drawing.
#[derive(Debug, Clone, PartialEq)]
pub struct Target {
    /// Row in the constraints panel.
    pub row: usize,
    pub body: usize,
    /// World position the constraint holds the body at.
    pub point: Vec3,
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
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ConstraintRow {
    /// `nail`, `floating`, `drag`, or an expression kind.
    pub kind: String,
    pub body: String,
    /// `t=1.250` or `hit#3 post`.
    pub at: String,
    pub residual: f64,
    /// Distance from the body's position to the position the constraint
    /// holds it at (m), for constraints that hold a position.
    pub gap: Option<f64>,
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
    /// Work going on in the pauses (a settle's progress), shown on the
    /// status line before any message.
    pub busy: Option<String>,
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
    /// The paths before the last edit that changed the motion (empty
    /// before the first).
    pub ghost: Vec<Path>,
    /// The selected body at the current time.
    pub pose: Option<Pose>,
    /// Where constraints hold positions.
    pub targets: Vec<Target>,
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
