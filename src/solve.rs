//! Constraints and the differential update (paper §4.1–4.2, §5; docs/design.md §6–§7).
//!
//! Each [`Constraint`] yields residual rows `r` (the change wanted) and
//! Jacobian rows `C = ∂g/∂q · J`. [`update`] solves
//! `min ½ δuᵀ M δu + dᵀ δu  s.t.  C δu = r` through the small system
//! `C M⁻¹ Cᵀ λ = r + C M⁻¹ d` (a rank-revealing eigendecomposition with
//! faer, so duplicate constraints converge and conflicting ones give the
//! least-squares step), then steps `u ← u + ε δu` with successive step
//! reduction, and samples around `δu` when the step would change the
//! motion's collision signature.

mod constraint;
mod explain;
mod update;

pub use constraint::{Anchor, Constraint, ConstraintError, Kind};
pub use explain::{Blocker, blockers};
pub(crate) use update::causal_events;
pub use update::{Diagnostic, SolveError, UpdateOptions, UpdateResult, kkt, residual_norm, update};
