//! The scene model: bodies, obstacles, effects, accuracy, constraints and
//! event controls, with the kinds parsed once into enums.

use crate::geometry::Geometry;
use crate::math::{Mat3, Vec3};
use nalgebra::{Isometry3, UnitQuaternion};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// A physical effect a scene may call for. Effects not listed are never
/// evaluated by the simulator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Effect {
    /// Uniform gravity `v̇ = g`.
    Gravity,
    /// Linear drag `v̇ += −c v / m`.
    Drag,
    /// The gyroscopic term of Euler's equations for non-isotropic bodies.
    Gyroscopic,
    /// Collision events and impulses (body–obstacle, and the body pairs listed).
    Collisions,
    /// Coulomb friction at impacts.
    Friction,
}

impl Effect {
    /// All effects, in report order.
    pub const ALL: [Effect; 5] = [
        Effect::Gravity,
        Effect::Drag,
        Effect::Gyroscopic,
        Effect::Collisions,
        Effect::Friction,
    ];

    /// The name used in scene files and reports.
    pub fn name(self) -> &'static str {
        match self {
            Effect::Gravity => "gravity",
            Effect::Drag => "drag",
            Effect::Gyroscopic => "gyroscopic",
            Effect::Collisions => "collisions",
            Effect::Friction => "friction",
        }
    }
}

/// Which effects a scene calls for.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Effects {
    pub gravity: bool,
    pub drag: bool,
    pub gyroscopic: bool,
    pub collisions: bool,
    pub friction: bool,
}

impl Effects {
    /// Whether `e` is listed.
    pub fn has(&self, e: Effect) -> bool {
        match e {
            Effect::Gravity => self.gravity,
            Effect::Drag => self.drag,
            Effect::Gyroscopic => self.gyroscopic,
            Effect::Collisions => self.collisions,
            Effect::Friction => self.friction,
        }
    }

    /// Turn `e` on or off.
    pub fn set(&mut self, e: Effect, on: bool) {
        match e {
            Effect::Gravity => self.gravity = on,
            Effect::Drag => self.drag = on,
            Effect::Gyroscopic => self.gyroscopic = on,
            Effect::Collisions => self.collisions = on,
            Effect::Friction => self.friction = on,
        }
    }

    /// The listed effects in report order.
    pub fn listed(&self) -> Vec<Effect> {
        Effect::ALL.into_iter().filter(|e| self.has(*e)).collect()
    }
}

/// Integration method for the rotation of non-isotropic bodies.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Classical fixed-step Runge–Kutta 4 (Munthe-Kaas form on SO(3)), step in s.
    Rk4 { step: f64 },
    /// Dormand–Prince 5(4) with dense output, relative/absolute tolerance and
    /// the largest step it may take (s).
    Adaptive { tol: f64, max_step: f64 },
}

/// Most collision events a motion may have: the simulator stops with an
/// error past it, and an event index in a scene file must be below it.
pub const MAX_EVENTS: usize = 100_000;

/// Most steps a motion may take at the given step (RK4) or largest step
/// (adaptive) (see [`Accuracy::problem`]).
pub const MAX_STEPS: f64 = 1e6;

/// Accuracy settings: the integrator and the collision root tolerance.
/// Tighter settings are more accurate and cost more time (`nudge bench`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Accuracy {
    pub method: Method,
    /// Collision times are refined until the signed distance is below this (m).
    pub root_tol: f64,
}

impl Default for Accuracy {
    fn default() -> Self {
        Accuracy {
            method: Method::Rk4 { step: 1e-3 },
            root_tol: 1e-12,
        }
    }
}

impl Accuracy {
    /// The event-search window and integration step the simulator starts with (s).
    pub fn window(&self) -> f64 {
        match self.method {
            Method::Rk4 { step } => step,
            Method::Adaptive { max_step, .. } => max_step,
        }
    }

    /// What is wrong with these settings for a motion of `duration`
    /// seconds, and how to fix it; `None` if they are usable. A step so
    /// small that the motion takes more than [`MAX_STEPS`] steps would
    /// freeze the editor (and fill memory with steps); tolerances below
    /// 1e-14 are below what f64 can resolve.
    pub fn problem(&self, duration: f64) -> Option<(String, String)> {
        let positive = |v: f64| v.is_finite() && v > 0.0;
        let problem = |what: String, fix: &str| Some((what, fix.to_string()));
        match self.method {
            Method::Rk4 { step } if !positive(step) || step > 1.0 => {
                return problem(
                    format!("the RK4 step {step} s is not > 0 and at most 1 s"),
                    "give a step such as 1e-3",
                );
            }
            Method::Rk4 { step } if duration / step > MAX_STEPS => {
                return problem(
                    format!(
                        "an RK4 step of {step:.1e} s takes {:.1e} steps over the {duration} s motion (at most {MAX_STEPS:.0e})",
                        duration / step
                    ),
                    &format!(
                        "use a step of at least {:.1e} s, or the adaptive integrator",
                        duration / MAX_STEPS
                    ),
                );
            }
            Method::Adaptive { tol, .. } if !(1e-14..1.0).contains(&tol) => {
                return problem(
                    format!("the adaptive tolerance {tol:e} is not in [1e-14, 1)"),
                    "give a tolerance such as 1e-9",
                );
            }
            Method::Adaptive { max_step, .. } if !positive(max_step) => {
                return problem(
                    format!("the largest adaptive step {max_step} s is not > 0"),
                    "give a largest step such as 0.05",
                );
            }
            Method::Adaptive { max_step, .. } if duration / max_step > MAX_STEPS => {
                return problem(
                    format!(
                        "a largest adaptive step of {max_step:.1e} s allows more than {MAX_STEPS:.0e} steps over the {duration} s motion"
                    ),
                    &format!(
                        "use a largest step of at least {:.1e} s: the tolerance, not the largest step, sets the accuracy",
                        duration / MAX_STEPS
                    ),
                );
            }
            _ => {}
        }
        if positive(self.root_tol) && self.root_tol < 1e-3 {
            None
        } else {
            problem(
                format!(
                    "the collision-time tolerance {:e} m is not > 0 and below 1e-3 m",
                    self.root_tol
                ),
                "give a tolerance such as 1e-12",
            )
        }
    }

    /// A short human label, e.g. `rk4 h=1e-3` or `dopri5 tol=1e-9`.
    pub fn label(&self) -> String {
        match self.method {
            Method::Rk4 { step } => format!("rk4 h={step:.0e}"),
            Method::Adaptive { tol, .. } => format!("dopri5 tol={tol:.0e}"),
        }
    }
}

/// A block of the control vector belonging to a body.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Block {
    Position,
    Orientation,
    Velocity,
    AngularVelocity,
    Mass,
    Inertia,
}

impl Block {
    /// All body blocks in control-vector order.
    pub const ALL: [Block; 6] = [
        Block::Position,
        Block::Orientation,
        Block::Velocity,
        Block::AngularVelocity,
        Block::Mass,
        Block::Inertia,
    ];

    /// The name used in scene files and control names.
    pub fn name(self) -> &'static str {
        match self {
            Block::Position => "position",
            Block::Orientation => "orientation",
            Block::Velocity => "velocity",
            Block::AngularVelocity => "angular_velocity",
            Block::Mass => "mass",
            Block::Inertia => "inertia",
        }
    }

    /// Number of entries in the block.
    #[allow(
        clippy::len_without_is_empty,
        reason = "a block always has at least one entry"
    )]
    pub fn len(self) -> usize {
        match self {
            Block::Mass => 1,
            _ => 3,
        }
    }

    /// Parse a block name.
    pub fn parse(s: &str) -> Option<Block> {
        Block::ALL.into_iter().find(|b| b.name() == s)
    }
}

/// A rigid body: geometry in its centre-of-mass frame, physical parameters
/// and its initial state (the control vector is read from and written to
/// these fields).
#[derive(Debug, Clone)]
pub struct Body {
    pub name: String,
    /// Geometry in the body frame, whose origin is the centre of mass.
    pub geometry: Geometry,
    /// What the scene file said about the shape (written back on save).
    pub shape_source: toml::Value,
    /// Centre of mass in the shape's own frame (the file's frame), m.
    pub com_offset: Vec3,
    /// kg.
    pub mass: f64,
    /// Principal moments of inertia, kg·m².
    pub inertia: Vec3,
    /// Principal axes in the body frame.
    pub inertia_axes: UnitQuaternion<f64>,
    /// Whether the file gave the inertia explicitly (saved back if so).
    pub inertia_given: bool,
    /// Initial centre-of-mass position, m.
    pub position: Vec3,
    /// Initial orientation as an exponential-map vector, rad (|r| ≤ π).
    pub orientation: Vec3,
    /// Initial linear velocity, m/s.
    pub velocity: Vec3,
    /// Initial angular velocity (world frame), rad/s.
    pub angular_velocity: Vec3,
    /// Coefficient of restitution in [0, 1].
    pub restitution: f64,
    /// Coulomb friction coefficient ≥ 0 (used only with the `friction` effect).
    pub friction: f64,
    /// Linear drag coefficient `c` ≥ 0, kg/s (used only with the `drag` effect).
    pub drag: f64,
    /// Body-frame points (relative to the centre of mass) whose paths are traced.
    pub traced: Vec<Vec3>,
    /// Which control blocks are free.
    pub free: Vec<Block>,
}

impl Body {
    /// Inertia tensor in the body frame.
    pub fn inertia_tensor(&self) -> Mat3 {
        let q = self.inertia_axes.to_rotation_matrix();
        q.matrix() * Mat3::from_diagonal(&self.inertia) * q.matrix().transpose()
    }

    /// Whether the inertia is isotropic (the gyroscopic term vanishes).
    pub fn isotropic(&self) -> bool {
        let i = self.inertia;
        let max = i.max();
        (i.x - i.y).abs() <= 1e-12 * max && (i.y - i.z).abs() <= 1e-12 * max
    }

    /// Whether `block` is free.
    pub fn is_free(&self, block: Block) -> bool {
        self.free.contains(&block)
    }
}

/// A static obstacle.
#[derive(Debug, Clone)]
pub struct Obstacle {
    pub name: String,
    pub geometry: Geometry,
    pub shape_source: toml::Value,
    /// Pose of the obstacle frame in the world.
    pub pose: Isometry3<f64>,
    /// Coefficient of restitution in [0, 1] (multiplies the body's).
    pub restitution: f64,
    /// Coulomb friction coefficient ≥ 0.
    pub friction: f64,
}

/// Controls attached to the k-th collision event of the motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EventControl {
    /// Global event index (0-based, in time order).
    pub event: usize,
    /// Normal deviation `(a, b)` in the tangent plane of the geometric
    /// normal, when controlled: `n = normalize(n_geom + a t₁ + b t₂)`.
    pub normal: Option<[f64; 2]>,
    /// Restitution used at this event instead of the bodies', when controlled.
    pub restitution: Option<f64>,
    /// The controls keep their values: the solver may not change them (the
    /// surface stays as edited so far while later edits use other controls).
    pub fixed: bool,
}

/// Scales (the diagonal of `M`) per kind of control: larger means "change
/// this less". Favour position over velocity by giving velocity a larger scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scales {
    pub position: f64,
    pub orientation: f64,
    pub velocity: f64,
    pub angular_velocity: f64,
    pub mass: f64,
    pub inertia: f64,
    pub normal: f64,
    pub restitution: f64,
}

/// A kind of control, as far as its scale goes (a field of [`Scales`]);
/// parsed once from the scene file or the command line.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ScaleKind {
    Position,
    Orientation,
    Velocity,
    AngularVelocity,
    Mass,
    Inertia,
    Normal,
    Restitution,
}

impl ScaleKind {
    pub const ALL: [ScaleKind; 8] = [
        ScaleKind::Position,
        ScaleKind::Orientation,
        ScaleKind::Velocity,
        ScaleKind::AngularVelocity,
        ScaleKind::Mass,
        ScaleKind::Inertia,
        ScaleKind::Normal,
        ScaleKind::Restitution,
    ];

    /// The word the scene file and the command line use.
    pub fn name(self) -> &'static str {
        match self {
            ScaleKind::Position => "position",
            ScaleKind::Orientation => "orientation",
            ScaleKind::Velocity => "velocity",
            ScaleKind::AngularVelocity => "angular_velocity",
            ScaleKind::Mass => "mass",
            ScaleKind::Inertia => "inertia",
            ScaleKind::Normal => "normal",
            ScaleKind::Restitution => "restitution",
        }
    }

    /// The kind named `word`, if any.
    pub fn parse(word: &str) -> Option<ScaleKind> {
        ScaleKind::ALL.into_iter().find(|k| k.name() == word)
    }
}

impl Scales {
    /// The scale of `kind`'s controls.
    pub fn get(&self, kind: ScaleKind) -> f64 {
        *self.field(kind)
    }

    /// Set the scale of `kind`'s controls.
    pub fn set(&mut self, kind: ScaleKind, value: f64) {
        *self.field_mut(kind) = value;
    }

    fn field(&self, kind: ScaleKind) -> &f64 {
        match kind {
            ScaleKind::Position => &self.position,
            ScaleKind::Orientation => &self.orientation,
            ScaleKind::Velocity => &self.velocity,
            ScaleKind::AngularVelocity => &self.angular_velocity,
            ScaleKind::Mass => &self.mass,
            ScaleKind::Inertia => &self.inertia,
            ScaleKind::Normal => &self.normal,
            ScaleKind::Restitution => &self.restitution,
        }
    }

    fn field_mut(&mut self, kind: ScaleKind) -> &mut f64 {
        match kind {
            ScaleKind::Position => &mut self.position,
            ScaleKind::Orientation => &mut self.orientation,
            ScaleKind::Velocity => &mut self.velocity,
            ScaleKind::AngularVelocity => &mut self.angular_velocity,
            ScaleKind::Mass => &mut self.mass,
            ScaleKind::Inertia => &mut self.inertia,
            ScaleKind::Normal => &mut self.normal,
            ScaleKind::Restitution => &mut self.restitution,
        }
    }
}

impl Default for Scales {
    fn default() -> Self {
        Scales {
            position: 1.0,
            orientation: 1.0,
            velocity: 1.0,
            angular_velocity: 1.0,
            mass: 1.0,
            inertia: 1.0,
            normal: 1.0,
            restitution: 1.0,
        }
    }
}

impl Scales {
    /// The scale of a body block.
    pub fn of(&self, b: Block) -> f64 {
        match b {
            Block::Position => self.position,
            Block::Orientation => self.orientation,
            Block::Velocity => self.velocity,
            Block::AngularVelocity => self.angular_velocity,
            Block::Mass => self.mass,
            Block::Inertia => self.inertia,
        }
    }
}

/// A quantity of a body's state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StateQuantity {
    Position,
    Orientation,
    Velocity,
    AngularVelocity,
}

impl StateQuantity {
    pub const ALL: [StateQuantity; 4] = [
        StateQuantity::Position,
        StateQuantity::Orientation,
        StateQuantity::Velocity,
        StateQuantity::AngularVelocity,
    ];

    pub fn name(self) -> &'static str {
        match self {
            StateQuantity::Position => "position",
            StateQuantity::Orientation => "orientation",
            StateQuantity::Velocity => "velocity",
            StateQuantity::AngularVelocity => "angular_velocity",
        }
    }

    /// Row offset of the quantity in a body's 12-row tangent.
    pub fn row(self) -> usize {
        match self {
            StateQuantity::Position => 0,
            StateQuantity::Orientation => 3,
            StateQuantity::Velocity => 6,
            StateQuantity::AngularVelocity => 9,
        }
    }
}

/// What a saved constraint holds; parsed once when the scene loads.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ConstraintKind {
    /// State quantities at a fixed time.
    Nail,
    /// State quantities just before or after the body's k-th collision.
    Floating,
    /// The body's speed equals another body's.
    EqualSpeed,
    /// The body's angular speed equals a value.
    AngularSpeed,
    /// The body's up axis points straight up.
    Upright,
    /// The body spins only about the vertical.
    Steady,
    /// A body point lies on a plane.
    PointOnPlane,
    /// Two body points are a given distance apart.
    Distance,
}

impl ConstraintKind {
    pub const ALL: [ConstraintKind; 8] = [
        ConstraintKind::Nail,
        ConstraintKind::Floating,
        ConstraintKind::EqualSpeed,
        ConstraintKind::AngularSpeed,
        ConstraintKind::Upright,
        ConstraintKind::Steady,
        ConstraintKind::PointOnPlane,
        ConstraintKind::Distance,
    ];

    /// The word the scene file uses.
    pub fn name(self) -> &'static str {
        match self {
            ConstraintKind::Nail => "nail",
            ConstraintKind::Floating => "floating",
            ConstraintKind::EqualSpeed => "equal_speed",
            ConstraintKind::AngularSpeed => "angular_speed",
            ConstraintKind::Upright => "upright",
            ConstraintKind::Steady => "steady",
            ConstraintKind::PointOnPlane => "point_on_plane",
            ConstraintKind::Distance => "distance",
        }
    }

    /// How many target numbers the kind takes, and what they are.
    pub fn target_len(self, quantities: usize) -> (usize, &'static str) {
        match self {
            ConstraintKind::Nail | ConstraintKind::Floating => {
                (3 * quantities, "[x, y, z] per held quantity")
            }
            ConstraintKind::EqualSpeed => (0, "none"),
            ConstraintKind::AngularSpeed => (1, "the angular speed in rad/s"),
            ConstraintKind::Upright | ConstraintKind::Steady => (3, "the body axis [x, y, z]"),
            ConstraintKind::PointOnPlane => (
                7,
                "the body point [x, y, z], the plane normal [x, y, z] and its offset",
            ),
            ConstraintKind::Distance => (
                7,
                "the body point [x, y, z], the other body's point [x, y, z] and the distance",
            ),
        }
    }

    /// Whether the kind names a second body (`other`).
    pub fn has_other(self) -> bool {
        matches!(self, ConstraintKind::EqualSpeed | ConstraintKind::Distance)
    }
}

/// Which side of an impulse: a floating constraint's, and a state query's
/// at an event time (the one `Side` of the code: `sim` and `edit` use it).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// Just before the impulse: the limit from before.
    Pre,
    /// Just after the impulse: the limit from after, and the value at any
    /// time that is not an event's.
    Post,
}

impl Side {
    /// The word the scene file and the command line use.
    pub fn word(self) -> &'static str {
        match self {
            Side::Pre => "pre",
            Side::Post => "post",
        }
    }
}

/// A saved constraint (the editing layer turns these into residual rows).
/// Stored as plain data so scenes round-trip through TOML; every field is
/// checked against its kind when the scene loads.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ConstraintSpec {
    pub kind: ConstraintKind,
    /// The body (by name).
    pub body: String,
    /// Second body for two-body expressions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub other: Option<String>,
    /// Fixed time (s) for nails and timed expressions.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time: Option<f64>,
    /// k-th collision of the body (0-based) for floating constraints.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub collision: Option<usize>,
    /// Before or after the impulse, for floating constraints (after when
    /// not given).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub side: Option<Side>,
    /// The constrained quantities of a nail/floating constraint.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub quantities: Vec<StateQuantity>,
    /// Target values: 3 per quantity (orientation as an exp-map vector), or
    /// the expression's parameters.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub target: Vec<f64>,
}

/// A validated scene.
#[derive(Debug, Clone)]
pub struct Scene {
    /// Short name (defaults to the file stem).
    pub name: String,
    /// Free text describing the scene and its intended edit.
    pub notes: String,
    /// Simulated time span, s.
    pub duration: f64,
    /// Gravity vector, m/s² (used only with the `gravity` effect).
    pub gravity: Vec3,
    pub effects: Effects,
    pub accuracy: Accuracy,
    /// A bounce whose separating speed falls below this (m/s) ends with the
    /// body at rest (no Zeno loop).
    pub rest_speed: f64,
    pub bodies: Vec<Body>,
    pub obstacles: Vec<Obstacle>,
    /// Body pairs (indices, `i < j`) that collide with each other.
    pub pairs: Vec<[usize; 2]>,
    pub scales: Scales,
    pub event_controls: Vec<EventControl>,
    pub constraints: Vec<ConstraintSpec>,
    /// The text the scene was loaded from, when it was: saving edits it in
    /// place, so the user's comments and layout survive. `None` for scenes
    /// built in code, which are saved as new text.
    pub source_text: Option<Arc<str>>,
}

impl Scene {
    /// Index of the body with this name.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// The controls of event `k`, if any.
    pub fn event_control(&self, k: usize) -> Option<&EventControl> {
        self.event_controls.iter().find(|c| c.event == k)
    }

    /// Effective gravity (zero when the effect is not listed).
    pub fn effective_gravity(&self) -> Vec3 {
        if self.effects.gravity {
            self.gravity
        } else {
            Vec3::zeros()
        }
    }
}
