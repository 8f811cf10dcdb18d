//! Scenes: the validated in-memory model the simulator consumes
//! ([`Scene`]), and the TOML file format it is loaded from and saved to.
//!
//! Units are SI throughout: metres, seconds, kilograms, radians.

mod format;
mod model;

pub use format::{
    DEFAULT_SCENE, SceneError, load, load_str, mesh_files, save, saved_text, to_toml,
};
pub use model::{
    Accuracy, Block, Body, ConstraintKind, ConstraintSpec, Effect, Effects, EventControl,
    MAX_EVENTS, MAX_STEPS, Method, Obstacle, ScaleKind, Scales, Scene, Side, StateQuantity,
};
