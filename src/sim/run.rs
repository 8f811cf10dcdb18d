//! The simulation loop: windows of integration, event search, impulses and
//! the saltation update of the Jacobian at every impulse (docs/design.md §5).

use super::dynamics::BodyDynamics;
use super::events::{Pair, Tolerances, World};
use super::impulse::{FrictionMode, ImpulseCtx, PartyCtx};
use super::integrator::{self, Step};
use super::rest::{self, Mode, Slide};
use super::state::{BodyState, StateSide};
use super::trajectory::{Counters, Event, Party, Segment, TangentError, Track, Trajectory};
use crate::controls::Controls;
use crate::geometry::{Corner, FeaturePair, PartKind, PatchCorner};
use crate::math::{Vec3, exp_so3, left_jacobian};
use crate::scene::{Block, Method, Scene};
use nalgebra::{DMatrix, DVector, Isometry3, Translation3, UnitQuaternion};

/// A fixed RK4 step whose body's angular velocity would turn by more than
/// this (rad; `h ·` [`BodyDynamics::precession_rate`]) is split into
/// substeps that turn it by at most this much. RK4 goes unstable near
/// 2.8 rad per step, which used to turn such a body into NaN. RK4's error
/// per step grows as the fifth power of the turn: at 0.1 rad energy and |L|
/// drifted 7e-6 over the 2e4 rad/s tumble of the extreme-parameter needle
/// (tests/hard.rs), at 0.05 rad 2e-7, for twice the steps of such spins only.
const SUBSTEP_TURN: f64 = 0.05;
/// More substeps than this per step: [`SimError::SpinTooFast`].
const MAX_SUBSTEPS: usize = 10_000;
/// Depth of a contact patch as a fraction of the body's reach: corners on
/// a flat face weigh fully in the impulse point, corners up to this height
/// over it (3e-4 of the body's size: 0.2 mm for a 1.2 m plank, 20 µm for a
/// mug) less and less. An edge or face landing nearly flat is then one
/// impulse near the patch's centre, not a sequence of corner impacts whose
/// order rocks and turns the body.
const PATCH_DEPTH: f64 = 1e-3;
/// A face takes part in a contact patch when its normal is within this
/// angle (rad) of the contact normal.
const PATCH_ANGLE: f64 = 0.02;

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
    /// Two parties stayed in contact, colliding ever faster (resting contact
    /// between bodies is outside the impact model).
    #[error(
        "\"{a}\" and \"{b}\" stay in contact from t = {t:.6} s ({count} impacts in {span:.1e} s): nudge models impacts, not sustained contact; raise restitution or separate them"
    )]
    SustainedContact {
        a: String,
        b: String,
        t: f64,
        count: usize,
        span: f64,
    },
    /// The event search between two parties made no progress (a contact
    /// that neither separates nor approaches faster than the root
    /// tolerance can resolve). Nothing tunnels silently: the run stops.
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

/// The saltation result: post-impulse Jacobian rows of the parties,
/// `dt_c/du`, and the grazing ratio.
type Saltation = (DMatrix<f64>, DVector<f64>, f64);

/// Where an integrated body's next step starts.
#[derive(Debug, Clone)]
struct Cursor {
    q: UnitQuaternion<f64>,
    z: Vec<f64>,
    /// `f(z)` (empty until known): evaluated for the first try of a step,
    /// or given by the step that ended here ([`Step::end_derivative_into`]);
    /// every try of the next adaptive step starts with it.
    f0: Vec<f64>,
}

impl Cursor {
    fn new(q: UnitQuaternion<f64>, z: Vec<f64>) -> Cursor {
        Cursor {
            q,
            z,
            f0: Vec::new(),
        }
    }
}

fn reset_theta(mut z: Vec<f64>) -> Vec<f64> {
    z[3..6].fill(0.0);
    z
}

/// The tangent columns body `i`'s rotation integrates in a segment that
/// starts with Jacobian `j0`. With its inertia free, all of them. Otherwise
/// a control reaches the rotation only through the orientation and
/// angular-velocity rows of `j0`; where those are all zero they stay zero
/// to the segment's end (in free flight the rotation depends only on its
/// own start and the inertia), and no variational equation is integrated
/// there: the segment costs what a plain simulation costs (`tangent_block`
/// of the shorter vector is zero, which is then exact).
fn rotation_columns(
    opts: &SimOptions,
    j0: &DMatrix<f64>,
    controls: &Controls,
    i: usize,
) -> integrator::Columns {
    let reached = || {
        j0.rows(3, 3)
            .iter()
            .chain(j0.rows(9, 3).iter())
            .any(|v| *v != 0.0)
    };
    if !opts.tangent {
        integrator::Columns::None
    } else if controls.body_column(i, Block::Inertia).is_some() {
        integrator::Columns::WithInertia
    } else if reached() {
        integrator::Columns::Transition
    } else {
        integrator::Columns::None
    }
}

fn initial_jacobian(scene: &Scene, controls: &Controls, i: usize, m: usize) -> DMatrix<f64> {
    let mut j = DMatrix::zeros(12, m);
    let b = &scene.bodies[i];
    let mut put = |block: Block, row: usize, m3: &nalgebra::Matrix3<f64>| {
        if let Some(col) = controls.body_column(i, block).filter(|c| c + 3 <= m) {
            j.view_mut((row, col), (3, 3)).copy_from(m3);
        }
    };
    let id = nalgebra::Matrix3::identity();
    put(Block::Position, 0, &id);
    put(Block::Orientation, 3, &left_jacobian(&b.orientation));
    put(Block::Velocity, 6, &id);
    put(Block::AngularVelocity, 9, &id);
    j
}

struct Sim<'a> {
    scene: &'a Scene,
    controls: &'a Controls,
    opts: SimOptions,
    traj: Trajectory,
    cursors: Vec<Option<Cursor>>,
    /// The steps of one integration try, kept to reuse its allocation.
    step_buf: Vec<(usize, Step)>,
    pairs: Vec<Pair>,
    /// The index in `pairs` of each listed body–body pair `(a, b)`.
    body_pairs: std::collections::HashMap<(usize, usize), usize>,
    obstacle_boxes: Vec<Option<(Vec3, Vec3)>>,
    /// Every obstacle placed for contact queries, once.
    obstacles: Vec<crate::geometry::Placement<'a>>,
    tol: Tolerances,
    /// Per pair, what its last event search established; valid while the
    /// motions it read are unchanged (cleared when either body starts a new
    /// segment or is re-integrated, and when the pair's own search state
    /// changes).
    searched: Vec<Option<Searched>>,
    /// The indices in `pairs` of each body's pairs.
    pairs_of: Vec<Vec<usize>>,
    /// Per body, its swept box from some time up to `end` (so it holds the
    /// body over any later interval ending by `end`), cleared with its
    /// searches.
    swept: Vec<Option<(f64, (Vec3, Vec3))>>,
    /// What the motion stores so far (see [`super::budget`]).
    stored: super::budget::Stored,
}

/// The outcome of a pair's event search from `from`: its first impact
/// (`hit`), or none before `until`. An impulse elsewhere does not change
/// it, so after an event only the pairs of the bodies it moved are searched
/// again: the cost of an event no longer grows with the number of bodies.
#[derive(Debug, Clone, Copy)]
struct Searched {
    from: f64,
    until: f64,
    hit: Option<(f64, crate::geometry::Contact)>,
}

/// Whether the motion that starts at `s` stays within the finite numbers
/// for `duration` seconds as far as its invariants tell: the reach of its
/// velocity and spin, its kinetic energy, its angular momentum and the
/// drag rate. A start whose every number is finite can still overflow in
/// these (`ω = 1e308 rad/s` makes `|ω|` and every rotation through it
/// infinite), and a contact query would then see a pose of NaNs.
fn representable(s: &BodyState, d: &BodyDynamics, duration: f64) -> bool {
    let spin = d.inertia * s.w;
    let energy = d.mass * s.v.norm_squared() + s.w.dot(&spin);
    [
        s.v.norm() * duration,
        s.w.norm() * duration,
        spin.norm(),
        energy,
        d.drag_k.unwrap_or(0.0) * duration,
    ]
    .iter()
    .all(|v| v.is_finite())
}

/// Simulate the scene for its current control values. With
/// `opts.tangent`, Jacobians with respect to the free controls of
/// `controls` are propagated alongside.
pub fn simulate(
    scene: &Scene,
    controls: &Controls,
    opts: &SimOptions,
) -> Result<Trajectory, SimError> {
    let m = if opts.tangent { controls.m() } else { 0 };
    let dynamics: Vec<BodyDynamics> = (0..scene.bodies.len())
        .map(|i| BodyDynamics::new(scene, i, controls))
        .collect();
    let mut tracks = Vec::new();
    let mut cursors = Vec::new();
    for (i, b) in scene.bodies.iter().enumerate() {
        let q = exp_so3(&b.orientation);
        let start = BodyState {
            x: b.position,
            q,
            v: b.velocity,
            w: b.angular_velocity,
        };
        if !start.is_finite() || !representable(&start, &dynamics[i], scene.duration) {
            return Err(SimError::NonFinite {
                body: b.name.clone(),
                t: 0.0,
            });
        }
        let j0 = initial_jacobian(scene, controls, i, m);
        tracks.push(Track {
            segments: vec![Segment {
                slide: None,
                t0: 0.0,
                start,
                j0,
                rest: false,
                steps: Vec::new(),
            }],
        });
        let columns = rotation_columns(opts, &tracks[i].segments[0].j0, controls, i);
        cursors.push(dynamics[i].integrate.then(|| {
            Cursor::new(
                q,
                integrator::initial(&(q.inverse() * b.angular_velocity), columns),
            )
        }));
    }
    let col = |i: usize, b: Block| {
        if opts.tangent {
            controls.body_column(i, b)
        } else {
            None
        }
    };
    let end = opts
        .until
        .filter(|t| t.is_finite())
        .map_or(scene.duration, |t| t.clamp(0.0, scene.duration));
    let traj = Trajectory {
        duration: end,
        gravity: scene.effective_gravity(),
        gravity_listed: scene.effects.gravity,
        mass_cols: (0..scene.bodies.len())
            .map(|i| col(i, Block::Mass))
            .collect(),
        inertia_cols: (0..scene.bodies.len())
            .map(|i| col(i, Block::Inertia))
            .collect(),
        dynamics,
        tracks,
        events: Vec::new(),
        counters: Counters::default(),
        m,
        tangent: opts.tangent,
        tangent_error: None,
        tangent_lost: vec![None; scene.bodies.len()],
        diagnostics: Vec::new(),
    };
    let mut pairs = Vec::new();
    if scene.effects.collisions {
        for a in 0..scene.bodies.len() {
            for o in 0..scene.obstacles.len() {
                pairs.push(Pair {
                    a,
                    b: Party::Obstacle(o),
                    armed: true,
                    hold: 0.0,
                    skips: 0,
                    skipped_since: 0.0,
                });
            }
        }
        for p in &scene.pairs {
            pairs.push(Pair {
                a: p[0],
                b: Party::Body(p[1]),
                armed: true,
                hold: 0.0,
                skips: 0,
                skipped_since: 0.0,
            });
        }
    }
    if scene.effects.collisions {
        starts_apart(scene)?;
    }
    let obstacle_boxes = scene
        .obstacles
        .iter()
        .map(|o| {
            if o.geometry.reach().is_finite() {
                let pts: Vec<Vec3> = o
                    .geometry
                    .outline(1.0)
                    .iter()
                    .flat_map(|(a, b)| [*a, *b])
                    .map(|p| (o.pose * nalgebra::Point3::from(p)).coords)
                    .collect();
                let lo = pts
                    .iter()
                    .fold(Vec3::repeat(f64::INFINITY), |a, p| a.inf(p));
                let hi = pts
                    .iter()
                    .fold(Vec3::repeat(f64::NEG_INFINITY), |a, p| a.sup(p));
                Some((lo, hi))
            } else {
                None
            }
        })
        .collect();
    let root = scene.accuracy.root_tol;
    let mut sim = Sim {
        scene,
        controls,
        opts: *opts,
        traj,
        cursors,
        step_buf: Vec::new(),
        body_pairs: pairs
            .iter()
            .enumerate()
            .filter_map(|(k, p)| match p.b {
                Party::Body(j) => Some(((p.a, j), k)),
                Party::Obstacle(_) => None,
            })
            .collect(),
        searched: vec![None; pairs.len()],
        swept: vec![None; scene.bodies.len()],
        stored: super::budget::Stored::new(scene.bodies.len()),
        pairs_of: (0..scene.bodies.len())
            .map(|i| {
                (0..pairs.len())
                    .filter(|&k| pairs[k].a == i || pairs[k].b == Party::Body(i))
                    .collect()
            })
            .collect(),
        pairs,
        obstacle_boxes,
        obstacles: scene
            .obstacles
            .iter()
            .map(|o| crate::geometry::Placement::new(&o.geometry, &o.pose))
            .collect(),
        tol: Tolerances {
            root,
            arm: (10.0 * root).max(1e-9),
        },
    };
    sim.run()?;
    Ok(sim.traj)
}

/// Penetration allowed at t = 0 (m), as when a scene is loaded.
const START_OVERLAP: f64 = 1e-9;

/// Refuse initial states in which a body overlaps an obstacle or a body it
/// collides with.
fn starts_apart(scene: &Scene) -> Result<(), SimError> {
    let pose = |b: &crate::scene::Body| {
        Isometry3::from_parts(Translation3::from(b.position), exp_so3(&b.orientation))
    };
    let check =
        |i: usize, geometry: &crate::geometry::Geometry, at: &Isometry3<f64>, other: &str| {
            let b = &scene.bodies[i];
            match crate::geometry::contact(&b.geometry, &pose(b), geometry, at, 0.0) {
                Some(c) if c.distance < -START_OVERLAP => Err(SimError::StartsInside {
                    body: b.name.clone(),
                    other: other.to_string(),
                    depth: -c.distance,
                }),
                _ => Ok(()),
            }
        };
    for i in 0..scene.bodies.len() {
        for o in &scene.obstacles {
            check(i, &o.geometry, &o.pose, &o.name)?;
        }
    }
    for &[i, j] in &scene.pairs {
        let b = &scene.bodies[j];
        check(i, &b.geometry, &pose(b), &b.name)?;
    }
    Ok(())
}

impl Sim<'_> {
    fn run(&mut self) -> Result<(), SimError> {
        let duration = self.traj.duration;
        let mut t = 0.0;
        let mut frontier = 0.0;
        let mut h = match self.scene.accuracy.method {
            Method::Rk4 { step } => step,
            Method::Adaptive { max_step, .. } => max_step.min(1e-2),
        };
        let window = self.opts.window.max(self.scene.accuracy.window());
        let mut win = window;
        while t < duration {
            let end = (t + win).min(duration);
            while frontier < end && self.cursors.iter().any(Option::is_some) {
                let mut hh = match self.scene.accuracy.method {
                    Method::Rk4 { step } => step,
                    Method::Adaptive { .. } => h,
                };
                if duration - frontier < 1.5 * hh {
                    hh = duration - frontier;
                }
                let taken = self.integrate(frontier, hh)?;
                frontier += taken.0;
                h = taken.1;
            }
            let end = if self.cursors.iter().any(Option::is_some) {
                end.min(frontier)
            } else {
                end
            };
            // Without integrated bodies every state is known in closed form
            // beyond the window: armed pairs are searched a window further,
            // so the next events' windows find their searches done.
            let ahead = if self.cursors.iter().any(Option::is_some) {
                end
            } else {
                (end + window).min(duration)
            };
            match self.next_impact(t, end, ahead)? {
                None => {
                    t = end;
                    win = (2.0 * win).min(window);
                }
                Some((tc, pair, contact)) => {
                    self.truncate(tc);
                    frontier = tc;
                    self.impact(tc, pair, &contact)?;
                    t = tc;
                    // Integration past the next impact is thrown away, and
                    // impacts come in clusters (a body rocking on a
                    // support): start again with a window of two steps.
                    // Closed-form motions cost nothing to look ahead in.
                    if self.cursors.iter().any(Option::is_some) {
                        win = match self.scene.accuracy.method {
                            Method::Rk4 { step } => 2.0 * step,
                            Method::Adaptive { .. } => 2.0 * h,
                        }
                        .min(window);
                    }
                    if self.traj.events.len() > self.opts.max_events {
                        return Err(SimError::TooManyEvents {
                            limit: self.opts.max_events,
                            t,
                        });
                    }
                }
            }
        }
        for (i, b) in self.scene.bodies.iter().enumerate() {
            if !self.traj.state(i, duration, StateSide::After).is_finite() {
                return Err(SimError::NonFinite {
                    body: b.name.clone(),
                    t: duration,
                });
            }
        }
        Ok(())
    }

    /// Advance every integrated body by one shared step from `t`. Returns the
    /// step taken and the proposal for the next one.
    fn integrate(&mut self, t: f64, h: f64) -> Result<(f64, f64), SimError> {
        let mut evals = 0u64;
        // The steps of one try, in body order (a buffer kept across steps).
        let mut steps = std::mem::take(&mut self.step_buf);
        steps.clear();
        let result = match self.scene.accuracy.method {
            Method::Rk4 { .. } => {
                for (i, c) in self.cursors.iter().enumerate() {
                    let Some(c) = c else { continue };
                    // A body whose angular velocity would turn by more
                    // than 0.1 rad in the step (a fast spin of a
                    // lopsided body) takes it in substeps of 0.1 rad.
                    let d = &self.traj.dynamics[i];
                    let rate = d.precession_rate(&integrator::body_rate(&c.z));
                    let n = (rate * h / self.opts.substep_turn).ceil().max(1.0);
                    if n > MAX_SUBSTEPS as f64 {
                        return Err(SimError::SpinTooFast {
                            body: self.scene.bodies[i].name.clone(),
                            t,
                            rate,
                            step: h,
                        });
                    }
                    let n = n as usize;
                    let hs = h / n as f64;
                    let mut q = c.q;
                    let mut z = c.z.clone();
                    for k in 0..n {
                        let t0 = if k == 0 { t } else { t + k as f64 * hs };
                        let len = if k + 1 == n { t + h - t0 } else { hs };
                        let step = integrator::step_rk4(d, t0, q, &z, len, &mut evals);
                        q = step.end_into(&mut z);
                        steps.push((i, step));
                    }
                }
                self.push_steps(&mut steps, t + h)?;
                (h, h)
            }
            Method::Adaptive { tol, max_step } => {
                // Every try of this step starts from the same state, so
                // with the same first stage.
                for (i, c) in self.cursors.iter_mut().enumerate() {
                    if let Some(c) = c
                        && c.f0.is_empty()
                    {
                        c.f0 = integrator::first_stage(&self.traj.dynamics[i], &c.z, &mut evals);
                    }
                }
                let mut hh = h;
                loop {
                    steps.clear();
                    let mut err: f64 = 0.0;
                    for (i, c) in self.cursors.iter().enumerate() {
                        let Some(c) = c else { continue };
                        let (s, e) = integrator::step_dopri(
                            &self.traj.dynamics[i],
                            t,
                            c.q,
                            &c.z,
                            &c.f0,
                            hh,
                            tol,
                            &mut evals,
                        );
                        err = err.max(if e.is_finite() { e } else { f64::INFINITY });
                        steps.push((i, s));
                    }
                    if err <= 1.0 {
                        let grow = if err > 0.0 {
                            (0.9 * err.powf(-0.2)).min(5.0)
                        } else {
                            5.0
                        };
                        self.push_steps(&mut steps, t + hh)?;
                        break (hh, (hh * grow).min(max_step));
                    }
                    hh *= (0.9 * err.powf(-0.2)).clamp(0.1, 0.9);
                    if hh.is_nan() || hh < 1e-12 {
                        return Err(SimError::StepTooSmall { t });
                    }
                }
            }
        };
        self.step_buf = steps;
        Counters::bump(&self.traj.counters.gyroscopic, evals);
        Ok(result)
    }

    /// Append the steps of one try (`(body, step)`, drained) to their
    /// bodies' segments and move their cursors to the steps' ends.
    fn push_steps(&mut self, steps: &mut Vec<(usize, Step)>, t1: f64) -> Result<(), SimError> {
        for (i, s) in steps.drain(..) {
            if !s.z1().iter().take(6).all(|v| v.is_finite()) {
                return Err(SimError::NonFinite {
                    body: self.scene.bodies[i].name.clone(),
                    t: t1,
                });
            }
            if let Some(c) = self.cursors[i].as_mut() {
                // The cursor's buffers are reused: no allocation per step.
                c.q = s.end_into(&mut c.z);
                if !s.end_derivative_into(&mut c.f0) {
                    c.f0.clear();
                }
            }
            if let Some(seg) = self.traj.tracks[i].segments.last_mut() {
                self.stored.add(i, s.stored_len());
                seg.steps.push(s);
            }
        }
        match self.stored.over_budget() {
            Some(i) => Err(SimError::MotionTooLarge {
                body: self.scene.bodies[i].name.clone(),
                t: t1,
            }),
            None => Ok(()),
        }
    }

    /// Cut every integrated body's steps at `tc` and restart its cursor there.
    fn truncate(&mut self, tc: f64) {
        for i in 0..self.cursors.len() {
            if self.cursors[i].is_none() {
                continue;
            }
            let d = &self.traj.dynamics[i];
            let Some(seg) = self.traj.tracks[i].segments.last() else {
                continue;
            };
            let k = seg.steps.partition_point(|s| s.t0 <= tc);
            if k == 0 {
                continue;
            }
            let mut evals = 0;
            let (q, z) = seg.steps[k - 1].at(d, tc, &mut evals);
            Counters::bump(&self.traj.counters.gyroscopic, evals);
            if let Some(seg) = self.traj.tracks[i].segments.last_mut() {
                let keep = seg.steps.partition_point(|s| s.t0 < tc);
                let cut: usize = seg.steps[keep..].iter().map(Step::stored_len).sum();
                self.stored.remove(i, cut);
                seg.steps.truncate(keep);
            }
            // Re-integrated from `tc` with other steps: its states move by
            // round-off, so its pairs are searched again.
            self.forget_searches(i);
            self.cursors[i] = Some(Cursor::new(q, reset_theta(z)));
        }
    }

    /// Drop the searches of body `i`'s pairs: its motion changed.
    fn forget_searches(&mut self, i: usize) {
        for &k in &self.pairs_of[i] {
            self.searched[k] = None;
        }
        self.swept[i] = None;
    }

    /// The earliest impact in `[t0, t1]`: broad phase, then conservative
    /// advancement per candidate pair.
    #[allow(clippy::type_complexity)]
    fn next_impact(
        &mut self,
        t0: f64,
        t1: f64,
        ahead: f64,
    ) -> Result<Option<(f64, usize, crate::geometry::Contact)>, SimError> {
        if self.pairs.is_empty() || t1 <= t0 {
            return Ok(None);
        }
        let world = World {
            scene: self.scene,
            traj: &self.traj,
            obstacles: &self.obstacles,
        };
        // Re-arm pairs that have separated by more than the arm distance.
        for (p, searched) in self.pairs.iter_mut().zip(self.searched.iter_mut()) {
            if p.armed {
                continue;
            }
            match world.contact(p, t0, self.tol.arm) {
                None => p.armed = true,
                Some((c, _)) => p.armed = c.distance > self.tol.arm,
            }
            if p.armed {
                *searched = None;
            }
        }
        let n = self.scene.bodies.len();
        let boxes: Vec<(Vec3, Vec3)> = (0..n)
            .map(|i| match self.swept[i] {
                Some((end, b)) if end >= t1 => b,
                _ => {
                    let b = world.sweep_box(i, t0, ahead);
                    self.swept[i] = Some((ahead, b));
                    b
                }
            })
            .collect();
        let overlap = |a: &(Vec3, Vec3), b: &(Vec3, Vec3)| {
            (0..3).all(|k| a.0[k] <= b.1[k] && b.0[k] <= a.1[k])
        };
        // Sweep and prune on x for body–body pairs (not quadratic in N).
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| boxes[a].0.x.total_cmp(&boxes[b].0.x));
        let mut close: Vec<usize> = Vec::new();
        let mut active: Vec<usize> = Vec::new();
        for &i in &order {
            active.retain(|&j| boxes[j].1.x >= boxes[i].0.x);
            for &j in &active {
                let key = (i.min(j), i.max(j));
                if let Some(&k) = self.body_pairs.get(&key)
                    && overlap(&boxes[i], &boxes[j])
                {
                    close.push(k);
                }
            }
            active.push(i);
        }
        // Candidates: body–obstacle pairs whose boxes overlap, and the
        // body–body pairs the sweep kept (never all N² pairs), in pair order.
        // (Body–obstacle pairs come first in `pairs`.)
        let with_obstacles = self
            .pairs
            .iter()
            .take_while(|p| matches!(p.b, Party::Obstacle(_)))
            .count();
        let mut candidates: Vec<usize> = (0..with_obstacles)
            .filter(|&k| match self.pairs[k].b {
                Party::Obstacle(o) => {
                    let a = self.pairs[k].a;
                    !self.traj.supported_by(a, t0, o)
                        && self.obstacle_boxes[o]
                            .as_ref()
                            .is_none_or(|b| overlap(&boxes[a], b))
                }
                Party::Body(_) => false,
            })
            .collect();
        candidates.extend(close);
        candidates.sort_unstable();
        let mut best: Option<(f64, usize, crate::geometry::Contact)> = None;
        for k in candidates {
            let p = &self.pairs[k];
            let limit = best.as_ref().map_or(t1, |b| b.0);
            let stalled = |t| SimError::EventSearchStalled {
                a: self.scene.bodies[p.a].name.clone(),
                b: self.party_name(p.b),
                t,
            };
            // An armed pair's search runs to the window's end and stands
            // while its motions do, so another pair's event does not make
            // it search again. A disarmed pair is searched afresh, only up
            // to the best impact so far (its skin may re-arm inside the
            // search, which a continuation would not see).
            let cached = self.searched[k].filter(|s| p.armed && s.from <= t0);
            // Search an armed pair on to `ahead`; a search that stalls past
            // this window resumes there next time (an event before then may
            // change the motions), and stops the run only inside it.
            let ahead_from = |from: f64| match world.find_impact(p, from, ahead, &self.tol) {
                Ok(found) => Ok((found, ahead)),
                Err(t) if t > t1 => Ok((None, t)),
                Err(t) => Err(stalled(t)),
            };
            let found = match cached {
                Some(Searched {
                    hit: Some((tc, c)), ..
                }) if tc >= t0 => Some((tc, c)),
                Some(s) if s.hit.is_none() && s.until >= t1 => None,
                Some(s) if s.hit.is_none() => {
                    let (found, until) = ahead_from(s.until)?;
                    self.searched[k] = Some(Searched {
                        until,
                        hit: found,
                        ..s
                    });
                    found
                }
                _ if p.armed => {
                    let (found, until) = ahead_from(t0)?;
                    self.searched[k] = Some(Searched {
                        from: t0,
                        until,
                        hit: found,
                    });
                    found
                }
                _ => world
                    .find_impact(p, t0, limit, &self.tol)
                    .map_err(stalled)?,
            }
            .filter(|(tc, _)| *tc <= limit);
            if let Some((tc, c)) = found
                && best.as_ref().is_none_or(|b| tc < b.0)
            {
                best = Some((tc, k, c));
            }
        }
        Ok(best)
    }

    fn party_name(&self, p: Party) -> String {
        match p {
            Party::Body(i) => self.scene.bodies[i].name.clone(),
            Party::Obstacle(i) => self.scene.obstacles[i].name.clone(),
        }
    }

    fn party_ctx(&self, i: usize, s: &BodyState) -> PartyCtx {
        let d = &self.traj.dynamics[i];
        PartyCtx {
            state: *s,
            mass: d.mass,
            principal: d.principal,
            axes: d.axes,
        }
    }

    /// Apply the impulse of pair `k` at `tc`, start new segments and update
    /// the Jacobians by the saltation formula.
    fn impact(
        &mut self,
        tc: f64,
        k: usize,
        contact: &crate::geometry::Contact,
    ) -> Result<(), SimError> {
        let pair = self.pairs[k];
        self.pairs[k].armed = false;
        self.searched[k] = None;
        let scene = self.scene;
        let a = pair.a;
        let sa = self.traj.state(a, tc, StateSide::After);
        let sb = match pair.b {
            Party::Body(j) => Some(self.traj.state(j, tc, StateSide::After)),
            Party::Obstacle(_) => None,
        };
        let (gb, pose_b, e_b, mu_b) = match pair.b {
            Party::Body(j) => (
                &scene.bodies[j].geometry,
                sb.as_ref().map(BodyState::pose).unwrap_or_default(),
                scene.bodies[j].restitution,
                scene.bodies[j].friction,
            ),
            Party::Obstacle(o) => (
                &scene.obstacles[o].geometry,
                scene.obstacles[o].pose,
                scene.obstacles[o].restitution,
                scene.obstacles[o].friction,
            ),
        };
        let body_a = &scene.bodies[a];
        let mut feature = FeaturePair::classify(&body_a.geometry, &sa.pose(), gb, &pose_b, contact);
        let index = self.traj.events.len();
        let control = scene.event_control(index);
        let restitution = control
            .and_then(|c| c.restitution)
            .unwrap_or(body_a.restitution * e_b);
        let n = contact.normal;
        let axis = {
            let k = (0..3)
                .min_by(|&x, &y| n[x].abs().total_cmp(&n[y].abs()))
                .unwrap_or(0);
            let mut e = Vec3::zeros();
            e[k] = 1.0;
            e
        };
        let friction = if scene.effects.friction {
            (body_a.friction * mu_b).sqrt()
        } else {
            0.0
        };
        let mut ctx = ImpulseCtx {
            feature: feature.clone(),
            a: self.party_ctx(a, &sa),
            b: match (pair.b, &sb) {
                (Party::Body(j), Some(s)) => Some(self.party_ctx(j, s)),
                _ => None,
            },
            b_pose: pose_b,
            restitution,
            normal_dev: control.and_then(|c| c.normal),
            tangent_axis: axis,
            friction,
            mode: FrictionMode::default(),
            min_separation: None,
        };
        let mut res = ctx.apply();
        if friction > 0.0 {
            Counters::bump(&self.traj.counters.friction, 1);
        }
        if let Some((corners, depth, face)) = self.patch(
            a,
            &body_a.geometry.parts[contact.part_a],
            &sa,
            gb.parts.get(contact.part_b),
            &pose_b,
            contact,
        ) {
            let patch = feature.at_patch(corners, depth, face);
            ctx.feature = patch.clone();
            let r2 = ctx.apply();
            // The patch's impulse must also stop the touching point: a body
            // pivoting fast about it (a box spinning onto a corner) would
            // otherwise keep sinking there while the centroid separates.
            let touching = contact.point_a;
            let at = |v: &Vec3, w: &Vec3, x: &Vec3| v + w.cross(&(touching - x));
            let vb = sb.map_or(Vec3::zeros(), |s| at(&r2.vb, &r2.wb, &s.x));
            let stopped = n.dot(&(at(&r2.va, &r2.wa, &sa.x) - vb)) >= -1e-9 * r2.approach.abs();
            if r2.approach < 0.0 && stopped {
                feature = patch;
                res = r2;
            } else {
                ctx.feature = feature.clone();
            }
        }
        if res.approach >= 0.0 {
            // A simultaneous contact whose centroid does not approach may
            // still have a vertex that does (an edge or face rocking about
            // its centre, after an inelastic impulse there): that vertex
            // takes the impulse. Skipping it let the vertex sink below the
            // surface.
            let deepest = feature
                .a_vertices(&body_a.geometry)
                .into_iter()
                .map(|(i, p)| {
                    let at = sa.point(&p);
                    let vb = sb.map_or(Vec3::zeros(), |s| s.v + s.w.cross(&(at - s.x)));
                    (i, p, n.dot(&(sa.point_velocity(&p) - vb)))
                })
                .min_by(|x, y| x.2.total_cmp(&y.2));
            if let Some((i, p, vn)) = deepest
                && vn < 0.0
            {
                let single = feature.with_a_vertex(i, p);
                ctx.feature = single.clone();
                let r2 = ctx.apply();
                if r2.approach < 0.0 {
                    feature = single;
                    res = r2;
                } else {
                    ctx.feature = feature.clone();
                }
            }
        }
        if res.approach >= 0.0 {
            // The feature model extrapolates its features (an edge's line,
            // a face's plane): when the features really touch at an end of
            // one of them — an edge's interior resting on a corner — its
            // point can be separating while the material point at the
            // actual contact approaches. The search skipped such a contact
            // for 1e-8 s at a time while it sank, a hundred thousand times
            // (scissors settling on the coatrack's lip). The actual contact
            // point on b's tangent plane takes the impulse then.
            let at_contact = |s: &BodyState, p: &Vec3| s.v + s.w.cross(&(p - s.x));
            let vb = sb.map_or(Vec3::zeros(), |s| at_contact(&s, &contact.point_b));
            if n.dot(&(at_contact(&sa, &contact.point_a) - vb)) < 0.0 {
                let tangent = feature.on_tangent_plane(&sa.pose(), &pose_b, contact);
                ctx.feature = tangent.clone();
                let r2 = ctx.apply();
                if r2.approach < 0.0 {
                    feature = tangent;
                    res = r2;
                } else {
                    ctx.feature = feature.clone();
                }
            }
        }
        if res.approach >= 0.0 && ctx.normal_dev.is_some() {
            // The bodies approach along the contact's normal, but the
            // controlled normal is tilted so far that they separate along
            // it: no impulse could keep them apart. Refuse (a solver trial
            // fails; an edit is refused) rather than let them sink.
            let at = |s: &BodyState, p: &Vec3| s.v + s.w.cross(&(p - s.x));
            let vb = sb.map_or(Vec3::zeros(), |s| at(&s, &contact.point_b));
            if n.dot(&(at(&sa, &contact.point_a) - vb)) < 0.0 {
                return Err(SimError::NormalAwayFromApproach {
                    event: index,
                    t: tc,
                });
            }
        }
        if res.approach >= 0.0 {
            // Touching without approaching (a graze at the root): no impulse;
            // resume this pair's search just past the contact.
            let v = res.separation.abs().max(1e-3);
            self.pairs[k].hold = tc + (10.0 * self.tol.root / v).max(1e-12 * tc.abs().max(1.0));
            let p = &mut self.pairs[k];
            if p.skips == 0 || tc - p.skipped_since > super::events::SKIP_SPAN {
                p.skips = 0;
                p.skipped_since = tc;
            }
            p.skips += 1;
            if p.skips > super::events::MAX_SKIPS {
                return Err(SimError::EventSearchStalled {
                    a: self.scene.bodies[a].name.clone(),
                    b: self.party_name(pair.b),
                    t: tc,
                });
            }
            return Ok(());
        }
        self.pairs[k].skips = 0;
        self.pairs[k].hold = tc;
        self.check_sustained(k, tc)?;
        // How the bounce ends (rest, slide, or on bouncing; see `sim::rest`).
        let mode = match pair.b {
            Party::Obstacle(o) => {
                let post = BodyState {
                    v: res.va,
                    w: res.wa,
                    ..sa
                };
                let (v_rest, band) = rest::thresholds(
                    scene,
                    &self.traj.dynamics[a],
                    &self.traj.gravity,
                    self.tol.arm,
                );
                rest::decide(&rest::Impact {
                    scene,
                    dynamics: &self.traj.dynamics[a],
                    gravity: self.traj.gravity,
                    body: a,
                    obstacle: o,
                    post,
                    band,
                    v_rest,
                })
            }
            Party::Body(_) => Mode::Bounce,
        };
        let rest = mode == Mode::Rest;
        let mut micro = false;
        let v_min = rest::thresholds(
            scene,
            &self.traj.dynamics[a],
            &self.traj.gravity,
            self.tol.arm,
        )
        .0;
        if mode == Mode::Bounce
            && matches!(pair.b, Party::Obstacle(_))
            && res.separation < v_min
            && -res.approach < rest::MICRO * v_min
        {
            // A micro-collision: elastic, or at least `v_min` (bounded
            // chatter instead of a Zeno series; see `sim::rest`).
            ctx.min_separation = Some(v_min);
            res = ctx.apply();
            micro = true;
        }
        let mut post_a = BodyState {
            v: res.va,
            w: res.wa,
            ..sa
        };
        let mut slide: Option<Slide> = None;
        match &mode {
            Mode::Rest => {
                post_a.v = Vec3::zeros();
                post_a.w = Vec3::zeros();
            }
            Mode::Slide {
                slide: sl,
                proj_v,
                proj_w,
            } => {
                post_a.v = proj_v * post_a.v;
                post_a.w = proj_w * post_a.w;
                slide = Some(*sl);
            }
            Mode::Bounce => {}
        }
        let post_b = sb.map(|s| BodyState {
            v: res.vb,
            w: res.wb,
            ..s
        });
        for (i, s) in [(Some(a), Some(post_a)), (pair.b_body(), post_b)] {
            if let (Some(i), Some(s)) = (i, s)
                && !s.is_finite()
            {
                return Err(SimError::NonFinite {
                    body: scene.bodies[i].name.clone(),
                    t: tc,
                });
            }
        }
        let g_n = -self.traj.gravity.dot(&n);
        let rest_time = (rest || slide.is_some()).then(|| {
            if restitution < 1.0 && g_n > 0.0 {
                tc + 2.0 * res.separation.max(0.0) / (g_n * (1.0 - restitution))
            } else {
                tc
            }
        });
        // Tangents through the impulse.
        let m = self.traj.m;
        let mut ja = DMatrix::zeros(12, m);
        let mut jb = DMatrix::zeros(12, m);
        let mut dt_du = None;
        let mut graze_ratio = f64::NAN;
        let mut grazing = false;
        let b_body = pair.b_body();
        let lost = self.traj.tangent_lost[a].or(b_body.and_then(|j| self.traj.tangent_lost[j]));
        if let (true, Some((_, e))) = (self.traj.tangent, lost) {
            // One party's Jacobians are already lost: the collision takes
            // the other's from now on.
            for body in std::iter::once(a).chain(b_body) {
                self.traj.tangent_lost[body].get_or_insert((tc, e));
            }
        } else if self.traj.tangent {
            match self.saltation(
                tc,
                index,
                pair,
                &sa,
                sb.as_ref(),
                &post_a,
                post_b.as_ref(),
                &mode,
                &ctx,
            ) {
                Ok((jpost, dt, ratio)) => {
                    graze_ratio = ratio;
                    ja.copy_from(&jpost.rows(0, 12));
                    if jpost.nrows() == 24 {
                        jb.copy_from(&jpost.rows(12, 12));
                    }
                    dt_du = Some(dt);
                }
                Err((e, ratio)) => {
                    graze_ratio = ratio;
                    grazing = matches!(e, TangentError::Grazing { .. });
                    self.traj.diagnostics.push(e.to_string());
                    self.traj.tangent_error.get_or_insert(e);
                    for body in std::iter::once(a).chain(b_body) {
                        self.traj.tangent_lost[body] = Some((e.time(), e));
                    }
                }
            }
        }
        // A contact on a surface beyond the finite numbers (a parabola of
        // curvature 1e308) gives a NaN normal: a typed error, never an
        // event of NaNs in the report.
        let finite = |v: &Vec3| v.iter().all(|x| x.is_finite());
        let all_finite = finite(&res.normal)
            && finite(&res.point)
            && res.approach.is_finite()
            && finite(&post_a.v)
            && finite(&post_a.w);
        if !all_finite {
            return Err(SimError::NonFinite {
                body: body_a.name.clone(),
                t: tc,
            });
        }
        let event = Event {
            index,
            t: tc,
            a,
            b: pair.b,
            key: feature.key(),
            simultaneous: feature.simultaneous(),
            feature,
            normal: res.normal,
            point: res.point,
            approach: res.approach,
            separation: if rest || slide.is_some() {
                0.0
            } else {
                res.separation
            },
            restitution,
            graze_ratio,
            grazing,
            rest,
            slide,
            micro,
            rest_time,
            friction: (friction > 0.0).then_some(ctx.mode),
            dt_du,
            pre: [sa, sb.unwrap_or(sa)],
            post: [post_a, post_b.unwrap_or(post_a)],
        };
        self.traj.events.push(event);
        self.start_segment(a, tc, post_a, ja, rest, slide);
        if let (Some(j), Some(s)) = (pair.b_body(), post_b) {
            self.start_segment(j, tc, s, jb, false, None);
        }
        Ok(())
    }

    /// The contact patch of an impact: when a flat face of either party
    /// lies in the contact plane (within [`PATCH_ANGLE`]) — an edge or face
    /// landing on a face, a face on an edge — the corners lying on it
    /// within twice the patch depth, each with its face (see
    /// [`crate::geometry::FeaturePair::at_patch`]), and the depth. Two
    /// curved (tessellated) surfaces never touch in a patch: their facets
    /// meet at angles. `a` is the body's index.
    #[allow(clippy::too_many_arguments)]
    fn patch(
        &self,
        a: usize,
        part_a: &crate::geometry::Part,
        sa: &BodyState,
        part_b: Option<&crate::geometry::Part>,
        pose_b: &Isometry3<f64>,
        contact: &crate::geometry::Contact,
    ) -> Option<(Vec<PatchCorner>, f64, (bool, Vec3))> {
        let part_b = part_b?;
        if !matches!(part_a.kind, PartKind::Convex { .. }) {
            return None;
        }
        let n = contact.normal;
        let pose_a = sa.pose();
        let cos = PATCH_ANGLE.cos();
        let flat_a = crate::geometry::flat_faces(part_a, &pose_a, &-n, cos);
        let flat_b = crate::geometry::flat_faces(part_b, pose_b, &n, cos);
        // The impulse takes the normal of b's flat face, or of a's; the one
        // closest to the contact normal.
        let closest = |faces: &[crate::geometry::FlatFace], dir: &Vec3| {
            faces
                .iter()
                .max_by(|x, y| x.normal.dot(dir).total_cmp(&y.normal.dot(dir)))
                .map(|f| f.normal)
        };
        let impulse_face = match (closest(&flat_b, &n), closest(&flat_a, &-n)) {
            (Some(m), _) => (false, pose_b.inverse_transform_vector(&m)),
            (None, Some(m)) => (true, pose_a.inverse_transform_vector(&m)),
            (None, None) => return None,
        };
        let depth = PATCH_DEPTH * self.traj.dynamics[a].reach;
        let band = 2.0 * depth;
        // A corner takes part when it is a vertex lying on the other
        // party's flat face, or where an edge lying on one party's flat
        // face crosses the other's edge. (Around a vertex touching a face
        // the edges rise away from it: their crossings are not contacts.)
        let face = |faces: &[crate::geometry::FlatFace], p: &Vec3, on_a: bool| {
            faces
                .iter()
                .find(|f| f.holds(p, band))
                .map(|f| (f.clone(), on_a))
        };
        let lying =
            |faces: &[crate::geometry::FlatFace], p: &Vec3, q: &Vec3, at: &Vec3, on_a: bool| {
                faces
                    .iter()
                    .find(|f| {
                        f.holds(at, band)
                            && (f.normal.dot(p) - f.offset).abs() <= band
                            && (f.normal.dot(q) - f.offset).abs() <= band
                    })
                    .map(|f| (f.clone(), on_a))
            };
        let world = |pose: &Isometry3<f64>, p: &Vec3| (pose * nalgebra::Point3::from(*p)).coords;
        let face_of = |c: &Corner, at: &Vec3| match c {
            Corner::A { .. } => face(&flat_b, at, false),
            Corner::B { p, .. } => face(&flat_a, &world(pose_b, p), true),
            Corner::Crossing { a: ea, b: eb, .. } => {
                let wa = ea.map(|p| world(&pose_a, &p));
                let wb = eb.map(|p| world(pose_b, &p));
                lying(&flat_b, &wa[0], &wa[1], at, false)
                    .or_else(|| lying(&flat_a, &wb[0], &wb[1], at, true))
            }
            Corner::Ball => None,
        };
        let near = crate::geometry::part_near_points(part_a, &pose_a, part_b, pose_b, band);
        let merge = 1e-9 * (1.0 + sa.x.norm());
        let mut seen: Vec<Vec3> = Vec::new();
        let mut corners = Vec::new();
        for p in near {
            if seen.iter().any(|c| (c - p.point).norm() <= merge) {
                continue;
            }
            if let Some((f, on_a)) = face_of(&p.corner, &p.point) {
                let owner = if on_a { &pose_a } else { pose_b };
                seen.push(p.point);
                corners.push(PatchCorner {
                    corner: p.corner,
                    face_on_a: on_a,
                    face_normal: owner.inverse_transform_vector(&f.normal),
                    face_point: owner
                        .inverse_transform_point(&nalgebra::Point3::from(f.normal * f.offset))
                        .coords,
                });
            }
        }
        (!corners.is_empty()).then_some((corners, depth, impulse_face))
    }

    /// Refuse a pair that chatters: many impacts in a tiny span of time.
    fn check_sustained(&self, k: usize, tc: f64) -> Result<(), SimError> {
        const COUNT: usize = 200;
        let pair = self.pairs[k];
        let recent: Vec<f64> = self
            .traj
            .events
            .iter()
            .rev()
            .filter(|e| e.a == pair.a && e.b == pair.b)
            .take(COUNT)
            .map(|e| e.t)
            .collect();
        if recent.len() == COUNT {
            let span = tc - recent[COUNT - 1];
            if span < 1e-3 * self.scene.duration.max(1e-3) {
                let name = |p: Party| match p {
                    Party::Body(i) => self.scene.bodies[i].name.clone(),
                    Party::Obstacle(i) => self.scene.obstacles[i].name.clone(),
                };
                return Err(SimError::SustainedContact {
                    a: name(Party::Body(pair.a)),
                    b: name(pair.b),
                    t: recent[COUNT - 1],
                    count: COUNT,
                    span,
                });
            }
        }
        Ok(())
    }

    fn start_segment(
        &mut self,
        i: usize,
        t0: f64,
        start: BodyState,
        j0: DMatrix<f64>,
        rest: bool,
        slide: Option<Slide>,
    ) {
        let columns = rotation_columns(&self.opts, &j0, self.controls, i);
        self.forget_searches(i);
        self.traj.tracks[i].segments.push(Segment {
            t0,
            start,
            j0,
            rest,
            slide,
            steps: Vec::new(),
        });
        // Resting and sliding bodies move in closed form: nothing to integrate.
        self.cursors[i] =
            (self.traj.dynamics[i].integrate && !rest && slide.is_none()).then(|| {
                Cursor::new(
                    start.q,
                    integrator::initial(&(start.q.inverse() * start.w), columns),
                )
            });
    }

    /// `J⁺ = Φ_q J⁻ + Φ_u + (Φ_q F⁻ − F⁺) dt_c/du` with
    /// `dt_c/du = −E_q J⁻ / (E_q F⁻)`.
    #[allow(clippy::too_many_arguments)]
    fn saltation(
        &self,
        tc: f64,
        index: usize,
        pair: Pair,
        sa: &BodyState,
        sb: Option<&BodyState>,
        post_a: &BodyState,
        post_b: Option<&BodyState>,
        mode: &Mode,
        ctx: &ImpulseCtx,
    ) -> Result<Saltation, (TangentError, f64)> {
        let m = self.traj.m;
        let a = pair.a;
        let ns = if sb.is_some() { 24 } else { 12 };
        let nonfinite = |ratio| (TangentError::NonFinite { t: tc }, ratio);
        let mut jpre = DMatrix::zeros(ns, m);
        jpre.rows_mut(0, 12).copy_from(
            &self
                .traj
                .jacobian(a, tc, StateSide::After)
                .map_err(|e| (e, f64::NAN))?,
        );
        let mut fpre = DVector::zeros(ns);
        fpre.rows_mut(0, 12)
            .copy_from(&self.traj.flow(a, sa, false));
        let mut fpost = DVector::zeros(ns);
        let post_flow = match mode {
            Mode::Rest => DVector::zeros(12),
            Mode::Slide { slide, .. } => {
                let f = slide.flow(post_a, self.traj.dynamics[a].drag_k);
                DVector::from_iterator(12, f.iter().flat_map(|v| v.iter().cloned()))
            }
            Mode::Bounce => self.traj.flow(a, post_a, false),
        };
        fpost.rows_mut(0, 12).copy_from(&post_flow);
        if let (Some(j), Some(sb), Some(pb)) = (pair.b_body(), sb, post_b) {
            jpre.rows_mut(12, 12).copy_from(
                &self
                    .traj
                    .jacobian(j, tc, StateSide::After)
                    .map_err(|e| (e, f64::NAN))?,
            );
            fpre.rows_mut(12, 12)
                .copy_from(&self.traj.flow(j, sb, false));
            fpost
                .rows_mut(12, 12)
                .copy_from(&self.traj.flow(j, pb, false));
        }
        // Φ_u: event parameters, masses and inertias.
        let p0 = ctx.param_offset();
        let mut params: Vec<(usize, usize)> = Vec::new();
        let (normal_col, rest_col) = self.controls.event_columns(index);
        if let Some(c) = normal_col.filter(|_| self.opts.tangent) {
            params.push((p0, c));
            params.push((p0 + 1, c + 1));
        }
        if let Some(c) = rest_col.filter(|_| self.opts.tangent) {
            params.push((p0 + 2, c));
        }
        if let Some(c) = self.traj.mass_cols[a] {
            params.push((p0 + 3, c));
        }
        if let Some(c) = self.traj.inertia_cols[a] {
            for k in 0..3 {
                params.push((p0 + 4 + k, c + k));
            }
        }
        if let Some(j) = pair.b_body() {
            if let Some(c) = self.traj.mass_cols[j] {
                params.push((p0 + 7, c));
            }
            if let Some(c) = self.traj.inertia_cols[j] {
                for k in 0..3 {
                    params.push((p0 + 8 + k, c + k));
                }
            }
        }
        let jac = ctx.jacobian_with(params.iter().any(|&(_, c)| c < m));
        // The event function's gradient E_q: that of the touching features,
        // or, where two or more corners of a patch touch at once, each of
        // theirs. A flat landing like that (a level plank's end face meeting
        // a support's edge) has an event time `min_i t_i(u)` with a kink,
        // and the feature pair the search happened to end on gives one of
        // its one-sided derivatives at best (a vertex–vertex pair at zero
        // distance has no normal at all), so the tangent would depend on
        // the search's steps. The corners give every one-sided derivative;
        // separating corners do not bound the event.
        let dot =
            |e: &[f64], f: &DVector<f64>| e.iter().zip(f.iter()).map(|(e, f)| e * f).sum::<f64>();
        let mut rows: Vec<(Vec<f64>, f64)> = ctx
            .touching_corners(10.0 * self.tol.root)
            .into_iter()
            .map(|row| {
                let den = dot(&row, &fpre);
                (row, den)
            })
            .filter(|(_, den)| *den < 0.0)
            .collect();
        if rows.len() < 2 {
            // No kink: the touching features, as the search found them.
            rows.clear();
            let eq: Vec<f64> = jac.view((0, 0), (1, ns)).iter().copied().collect();
            let den = dot(&eq, &fpre);
            rows.push((eq, den));
        }
        // Grazing measure: the cosine between E_q and the configuration part
        // of F (velocities; E does not depend on them, so including the
        // accelerations would only mix units into the ratio), the smallest
        // of the touching corners'.
        let config: f64 = (0..ns)
            .filter(|r| r % 12 < 6)
            .map(|r| fpre[r] * fpre[r])
            .sum::<f64>()
            .sqrt();
        let ratios: Vec<f64> = rows
            .iter()
            .map(|(e, den)| den.abs() / (e.iter().map(|v| v * v).sum::<f64>().sqrt() * config))
            .collect();
        let ratio = ratios.iter().copied().fold(f64::INFINITY, f64::min);
        if !ratios.iter().all(|r| r.is_finite()) {
            return Err(nonfinite(ratio));
        }
        if ratio < self.opts.graze_tol {
            return Err((
                TangentError::Grazing {
                    event: index,
                    t: tc,
                    ratio,
                },
                ratio,
            ));
        }
        // dt_c/du = −E_q J⁻ / (E_q F⁻), 1 × m; at a kink, column by column
        // the midpoint of the extreme one-sided derivatives: what central
        // differences converge to, whichever corner the search named.
        let dt: Vec<f64> = (0..m)
            .map(|c| {
                let (lo, hi) = rows
                    .iter()
                    .map(|(e, den)| {
                        -e.iter()
                            .zip(jpre.column(c).iter())
                            .map(|(e, j)| e * j)
                            .sum::<f64>()
                            / den
                    })
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
                        (lo.min(s), hi.max(s))
                    });
                0.5 * (lo + hi)
            })
            .collect();
        // Φ_q is the identity but for the velocity rows of each body (the
        // impulse changes velocities, not positions): only those rows of
        // Φ_q J⁻ and Φ_q F⁻ need a product. J⁻ becomes J⁺ in place, one
        // column at a time (each column's new rows read only that column).
        let velocity_rows: &[(usize, usize)] = if ns == 24 {
            &[(6, 1), (18, 7)]
        } else {
            &[(6, 1)]
        };
        let phi = |row: usize, x: &[f64]| -> f64 {
            x.iter().enumerate().map(|(k, v)| jac[(row, k)] * v).sum()
        };
        let mut mismatch = &fpre - &fpost; // Φ_q F⁻ − F⁺
        for &(row, jac_row) in velocity_rows {
            for i in 0..6 {
                mismatch[row + i] += phi(jac_row + i, fpre.as_slice()) - fpre[row + i];
            }
        }
        let mut jpost = jpre;
        let mut rows = [0.0; 12];
        for c in 0..m {
            for (b, &(_, jac_row)) in velocity_rows.iter().enumerate() {
                for i in 0..6 {
                    rows[6 * b + i] = phi(jac_row + i, jpost.column(c).as_slice());
                }
            }
            for (b, &(row, _)) in velocity_rows.iter().enumerate() {
                for i in 0..6 {
                    jpost[(row + i, c)] = rows[6 * b + i];
                }
            }
            for r in 0..ns {
                jpost[(r, c)] += mismatch[r] * dt[c];
            }
        }
        for (p, c) in params {
            if c >= m {
                continue;
            }
            for r in 0..6 {
                jpost[(6 + r, c)] += jac[(1 + r, p)];
                if ns == 24 {
                    jpost[(18 + r, c)] += jac[(7 + r, p)];
                }
            }
        }
        // Rest and slide project the post-impulse velocities; their flows
        // already lie in the projections' ranges, so projecting the rows
        // of J⁺ is the exact derivative of the composed map.
        match mode {
            Mode::Rest => jpost.rows_mut(6, 6).fill(0.0),
            Mode::Slide { proj_v, proj_w, .. } => {
                let jv = proj_v * jpost.rows(6, 3);
                let jw = proj_w * jpost.rows(9, 3);
                jpost.rows_mut(6, 3).copy_from(&jv);
                jpost.rows_mut(9, 3).copy_from(&jw);
            }
            Mode::Bounce => {}
        }
        if !jpost.iter().chain(dt.iter()).all(|v| v.is_finite()) {
            return Err(nonfinite(ratio));
        }
        Ok((jpost, DVector::from_vec(dt), ratio))
    }
}

impl Pair {
    fn b_body(&self) -> Option<usize> {
        match self.b {
            Party::Body(j) => Some(j),
            Party::Obstacle(_) => None,
        }
    }
}
