//! Collision detection between steps: a broad phase over each window, then
//! conservative advancement per candidate pair (no tunnelling: the time
//! step is bounded by distance / maximum approach speed, or, far longer, by
//! the time any vertex needs to cross a plane separating two parts: fixed
//! in the contact normal's direction, turning with two crossing edges, or
//! carried with the moving body's face),
//! Newton probes to bracket the root early, and a safeguarded
//! Newton–bisection refinement of the time of impact to the root tolerance.

use super::trajectory::{Party, Trajectory};
use crate::geometry::Placement;
use crate::scene::Scene;

/// A pair that may collide, and whether its event is armed (a pair is
/// disarmed right after its impulse until it separates by `arm`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Pair {
    pub a: usize,
    pub b: Party,
    pub armed: bool,
    /// The search for this pair starts no earlier than this time (a contact
    /// found not to be approaching is skipped past).
    pub hold: f64,
    /// Contacts of this pair skipped in a row as not approaching, with no
    /// impulse in between, and the time of the first of them (see
    /// [`MAX_SKIPS`]).
    pub skips: usize,
    pub skipped_since: f64,
    /// The search of this pair crawled in a sustained contact and its next
    /// impact is a *push* (`sim::run::sustained`).
    pub push: bool,
}

/// A search that steps this many times in a row inside the contact band
/// without the contact approaching is creeping in a sustained contact: the
/// gap neither closes nor clears faster than the certified steps (a gap of
/// picometres over a speed bound of metres per second) can follow. With a
/// micro-collision floor the search stops there and the contact is pushed
/// apart (`sim::run::sustained`), instead of running the whole iteration
/// budget (10,000 steps, tens of milliseconds) first.
pub(crate) const CREEP_STEPS: usize = 64;

/// A pair whose contact is skipped as "not approaching" this many times in
/// a row within [`SKIP_SPAN`] is stuck: the search and the impulse model
/// disagree about a contact that neither separates nor closes (a
/// penetrating point that the contact features do not see approach), and
/// skipping it 1e-10 s at a time would take forever. The run stops with
/// [`super::SimError::EventSearchStalled`] instead.
pub(crate) const MAX_SKIPS: usize = 1000;

/// See [`MAX_SKIPS`], s.
pub(crate) const SKIP_SPAN: f64 = 1e-6;

/// Tolerances of the event search.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tolerances {
    /// Refine until `|E| ≤ root` (m).
    pub root: f64,
    /// Re-arm distance and skin of disarmed pairs (m).
    pub arm: f64,
}

/// Read-only view of the world at any time during the simulation.
pub(crate) struct World<'a, 'g> {
    pub scene: &'a Scene,
    pub traj: &'a Trajectory,
    /// Every obstacle placed for contact queries (they never move).
    pub obstacles: &'a [Placement<'g>],
}

/// A part's points' heights, rates and acceleration bounds over a plane
/// (on the stack for parts of up to 16 points).
mod bounds;
mod planes;
mod search;
mod sinking;
