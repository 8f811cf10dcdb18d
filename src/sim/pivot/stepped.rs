//! Stepped contact: a body chattering on several contacts at once,
//! moved by velocity-level time stepping until the chatter ends
//! (docs/design.md §4).
//!
//! Micro-collisions (`sim::rest`, rule 3) stand in for sustained contact
//! one hop at a time, each hop an event. A hinge, a skid or a lean takes
//! a sustained contact on one line or corner of one obstacle; a body
//! whose contacts are spread over obstacles or features those do not model
//! — scissors with a handle on the floor and a blade riding the edge of a
//! coatrack's base, a blade's edge rolling along that edge at 17 rad/s —
//! chatters on in micro-collisions every 0.1–2 ms, hundreds of events for
//! a quarter of a second of motion. After [`TRAIN`] micro-collisions of a
//! body in a row with no pivot taking them (and unless its supports are
//! all on one obstacle that is a lone half-space, where a slide or a rest
//! takes over), the body is *stepped* instead:
//!
//! - every [`STEP`] its contacts with the static obstacles are found
//!   (`geometry::near_points` within the support band plus twice what the
//!   step can close at each part's, then each point's, own speed), and
//!   one impulse per contact keeps it from closing
//!   (`n · u ≥ (c − d) / h` for a gap `d`, a fifth of a penetration pushed
//!   out per step, `c` the clearance) inside its Coulomb disc
//!   (`|λ_t| ≤ μ λ_n`), solved by projected Gauss–Seidel: a plastic,
//!   frictional contact, the limit the micro-collisions approach without
//!   their hop;
//! - each contact's own second order over the step (its gap after the
//!   drift, by its features, less the linear prediction) is added where it
//!   turns inward, so that no point dips into an obstacle between the
//!   steps (a point turning at `ω` sags by `½ ω² r h²`, some 1e-5 m at
//!   17 rad/s);
//! - between steps the body drifts with the velocities after the
//!   impulses (gravity added at the start of the step; with the
//!   gyroscopic effect the spin follows the angular momentum as the
//!   inertia turns, at the rotational energy it had);
//! - the stepping ends
//!   - **rests** when every point of the body moves slower than the rest
//!     speed and its supports hold it (`sim::statics`, as rule 1);
//!   - **lands** when a contact not yet touching closes so fast that its
//!     bounce would leave the support band: the body drifts to that
//!     contact, where an ordinary impact takes over;
//!   - **lifts off** after [`QUIET`] steps with no contact force: free
//!     flight, searched as usual;
//!   - or when the simulation ends.
//!
//! At every end the body is first moved out of any penetration, so the
//! event search resumes from a state clear of every obstacle.
//!
//! The motion is stored as the state at the start of each step with the
//! velocities it drifts with; positions are continuous, velocities jump at
//! the steps. It is first order in `h`: a stand-in for a chatter, not the
//! exact flight between impacts. The body's Jacobian is lost from the
//! first step on (`TangentError::Contact`), as in a pivot. Only a body
//! alone in its scene is stepped: the steps are found against the static
//! obstacles only, and another body's search against this motion would
//! need bounds that its velocity jumps do not have.

mod contacts;
mod impulses;
#[cfg(test)]
mod tests;

use super::{Motion, Pivot, PivotEnd};
use crate::math::{Vec3, exp_so3, plane_basis};
use crate::scene::Scene;
use crate::sim::dynamics::BodyDynamics;
use crate::sim::rest;
use crate::sim::state::BodyState;
use crate::sim::statics::{self, Support};
pub(crate) use contacts::supported;
use contacts::{Margin, Touch, follow, touches};
use impulses::{Impulses, Solve, inertia, inverse_inertia};

/// The time step, s.
pub const STEP: f64 = 2e-3;

/// Micro-collisions of a body in a row after which it is stepped.
pub const TRAIN: usize = 2;

/// Steps in a row without any contact force after which the body flies.
pub const QUIET: usize = 2;

/// Fraction of a penetration pushed out per step.
const PUSH: f64 = 0.2;

/// The least gap contacts are held at, as a fraction of the body's reach.
const CLEARANCE: f64 = 1e-6;

/// Everything [`Pivot::enter_stepped`] needs.
pub(crate) struct SteppedStart<'a> {
    pub scene: &'a Scene,
    pub dynamics: &'a BodyDynamics,
    pub gravity: Vec3,
    pub body: usize,
    /// The state the stepping starts from (after the impact's impulse).
    pub post: BodyState,
    /// Longest the stepping may last, s.
    pub horizon: f64,
    /// The body's rest speed and support band (`rest::thresholds`).
    pub v_rest: f64,
    pub band: f64,
    /// The obstacle and part struck by the impact that starts it.
    pub obstacle: usize,
    pub part: usize,
}

/// A stepped motion (see the module notes).
#[derive(Debug, Clone, PartialEq)]
pub struct Stepped {
    /// The state at the start of each step, with the velocities the body
    /// drifts with through it; the last is the state at the end.
    table: Vec<BodyState>,
}

impl Stepped {
    /// The state `tau` seconds in.
    pub(super) fn at(&self, tau: f64) -> BodyState {
        let k = ((tau.max(0.0) / STEP).floor() as usize).min(self.table.len() - 1);
        drift(&self.table[k], tau - k as f64 * STEP)
    }
}

/// `s` moved on for `dt` with its velocities held.
fn drift(s: &BodyState, dt: f64) -> BodyState {
    if dt <= 0.0 {
        return *s;
    }
    BodyState {
        x: s.x + s.v * dt,
        q: exp_so3(&(s.w * dt)) * s.q,
        ..*s
    }
}

/// `s` moved out of every obstacle it sinks into: frictionless
/// position corrections along the contact normals, least in the mass
/// metric (the velocity solve over a unit step, pushing fully out).
fn clear(p: &SteppedStart<'_>, s: &BodyState) -> BodyState {
    let d = p.dynamics;
    let mut s = *s;
    let skin = 1e-12 * (1.0 + d.reach);
    for _ in 0..8 {
        let deep: Vec<Touch> = touches(p, &s, &Margin::band(p.band))
            .into_iter()
            .filter(|t| t.distance < 0.0)
            .map(|t| Touch {
                friction: 0.0,
                distance: t.distance - skin,
                ..t
            })
            .collect();
        if deep.is_empty() {
            break;
        }
        let solve = Solve {
            dynamics: d,
            i_inv: inverse_inertia(d, &s),
            h: 1.0,
            push: 1.0,
            clearance: 0.0,
            tol: 1e-15,
        };
        let (dx, dq, _) = solve.run(&deep, Vec3::zeros(), Vec3::zeros(), None);
        s.x += dx;
        s.q = exp_so3(&dq) * s.q;
    }
    s
}

impl Pivot {
    /// The stepped motion an impact starts (see the module notes), with
    /// the state it starts from; `None` when the first step already
    /// lands, a step leaves the finite numbers, or the scene is not one
    /// it steps.
    pub(crate) fn enter_stepped(p: &SteppedStart<'_>) -> Option<(Pivot, BodyState)> {
        let (d, g) = (p.dynamics, p.gravity);
        if g.norm() == 0.0 || d.drag_k.is_some() || !supported(p.scene, p.body) {
            return None;
        }
        let gyro = p.scene.effects.gyroscopic && d.integrate;
        // Sweeps stop once a sweep changes no point's velocity by more
        // than 1e-4 of the rest speed.
        let tol = 1e-4 * d.mass * p.v_rest;
        let down = g.normalize();
        // A contact struck faster than this bounces out of the support
        // band: an impact, not part of the chatter.
        let bounce = (2.0 * g.norm() * p.band).sqrt().max(p.v_rest);
        let mut s = p.post;
        let mut table: Vec<BodyState> = Vec::new();
        let mut quiet = 0;
        let mut last: Vec<([usize; 5], Vec3)> = Vec::new();
        let mut end = PivotEnd::Duration;
        // The contact struck, its point in the body frame, and the state
        // that touches it.
        let mut landing: Option<(Touch, Vec3, BodyState)> = None;
        let mut duration = p.horizon;
        let (mut v_max, mut w_max, mut accel_max) = (0.0_f64, 0.0_f64, 0.0_f64);
        let steps = (p.horizon / STEP).ceil().min(1e7) as usize;
        for k in 0..steps {
            let t0 = k as f64 * STEP;
            let h = STEP.min(p.horizon - t0);
            if h <= 0.0 {
                break;
            }
            let v_free = s.v + g * h;
            // Within the support band, plus twice what the step can close.
            let margin = Margin {
                band: p.band,
                ahead: 2.0 * h,
                v: v_free,
                w: s.w,
            };
            // Contacts are held this far off (more than the third-order
            // error of a step's drift, `|ω|³ r h³`), so no point of the
            // body dips into an obstacle between the steps.
            let clearance = CLEARANCE * d.reach + (s.w.norm() * h).powi(3) * d.reach;
            let mut found = touches(p, &s, &margin);
            let solve = Solve {
                dynamics: d,
                i_inv: inverse_inertia(d, &s),
                h,
                push: PUSH,
                clearance,
                tol,
            };
            // Each contact's turn over the step is taken at the free
            // velocities, then again at the solved ones.
            follow(&mut found, &s, v_free, s.w, h);
            // Started from the last step's impulses at the same contacts.
            let warm = Impulses::warm(&found, &last);
            let (mut v1, mut w1, mut impulses) = solve.run(&found, v_free, s.w, Some(&warm));
            // Where the impulses turn the body enough to change a contact's
            // own turn so that it would end below half the clearance, once
            // more with the turns at the solved velocities.
            follow(&mut found, &s, v1, w1, h);
            let short = found.iter().any(|t| {
                let end = t.distance + h * t.normal.dot(&(v1 + w1.cross(&t.r))) + t.turn;
                end < 0.5 * clearance
            });
            if short {
                (v1, w1, impulses) = solve.run(&found, v_free, s.w, Some(&impulses));
            }
            last = impulses.keyed(&found);
            let normal = impulses.normal;
            // A contact not yet touching that this step closes fast enough
            // to bounce off visibly: the body drifts to it, without it.
            let striking: Vec<usize> = (0..found.len())
                .filter(|&i| {
                    let t = &found[i];
                    let u = -t.normal.dot(&(v_free + s.w.cross(&t.r)));
                    normal[i] > 0.0 && t.distance > p.band && t.restitution * u > bounce
                })
                .collect();
            if !striking.is_empty() {
                let rest: Vec<Touch> = (0..found.len())
                    .filter(|i| !striking.contains(i))
                    .map(|i| found[i])
                    .collect();
                let (v2, w2, _) = solve.run(&rest, v_free, s.w, None);
                let moving = BodyState { v: v2, w: w2, ..s };
                // The first of them to close under that motion.
                let first = striking
                    .iter()
                    .filter_map(|&i| {
                        let t = found[i];
                        let u = -t.normal.dot(&(v2 + w2.cross(&t.r)));
                        (u > 0.0 && t.distance < u * h).then(|| {
                            let body_point = s.q.inverse() * t.r;
                            let gap = |dt: f64| t.gap_at(&s, &drift(&moving, dt));
                            let (mut lo, mut hi) = (0.0, h);
                            if gap(hi) > 0.0 {
                                return (h, t, body_point);
                            }
                            for _ in 0..60 {
                                let mid = 0.5 * (lo + hi);
                                if gap(mid) > 0.0 {
                                    lo = mid;
                                } else {
                                    hi = mid;
                                }
                            }
                            (lo, t, body_point)
                        })
                    })
                    .min_by(|a, b| a.0.total_cmp(&b.0));
                if let Some((dt, t, body_point)) = first {
                    v_max = v_max.max(v2.norm());
                    w_max = w_max.max(w2.norm());
                    table.push(moving);
                    duration = t0 + dt;
                    end = PivotEnd::Lands;
                    landing = Some((t, body_point, drift(&moving, dt)));
                    break;
                }
            }
            let now = BodyState { v: v1, w: w1, ..s };
            // A step that leaves the finite numbers (a degenerate contact
            // geometry) gives no stepped motion: the impact stays a
            // micro-collision.
            if !now.is_finite() {
                return None;
            }
            v_max = v_max.max(v1.norm());
            w_max = w_max.max(w1.norm());
            accel_max = accel_max.max((v1 - s.v).norm() / h);
            // Rest: every point slow, and the supports hold the body.
            if rest::slower_than(p.scene, p.body, &now, p.v_rest) {
                let supports: Vec<Support> = found
                    .iter()
                    .filter(|t| t.distance <= p.band)
                    .map(|t| Support {
                        point: s.x + t.r,
                        normal: t.normal,
                        friction: t.friction,
                    })
                    .collect();
                if statics::held(&supports, &s.x, &down, d.reach) {
                    table.push(BodyState {
                        v: Vec3::zeros(),
                        w: Vec3::zeros(),
                        ..s
                    });
                    duration = t0;
                    end = PivotEnd::Rests;
                    break;
                }
            }
            quiet = if normal.iter().all(|&f| f == 0.0) {
                quiet + 1
            } else {
                0
            };
            if quiet >= QUIET && found.iter().all(|t| t.distance >= 0.0) {
                table.push(s);
                duration = t0;
                end = PivotEnd::LiftsOff;
                break;
            }
            table.push(now);
            // Drift through the step; the spin follows the momentum.
            let momentum = inertia(d, &s) * w1;
            let mut next = drift(&now, h);
            if gyro {
                // Along the momentum at the new attitude, with the
                // rotational energy it had (free rotation keeps both; the
                // step's first-order turn would change the energy).
                let w = inverse_inertia(d, &next) * momentum;
                let (before, after) = (w1.dot(&momentum), w.dot(&momentum));
                next.w = if after > 0.0 {
                    w * (before / after).sqrt()
                } else {
                    w
                };
            }
            s = next;
        }
        if end == PivotEnd::Duration {
            table.push(s);
            duration = p.horizon;
        }
        // At a landing within the first step the impact is just that.
        if table.len() <= 1 && end == PivotEnd::Lands {
            return None;
        }
        // Out of any penetration at the end (a landing drifts there from
        // the last entry, which moves with it).
        let last = table.len() - 1;
        let end_state = landing.as_ref().map_or(table[last], |(.., at)| *at);
        let cleared = clear(p, &end_state);
        if !cleared.is_finite() {
            return None;
        }
        let shift = cleared.x - end_state.x;
        // (A turn in the body frame, so that the drift ends on it.)
        let turn = end_state.q.inverse() * cleared.q;
        table[last].x += shift;
        table[last].q *= turn;
        let (point, normal, obstacle, part, landing_at) = match landing {
            Some((t, body_point, _)) => (
                cleared.point(&body_point),
                t.normal,
                t.obstacle,
                t.part_b,
                Some((t.part_a, body_point)),
            ),
            None => (p.post.x, -down, p.obstacle, p.part, None),
        };
        let stepped = Stepped { table };
        let start = stepped.at(0.0);
        let pv = Pivot {
            obstacle,
            part,
            point,
            axis: plane_basis(&normal).0,
            normal,
            length: 0.0,
            motion: Motion::Stepped(Box::new(stepped)),
            duration,
            end,
            landing: landing_at,
            lean: None,
            lands_on_lean: false,
            beside: false,
            v_max,
            w_max,
            alpha_max: 0.0,
            accel_max,
        };
        Some((pv, start))
    }
}
