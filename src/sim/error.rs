//! Options of a simulation run and the typed errors that end one.

/// A fixed RK4 step whose body's angular velocity would turn by more than
/// this (rad; `h ·` [`BodyDynamics::precession_rate`]) is split into
/// substeps that turn it by at most this much. RK4 goes unstable near
/// 2.8 rad per step, which used to turn such a body into NaN. RK4's error
/// per step grows as the fifth power of the turn: at 0.1 rad energy and |L|
/// drifted 7e-6 over the 2e4 rad/s tumble of the extreme-parameter needle
/// (tests/hard.rs), at 0.05 rad 2e-7, for twice the steps of such spins only.
pub(super) const SUBSTEP_TURN: f64 = 0.05;
/// More substeps than this per step: [`SimError::SpinTooFast`].
pub(super) const MAX_SUBSTEPS: usize = 10_000;

/// Options of one simulation run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimOptions {
    /// Propagate tangents (compute Jacobians). Off for finite differences.
    pub tangent: bool,
    /// A contact is grazing when `|E_q F| < graze_tol |E_q| |F|`.
    pub graze_tol: f64,
    /// Refuse to go on past this many events.
    pub max_events: usize,
    /// Longest event-search window, s. Right after an impact of
    /// integrated bodies the window is two integration steps, and it
    /// doubles with each window without one.
    pub window: f64,
    /// Stop at this time (s) instead of at the scene's duration; the
    /// trajectory then ends there (`Trajectory::duration`). The solver's
    /// trials stop just past the last constrained time: what happens later
    /// cannot change the residual, and a long settling tail (micro-
    /// collisions on a support) costs more than the whole flight.
    pub until: Option<f64>,
    /// Largest turn of a body's angular velocity within one RK4 substep,
    /// rad: a fast-precessing body takes its step in substeps this fine.
    /// Halving it with the step halves every step (the error estimate).
    pub substep_turn: f64,
}

impl SimOptions {
    /// The default options without tangents: the states alone (trial
    /// simulations, finite differences, error estimates).
    pub fn without_tangents() -> SimOptions {
        SimOptions {
            tangent: false,
            ..SimOptions::default()
        }
    }
}

impl Default for SimOptions {
    fn default() -> Self {
        SimOptions {
            tangent: true,
            graze_tol: 1e-3,
            max_events: crate::scene::MAX_EVENTS,
            window: 0.05,
            until: None,
            substep_turn: SUBSTEP_TURN,
        }
    }
}

/// Why a simulation could not be completed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// A body's state stopped being finite.
    #[error(
        "body \"{body}\" left the finite numbers at t = {t:.6} s; check its mass, inertia and speeds for extreme values"
    )]
    NonFinite { body: String, t: f64 },
    /// More events than the limit.
    #[error(
        "more than {limit} collision events by t = {t:.6} s; shorten the duration or raise rest_speed"
    )]
    TooManyEvents { limit: usize, t: f64 },
    /// Two parties stayed in contact, colliding ever faster, neither coming
    /// to rest nor bounded by micro-collisions (a guard: with a rest speed
    /// slow contacts rest or hop; see `sim::run::islands`).
    #[error(
        "\"{a}\" and \"{b}\" stay in contact from t = {t:.6} s ({count} impacts in {span:.1e} s) without coming to rest; raise rest_speed so micro-collisions bound the impacts, or raise restitution or separate them"
    )]
    SustainedContact {
        a: String,
        b: String,
        t: f64,
        count: usize,
        span: f64,
    },
    /// The contact forces of an island of bodies resting on bodies could
    /// not be solved for: the active-set iterations ran out.
    #[error(
        "the contact forces of the island {bodies} at t = {t:.6} s did not converge in {iterations} iterations (degenerate contacts); move the bodies apart slightly or change their shapes where they touch"
    )]
    IslandUnsolved {
        bodies: String,
        t: f64,
        iterations: usize,
    },
    /// The event search between two parties made no progress (a contact
    /// that neither separates nor approaches faster than the root
    /// tolerance can resolve). Nothing tunnels silently: the run stops.
    /// (Between two bodies such a stall is a sustained contact and is
    /// pushed apart instead, `sim::run::sustained`; this remains for
    /// obstacles and for pairs already separating faster than the floor.)
    #[error(
        "the collision search between \"{a}\" and \"{b}\" stalled at t = {t:.6} s : their contact neither clears nor closes (a sustained contact, or a body spinning much faster than it moves); raise rest_speed so micro-collisions resolve sustained contact, or make extreme principal moments less extreme"
    )]
    EventSearchStalled { a: String, b: String, t: f64 },
    /// A body's angular velocity turns faster than the fixed step can
    /// follow (a near-singular inertia kicked into a fast spin).
    #[error(
        "body \"{body}\" spins so that its angular velocity turns at {rate:.1e} rad/s at t = {t:.6} s, too fast for the rk4 step of {step:.1e} s (steps longer than {limit:.1e} s would need more than 10 000 substeps); make its principal moments less extreme, or use a smaller step or method = \"adaptive\"",
        limit = SUBSTEP_TURN * MAX_SUBSTEPS as f64 / rate
    )]
    SpinTooFast {
        body: String,
        t: f64,
        rate: f64,
        step: f64,
    },
    /// A controlled normal tilted so far from the contact's own normal that
    /// the approaching bodies would separate along it.
    #[error(
        "the controlled normal of event {event} (t = {t:.6} s) is tilted so far that the colliding bodies would separate along it and pass through each other; reduce event{event}.normal or fix that event's controls"
    )]
    NormalAwayFromApproach { event: usize, t: f64 },
    /// A body starts inside an obstacle or a body it collides with (the
    /// solver may step an initial position there; a scene file may not).
    #[error(
        "body \"{body}\" starts {depth:.1e} m inside \"{other}\"; bodies must not overlap what they collide with at t = 0"
    )]
    StartsInside {
        body: String,
        other: String,
        depth: f64,
    },
    /// The stored motion outgrew its memory budget.
    #[error(
        "the motion of \"{body}\" outgrew its {mib} MiB budget by t = {t:.6} s: slow its spin, free fewer controls or loosen the accuracy",
        mib = (super::MAX_STORED_VALUES * 8) >> 20
    )]
    MotionTooLarge { body: String, t: f64 },
    /// The adaptive integrator could not meet the tolerance.
    #[error("the adaptive step fell below 1e-12 s at t = {t:.6} s; loosen the tolerance")]
    StepTooSmall { t: f64 },
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_unsolved_island_names_its_bodies_the_time_and_a_way_out() {
        let e = SimError::IslandUnsolved {
            bodies: "\"box0\", \"box1\"".into(),
            t: 0.25,
            iterations: 34,
        };
        let text = e.to_string();
        for part in [
            "\"box0\", \"box1\"",
            "t = 0.250000 s",
            "34 iterations",
            "move the bodies apart",
        ] {
            assert!(text.contains(part), "{text}");
        }
    }
}
