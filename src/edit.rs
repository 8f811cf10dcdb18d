//! Editing: every user intent is an [`Edit`], applied atomically through
//! [`Core::apply`]. The TUI and the headless runner both drive the same core.

mod editor;
mod note;

pub use editor::{Editor, MAX_SETTLE_UPDATES, paths_of};
pub use note::{BlockedBy, Note};

pub use crate::files::WriteMode;
use crate::math::Vec3;
use crate::scene::{Accuracy, Block, ScaleKind, StateQuantity};
use crate::view::View;
use std::path::{Path, PathBuf};

pub use crate::scene::Side;

/// What a constraint about the world vertical holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Vertical {
    /// The body's z axis (its shape frame's) points straight up.
    Upright,
    /// The body spins only about the vertical: no tumbling, so a body that
    /// stands upright stays so.
    Steady,
}

impl Vertical {
    /// The word the command line, the panels and the saved file use.
    pub fn word(self) -> &'static str {
        match self {
            Vertical::Upright => "upright",
            Vertical::Steady => "steady",
        }
    }
}

/// An expression constraint (paper §4.2).
#[derive(Debug, Clone, PartialEq)]
pub enum Expression {
    /// `|v_a| − |v_b| = 0` at the current time.
    EqualSpeed { other: usize },
    /// `|ω| = value` (rad/s) at the current time.
    AngularSpeed { value: f64 },
    /// The body-frame `point` lies on the world plane `n · p = offset`.
    PointOnPlane {
        point: Vec3,
        normal: Vec3,
        offset: f64,
    },
    /// `|p_a − p_b| = value` between body-frame points of two bodies.
    Distance {
        other: usize,
        point: Vec3,
        other_point: Vec3,
        value: f64,
    },
}

/// One user intent.
#[derive(Debug, Clone, PartialEq)]
pub enum Edit {
    /// Select a body by index.
    SelectBody(usize),
    /// Move the current time to `t` (s), clamped to the scene duration.
    SelectTime(f64),
    /// Move the current time to the k-th collision event (global index).
    SelectEvent(usize),
    /// Drag the selected body's `quantity` at the current time by `delta`
    /// (world frame; for orientation a rotation vector), keeping every
    /// constraint in place.
    Nudge {
        quantity: StateQuantity,
        delta: Vec3,
    },
    /// Nail the selected body's quantities at the current time: to their
    /// current values, or to the values in `exact` (world frame; an
    /// orientation as an exponential-map vector) for the quantities listed
    /// there. No quantities: all four.
    Nail {
        quantities: Vec<StateQuantity>,
        exact: Vec<(StateQuantity, Vec3)>,
    },
    /// A floating constraint on the selected body's quantities at its
    /// collision nearest the current time (values as for [`Edit::Nail`]).
    Float {
        quantities: Vec<StateQuantity>,
        exact: Vec<(StateQuantity, Vec3)>,
        /// Before or after the impulse; `None`: before if the collision is
        /// still ahead of the current time, else after.
        side: Option<Side>,
    },
    /// An expression constraint on the selected body at the current time.
    Expression(Expression),
    /// A constraint about the vertical on the selected body ([`Vertical`]):
    /// at the current time (`side: None`), or just before or after its
    /// collision nearest the current time (a floating constraint).
    Vertical { goal: Vertical, side: Option<Side> },
    /// Remove the constraint with this index (in the constraints panel order).
    RemoveConstraint(usize),
    /// Stop holding these quantities in the nail or floating constraint
    /// with this index (removing it when none is left).
    Release {
        row: usize,
        quantities: Vec<StateQuantity>,
    },
    /// Free or fix a control block of a body.
    SetBlock {
        body: usize,
        block: Block,
        free: bool,
    },
    /// Add normal and/or restitution controls at the event nearest the current time.
    AddEventControls { normal: bool, restitution: bool },
    /// Free or fix the controls of one event (`None`: the selected body's
    /// collision nearest the current time); `free: None` toggles them.
    SetEventControls {
        event: Option<usize>,
        free: Option<bool>,
    },
    /// Change the scale (diagonal of M) of a kind of control: a block name,
    /// `normal` or `restitution`.
    SetScale { kind: ScaleKind, value: f64 },
    /// Change the accuracy settings.
    SetAccuracy(Accuracy),
    /// Set the free controls (the control vector `u`, in the order of
    /// `Controls::free`) to these values at once, e.g. an alternative that
    /// exploring found (`crate::explore`); undoable like any edit.
    SetControls(Vec<f64>),
    /// Iterate updates until the constraints are met or progress stalls,
    /// within `budget_ms` of wall time.
    Settle { budget_ms: u64 },
    /// Undo the last edit that changed the motion or the constraints.
    Undo,
    /// Redo the last undone edit.
    Redo,
}

/// What an applied edit did, for the status line.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Outcome {
    /// Number of differential updates performed.
    pub updates: usize,
    /// Wall time spent, ms.
    pub elapsed_ms: f64,
    /// What it has to say (conflicts, pops, blocks, grazing, ...).
    pub notes: Vec<Note>,
    /// Where a new constraint or event control was anchored.
    pub anchored: Option<Anchored>,
    /// For undo and redo: what the undone or redone edit was.
    pub reverted: Option<String>,
}

/// Where an edit took effect.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Anchored {
    /// At this time, s.
    Time(f64),
    /// At the selected body's `collision`-th collision (global `event`),
    /// on this side of it.
    Collision {
        collision: usize,
        event: usize,
        side: Side,
    },
}

/// Why an edit was refused. The core's state is unchanged.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum EditError {
    #[error("{0}")]
    Invalid(String),
    #[error("could not save: {0}")]
    Save(String),
    /// The file to save to is read-only.
    #[error("{} is read-only: :w! writes it anyway", .0.display())]
    ReadOnly(PathBuf),
    /// The path to save to names a directory, FIFO, socket or device,
    /// which a save never replaces.
    #[error("could not save: {} is {kind}, not a file: give a file, e.g. :w {suggest}", path.display())]
    NotRegular {
        path: PathBuf,
        /// What it is, e.g. "a directory".
        kind: &'static str,
        /// A file name to offer instead.
        suggest: String,
    },
    /// A new constraint's target is so far from the motion that the
    /// distance to it is not a finite number.
    #[error("target too far away to measure: give values within about 1e150 of the body")]
    TargetOutOfRange,
    /// The whole motion after nudges whose prefix was shown could not be
    /// simulated: those nudges were taken back.
    #[error(
        "the motion after the last {nudges} nudge(s) could not be simulated, so they were taken back: {why}"
    )]
    MotionRefused { nudges: usize, why: String },
}

/// Where a scene was saved.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Saved {
    pub path: PathBuf,
    /// Set when the text the scene was loaded from could not be edited in
    /// place and the scene was written as new text: why (its comments and
    /// layout are gone, every number is there).
    pub layout_lost: Option<String>,
}

/// The editing core as the user interfaces see it.
pub trait Core {
    /// Apply one edit atomically: on error nothing changes.
    fn apply(&mut self, edit: Edit) -> Result<Outcome, EditError>;
    /// A snapshot of everything the screen shows.
    fn view(&self) -> View;
    /// Save the edited scene (to `path`, or where it was loaded from); a
    /// read-only file only with [`WriteMode::Force`].
    fn save(&mut self, path: Option<&Path>, mode: WriteMode) -> Result<Saved, EditError>;
    /// Whether there are unsaved edits.
    fn dirty(&self) -> bool;
    /// The JSON report (`nudge check --json` shape plus constraints).
    fn report(&self) -> serde_json::Value;
    /// How each free control moves the selected body at the current time
    /// (the Jacobian's position and orientation rows), or why it cannot
    /// be said.
    fn sensitivity(&self) -> Result<crate::view::Sensitivity, String> {
        Err("this core computes no Jacobians".into())
    }
    /// Write the motion as binary glTF to `path` at `fps` keys per second
    /// (and at every collision). Returns the bytes written.
    fn export_gltf(&self, _path: &Path, _fps: f64) -> Result<usize, EditError> {
        Err(EditError::Invalid("this core cannot export".into()))
    }
    /// Where exploring starts from (the scene, its controls, constraints
    /// and a blocked drag's goal), if this core can explore.
    fn explore_start(&self) -> Option<crate::explore::Start> {
        None
    }
    /// Work deferred from the last edits (the rest of a nudged motion,
    /// then its integration error estimate), done while the user pauses:
    /// one piece per call, so call it again while no key is waiting.
    /// Returns whether it did anything (the view may have changed).
    fn idle(&mut self) -> bool {
        false
    }
    /// Stop the work going on in the pauses (a settle) where it is; what
    /// was stopped, if anything.
    fn stop(&mut self) -> Option<String> {
        None
    }
}
