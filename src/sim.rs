//! The rigid-body simulator with tangent propagation (docs/design.md §3–§5).
//!
//! [`simulate`] integrates the whole motion of a [`Scene`](crate::scene::Scene)
//! for its control layout and returns a [`Trajectory`]: every body's state at
//! any time, every collision [`Event`], evaluation counters per effect and —
//! when asked — the exact Jacobian `J(t) = ∂q(t)/∂u` at any time and event.
//!
//! Only the effects a scene lists are assembled: translation is closed form
//! (gravity and linear drag are linear ODEs), rotation is closed form unless
//! the gyroscopic term is listed and the body is non-isotropic (or its
//! inertia is a free control), and no event search runs without collisions.

mod budget;
mod dynamics;
mod error;
mod events;
mod flight;
mod impulse;
mod integrator;
pub mod island;
mod jet;
mod pivot;
mod rest;
mod roll;
mod run;
mod settle;
mod state;
mod statics;
mod trajectory;

pub use budget::MAX_STORED_VALUES;
pub use dynamics::BodyDynamics;
pub use flight::{Translation, translation};
pub use impulse::{FrictionMode, ImpulseCtx, ImpulseResult};
pub use integrator::{euler_rhs, free_rotation};
pub use pivot::{Pivot, PivotEnd};
pub use rest::Slide;
pub use roll::Roll;
pub use run::{SimError, SimOptions, simulate};
pub use state::{BodyState, Side};
pub use trajectory::{Counters, Event, Party, TangentError, Trajectory};
