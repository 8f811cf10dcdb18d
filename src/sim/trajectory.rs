//! The simulated motion: per-body segments between impulses, collision
//! events, and queries of the state and the Jacobian at any time.

use super::dynamics::BodyDynamics;
use super::flight::translation;
use super::impulse::FrictionMode;
use super::integrator::{Step, body_rate, tangent_block};
use super::pivot::Pivot;
use super::rest::Slide;
use super::state::{BodyState, Side};
use crate::geometry::FeaturePair;
use crate::math::{Mat3, Vec3, exp_so3, left_jacobian, skew};
use nalgebra::{DMatrix, DVector};
use std::cell::Cell;

/// The other party of a collision.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Party {
    Body(usize),
    Obstacle(usize),
}

/// A stretch of one body's motion between impulses (or at rest).
#[derive(Debug, Clone)]
pub struct Segment {
    /// Start time, s.
    pub t0: f64,
    /// State at `t0` (post-impulse when the segment starts at an event).
    pub start: BodyState,
    /// Jacobian at `t0` (12 × m; 12 × 0 without tangents).
    pub j0: DMatrix<f64>,
    /// The body rests from `t0` on.
    pub rest: bool,
    /// The body slides on a static plane from `t0` on (closed form, see
    /// [`Slide`]).
    pub slide: Option<Slide>,
    /// The body pivots on a line of support from `t0` on (see [`Pivot`]).
    pub pivot: Option<std::sync::Arc<Pivot>>,
    /// Integration steps (bodies whose rotation is integrated).
    pub steps: Vec<Step>,
}

/// One body's whole motion.
#[derive(Debug, Clone, Default)]
pub struct Track {
    pub segments: Vec<Segment>,
}

/// A collision event.
#[derive(Debug, Clone)]
pub struct Event {
    /// Global index in time order.
    pub index: usize,
    /// Time of impact, s.
    pub t: f64,
    /// The body (first party).
    pub a: usize,
    /// The other party.
    pub b: Party,
    /// The touching features.
    pub feature: FeaturePair,
    /// Signature key of the features, e.g. `0:v3/0:plane`.
    pub key: String,
    /// Normal used for the impulse (from b towards a).
    pub normal: Vec3,
    /// Contact point, world.
    pub point: Vec3,
    /// Relative normal velocity before (negative) and after the impulse, m/s.
    pub approach: f64,
    pub separation: f64,
    /// Restitution used.
    pub restitution: f64,
    /// `|E_q F⁻| / (|E_q| |F⁻|)`: small means a grazing contact.
    pub graze_ratio: f64,
    /// Flagged grazing: the event-time derivative is unbounded.
    pub grazing: bool,
    /// Number of vertices touching at once (1 for an ordinary contact).
    pub simultaneous: usize,
    /// The body came to rest at this event (separating speed below the
    /// scene's rest speed); `rest_time` is when the Zeno series of ever
    /// smaller bounces would have ended.
    pub rest: bool,
    /// From this event the body slides on the obstacle's plane instead of
    /// bouncing (its normal motion died out; see [`Slide`]).
    pub slide: Option<Slide>,
    /// Not an impulse: a sliding ball stopped slipping and rolls on from
    /// here (see `sim::roll`; `slide` is then the rolling slide).
    pub roll: bool,
    /// The impulse was a micro-collision: the contact separated slower than
    /// the scene's rest speed and was made to leave at exactly that speed.
    pub micro: bool,
    pub rest_time: Option<f64>,
    /// Friction mode when friction applied.
    pub friction: Option<FrictionMode>,
    /// `dt_c/du` (length m) when tangents were computed and the contact is not grazing.
    pub dt_du: Option<DVector<f64>>,
    /// States of a and (if a body) b just before and after the impulse.
    pub pre: [BodyState; 2],
    pub post: [BodyState; 2],
}

/// Why a Jacobian is not available.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum TangentError {
    /// A grazing contact makes `dt_c/du` unbounded from this event on.
    #[error(
        "grazing contact at event {event} (t = {t:.6} s, |E_q F| ratio {ratio:.1e}): the motion is not differentiable there; nudge falls back to sampling"
    )]
    Grazing { event: usize, t: f64, ratio: f64 },
    /// A sustained contact without a tangent: a pivot or skid (its start
    /// and end jump with the controls), a slide on a face that leaves it at
    /// a graze, or bodies frozen or woken in an island at an event that has
    /// no tangent itself: the Jacobian of the bodies concerned is flagged
    /// lost from here on.
    #[error(
        "a sustained contact from t = {t:.6} s (a pivot or skid, a slide leaving a face at a graze, or bodies at rest on bodies) has no tangent: the motion is not differentiable there; nudge falls back to sampling"
    )]
    Contact { t: f64 },
    /// The simulation was run without tangents.
    #[error("the trajectory was simulated without tangents")]
    NotComputed,
    /// A non-finite number appeared in the tangent.
    #[error("the Jacobian became non-finite at t = {t:.6} s")]
    NonFinite { t: f64 },
}

impl TangentError {
    /// Time from which Jacobians are unavailable.
    pub fn time(&self) -> f64 {
        match self {
            TangentError::Grazing { t, .. }
            | TangentError::NonFinite { t }
            | TangentError::Contact { t } => *t,
            TangentError::NotComputed => f64::NEG_INFINITY,
        }
    }
}

/// How often each effect's term was evaluated. An effect a scene does not
/// list stays at zero.
#[derive(Debug, Default, Clone)]
pub struct Counters {
    pub gravity: Cell<u64>,
    pub drag: Cell<u64>,
    pub gyroscopic: Cell<u64>,
    pub collisions: Cell<u64>,
    pub friction: Cell<u64>,
    /// Island statics solved (bodies resting on bodies, `sim::island`).
    pub islands: Cell<u64>,
}

impl Counters {
    pub(crate) fn bump(c: &Cell<u64>, n: u64) {
        c.set(c.get() + n);
    }
}

/// The simulated motion of a scene for one control vector.
#[derive(Debug, Clone)]
pub struct Trajectory {
    pub duration: f64,
    /// Effective gravity.
    pub gravity: Vec3,
    pub gravity_listed: bool,
    pub dynamics: Vec<BodyDynamics>,
    pub tracks: Vec<Track>,
    pub events: Vec<Event>,
    pub counters: Counters,
    /// Number of Jacobian columns (free controls); 0 without tangents.
    pub m: usize,
    pub tangent: bool,
    /// The first reason Jacobians stop being available (from its time on)
    /// for some body.
    pub tangent_error: Option<TangentError>,
    /// Per body: from which time its Jacobians are unavailable, and why. A
    /// grazing contact takes them from the bodies that touch; a later
    /// collision with such a body takes them from the other party too. A
    /// body that never meets one keeps exact Jacobians (a grazing egg in
    /// one bucket does not stop the other egg's edit).
    pub tangent_lost: Vec<Option<(f64, TangentError)>>,
    pub diagnostics: Vec<String>,
    /// Jacobian columns of each body's mass and first inertia entry.
    pub(crate) mass_cols: Vec<Option<usize>>,
    pub(crate) inertia_cols: Vec<Option<usize>>,
}

impl Trajectory {
    /// How many numbers the motion's steps store (at most
    /// [`super::MAX_STORED_VALUES`]).
    pub fn stored_values(&self) -> usize {
        self.tracks
            .iter()
            .flat_map(|t| &t.segments)
            .flat_map(|s| &s.steps)
            .map(super::integrator::Step::stored_len)
            .sum()
    }

    fn segment_index(&self, body: usize, t: f64, side: Side) -> usize {
        let segs = &self.tracks[body].segments;
        let mut i = segs.partition_point(|s| s.t0 <= t).saturating_sub(1);
        if side == Side::Pre && i > 0 && segs[i].t0 == t {
            i -= 1;
        }
        i
    }

    fn step_at<'a>(&self, seg: &'a Segment, t: f64) -> Option<&'a Step> {
        let i = seg.steps.partition_point(|s| s.t0 <= t);
        if i == 0 {
            None
        } else {
            Some(&seg.steps[i - 1])
        }
    }

    /// Rotation state (q, world ω) and the integrated vector at `t` in a
    /// segment; with `full` the vector includes the tangent block.
    fn rotation(
        &self,
        body: usize,
        seg: &Segment,
        t: f64,
        full: bool,
    ) -> (BodyState, Option<Vec<f64>>) {
        let d = &self.dynamics[body];
        let s0 = &seg.start;
        let tau = t - seg.t0;
        if seg.rest {
            return (*s0, None);
        }
        if let Some(slide) = &seg.slide {
            if self.gravity_listed {
                Counters::bump(&self.counters.gravity, 1);
            }
            return (slide.at(s0, d.drag_k, tau).state, None);
        }
        if let Some(pivot) = &seg.pivot {
            if self.gravity_listed {
                Counters::bump(&self.counters.gravity, 1);
            }
            return (pivot.at(tau), None);
        }
        let tr = translation(&s0.x, &s0.v, &self.gravity, d.drag_k, tau);
        if self.gravity_listed {
            Counters::bump(&self.counters.gravity, 1);
        }
        if d.drag_k.is_some() {
            Counters::bump(&self.counters.drag, 1);
        }
        if !d.integrate {
            let q = exp_so3(&(s0.w * tau)) * s0.q;
            return (
                BodyState {
                    x: tr.x,
                    q,
                    v: tr.v,
                    w: s0.w,
                },
                None,
            );
        }
        match self.step_at(seg, t) {
            None => (
                BodyState {
                    x: tr.x,
                    v: tr.v,
                    ..*s0
                },
                None,
            ),
            Some(step) => {
                let mut evals = 0;
                let (q, w, z) = if full {
                    let (q, z) = step.at(d, t, &mut evals);
                    (q, q * body_rate(&z), Some(z))
                } else {
                    let (q, z) = step.at_state(d, t, &mut evals);
                    (q, q * body_rate(&z), None)
                };
                Counters::bump(&self.counters.gyroscopic, evals);
                (
                    BodyState {
                        x: tr.x,
                        q,
                        v: tr.v,
                        w,
                    },
                    z,
                )
            }
        }
    }

    /// State of `body` at time `t` (at an event time, `side` picks the
    /// pre- or post-impulse limit).
    pub fn state(&self, body: usize, t: f64, side: Side) -> BodyState {
        let i = self.segment_index(body, t, side);
        self.rotation(body, &self.tracks[body].segments[i], t, false)
            .0
    }

    /// Whether `body`'s Jacobians are available at time `t`.
    pub fn jacobian_available(&self, body: usize, t: f64) -> Result<(), TangentError> {
        if !self.tangent {
            return Err(TangentError::NotComputed);
        }
        match self.tangent_lost.get(body).copied().flatten() {
            Some((from, e)) if t >= from => Err(e),
            _ => Ok(()),
        }
    }

    /// Jacobian `∂q(t)/∂u` of `body` (12 × m, rows `δx, δθ, δv, δω` with
    /// `δθ` a world-frame rotation), exact to integrator accuracy.
    pub fn jacobian(&self, body: usize, t: f64, side: Side) -> Result<DMatrix<f64>, TangentError> {
        self.jacobian_available(body, t)?;
        let i = self.segment_index(body, t, side);
        let seg = &self.tracks[body].segments[i];
        let j = self.segment_jacobian(body, seg, t);
        if j.iter().all(|v| v.is_finite()) {
            Ok(j)
        } else {
            Err(TangentError::NonFinite { t })
        }
    }

    /// Jacobian of `body`'s state at the (floating) time of `event`, just
    /// before or after it: the event moves with the controls, so this is
    /// `J(t_c) + F dt_c/du`, the derivative of the state at each run's own
    /// event time (a floating constraint's rows; what central differences
    /// of the states at the perturbed runs' events approximate).
    pub fn jacobian_at_event(
        &self,
        body: usize,
        event: &Event,
        side: Side,
    ) -> Result<DMatrix<f64>, TangentError> {
        // A ball's switch to rolling is no impulse: the state at its own
        // time is one from either side; the rolling side's flow is the
        // one its start state finds.
        let side = if event.roll { Side::Post } else { side };
        let j = self.jacobian(body, event.t, side)?;
        let lost = self.tangent_lost.get(body).copied().flatten();
        let dt = event
            .dt_du
            .as_ref()
            .ok_or(lost.map_or(TangentError::NotComputed, |(_, e)| e))?;
        let state = self.state(body, event.t, side);
        let f = self.flow(body, &state, self.resting(body, event.t, side));
        Ok(j + f * dt.transpose())
    }

    fn segment_jacobian(&self, body: usize, seg: &Segment, t: f64) -> DMatrix<f64> {
        let m = self.m;
        let j0 = &seg.j0;
        if seg.rest {
            return j0.clone();
        }
        let d = &self.dynamics[body];
        let s0 = &seg.start;
        let tau = t - seg.t0;
        if let Some(slide) = &seg.slide {
            if let Some(roll) = &slide.roll {
                let mass = self.mass_cols[body].map(|c| (c, d.mass));
                return roll.jacobian(&slide.normal, s0, tau, j0, mass);
            }
            let at = slide.at(s0, d.drag_k, tau);
            let mut j = DMatrix::zeros(12, m);
            let (jx0, jt0, jv0, jw0) = (j0.rows(0, 3), j0.rows(3, 3), j0.rows(6, 3), j0.rows(9, 3));
            j.rows_mut(0, 3).copy_from(&(jx0 + at.dx_dv * jv0));
            j.rows_mut(6, 3).copy_from(&(at.dv_dv * jv0));
            j.rows_mut(3, 3)
                .copy_from(&(at.rot * jt0 + at.dth_dw * jw0));
            j.rows_mut(9, 3).copy_from(&(at.dw_dw * jw0));
            if let (Some(k), Some(col)) = (d.drag_k, self.mass_cols[body]) {
                let dk = -k / d.mass;
                for r in 0..3 {
                    j[(r, col)] += at.dx_dk[r] * dk;
                    j[(6 + r, col)] += at.dv_dk[r] * dk;
                }
            }
            return j;
        }
        let tr = translation(&s0.x, &s0.v, &self.gravity, d.drag_k, tau);
        // Start from J₀ and update its rows in place, column by column: the
        // blocks are 3 × m with small m, where temporaries would cost more
        // than the arithmetic.
        let mut j = j0.clone();
        let rotation = (!d.integrate).then(|| {
            let wt = s0.w * tau;
            let e = *exp_so3(&wt).to_rotation_matrix().matrix();
            (e, left_jacobian(&wt) * tau)
        });
        for c in 0..m {
            let col = j0.column(c);
            let (x0, t0) = (col.fixed_rows::<3>(0), col.fixed_rows::<3>(3));
            let (v0, w0) = (col.fixed_rows::<3>(6), col.fixed_rows::<3>(9));
            // Translation: δx = δx₀ + φ₁ δv₀ (+ ∂x/∂k δk), δv = e δv₀ (+ ∂v/∂k δk).
            j.fixed_view_mut::<3, 1>(0, c)
                .copy_from(&(x0 + v0 * tr.dx_dv));
            j.fixed_view_mut::<3, 1>(6, c).copy_from(&(v0 * tr.dv_dv));
            // Torque-free rotation at constant ω: δθ = e δθ₀ + τ J_l δω₀.
            if let Some((e, jl)) = &rotation {
                j.fixed_view_mut::<3, 1>(3, c)
                    .copy_from(&(e * t0 + jl * w0));
            }
        }
        if let (Some(k), Some(col)) = (d.drag_k, self.mass_cols[body]) {
            // k = c/m, dk/dm = −k/m.
            let dk = -k / d.mass;
            for r in 0..3 {
                j[(r, col)] += tr.dx_dk[r] * dk;
                j[(6 + r, col)] += tr.dv_dk[r] * dk;
            }
        }
        if rotation.is_some() {
            return j;
        }
        let jt0 = j0.rows(3, 3);
        let jw0 = j0.rows(9, 3);
        let (st, z) = self.rotation(body, seg, t, true);
        let y = match z {
            Some(z) => tangent_block(&z),
            None => {
                let mut y = nalgebra::SMatrix::<f64, 6, 9>::zeros();
                y.fixed_view_mut::<6, 6>(0, 0).fill_with_identity();
                y
            }
        };
        // World → body at the segment start: η = R₀ᵀ δθ, δw = R₀ᵀ (δω + [ω₀]× δθ).
        let r0: Mat3 = *s0.q.to_rotation_matrix().matrix();
        let r0t = r0.transpose();
        let eta0 = r0t * jt0;
        let dw0 = r0t * (jw0 + skew(&s0.w) * jt0);
        let mut b0 = DMatrix::zeros(6, m);
        b0.rows_mut(0, 3).copy_from(&eta0);
        b0.rows_mut(3, 3).copy_from(&dw0);
        let y66 = DMatrix::from_iterator(6, 6, y.fixed_view::<6, 6>(0, 0).iter().cloned());
        let mut bt = y66 * b0;
        if let Some(col) = self.inertia_cols[body] {
            for k in 0..3 {
                for r in 0..6 {
                    bt[(r, col + k)] += y[(r, 6 + k)];
                }
            }
        }
        // Body → world at t: δθ = R η, δω = R δw − [ω]× R η.
        let r: Mat3 = *st.q.to_rotation_matrix().matrix();
        let dth = r * bt.rows(0, 3);
        let dw = r * bt.rows(3, 3) - skew(&st.w) * &dth;
        j.rows_mut(3, 3).copy_from(&dth);
        j.rows_mut(9, 3).copy_from(&dw);
        j
    }

    /// The state derivative `F = (v, ω, a, α)` of `body` in tangent coordinates.
    pub fn flow(&self, body: usize, s: &BodyState, resting: bool) -> DVector<f64> {
        if resting {
            return DVector::zeros(12);
        }
        // A state that starts a slide moves by the slide's law.
        let slide = self.tracks[body]
            .segments
            .iter()
            .rev()
            .find(|seg| seg.slide.is_some() && seg.start == *s)
            .and_then(|seg| seg.slide);
        let f = match slide {
            Some(sl) => sl.flow(s, self.dynamics[body].drag_k),
            None => self.dynamics[body].state_derivative(s, &self.gravity),
        };
        DVector::from_iterator(12, f.iter().flat_map(|v| v.iter().cloned()))
    }

    /// Whether `body` rests at time `t`.
    pub fn resting(&self, body: usize, t: f64, side: Side) -> bool {
        let i = self.segment_index(body, t, side);
        self.tracks[body].segments[i].rest
    }

    /// The slide `body` follows at time `t`, if any.
    pub fn slide(&self, body: usize, t: f64, side: Side) -> Option<Slide> {
        let i = self.segment_index(body, t, side);
        self.tracks[body].segments[i].slide
    }

    /// Whether `body` leans on obstacle `o` at time `t` (resting on
    /// anything, sliding on `o` when it has no other parts, or pivoting on
    /// `o` with its other parts clear of the sweep): the pair needs no
    /// event search.
    pub fn supported_by(&self, body: usize, t: f64, o: usize) -> bool {
        let seg = &self.tracks[body].segments[self.segment_index(body, t, Side::Post)];
        seg.rest
            || seg
                .slide
                .is_some_and(|s| s.obstacle == o && !s.face.is_some_and(|f| f.beside))
            || seg
                .pivot
                .as_ref()
                .is_some_and(|p| (p.obstacle == o && !p.beside) || p.stepped().is_some())
    }

    /// The pivot `body` follows at time `t`, if any.
    pub fn pivot(&self, body: usize, t: f64, side: Side) -> Option<&Pivot> {
        let i = self.segment_index(body, t, side);
        self.tracks[body].segments[i].pivot.as_deref()
    }

    /// Whether `s` is the frozen state of a body at rest (resting bodies
    /// have zero velocities; checked only then).
    pub(crate) fn resting_state(&self, body: usize, s: &BodyState) -> bool {
        self.tracks[body]
            .segments
            .iter()
            .rev()
            .any(|seg| seg.rest && seg.start.x == s.x)
    }

    /// Events in which `body` takes part, in time order.
    pub fn body_events(&self, body: usize) -> Vec<&Event> {
        self.events
            .iter()
            .filter(|e| e.a == body || e.b == Party::Body(body))
            .collect()
    }

    /// Signature of the motion: the ordered list of (pair, feature) keys.
    /// How each event ended (rest, slide, micro-collision) is part of it:
    /// each is a different impulse map, so a change is a discontinuity.
    pub fn signature(&self) -> Vec<String> {
        self.events
            .iter()
            .map(|e| {
                let ending = if e.roll {
                    "|roll"
                } else if e.rest {
                    "|rest"
                } else if e.slide.is_some() {
                    "|slide"
                } else if e.micro && e.separation > -e.approach {
                    "|micro-floor"
                } else if e.micro {
                    "|micro"
                } else {
                    ""
                };
                format!("{}|{:?}|{}{ending}", e.a, e.b, e.key)
            })
            .collect()
    }

    /// Sample a body-frame point's path at `n` uniform times plus every
    /// event time of the body (so bounces are drawn sharp).
    pub fn path(&self, body: usize, point: &Vec3, n: usize) -> Vec<(f64, Vec3)> {
        let mut times: Vec<f64> = (0..=n)
            .map(|i| self.duration * i as f64 / n.max(1) as f64)
            .collect();
        for e in self.body_events(body) {
            times.push(e.t);
        }
        times.sort_by(f64::total_cmp);
        times.dedup();
        times
            .into_iter()
            .map(|t| (t, self.state(body, t, Side::Post).point(point)))
            .collect()
    }
}
