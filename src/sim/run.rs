//! The simulation loop: windows of integration, event search, impulses and
//! the saltation update of the Jacobian at every impulse (docs/design.md §5).

use super::dynamics::BodyDynamics;
use super::events::{Pair, Tolerances, World};
use super::impulse::{FrictionMode, ImpulseCtx, PartyCtx};
use super::integrator::{self, Step};
use super::rest::{self, Mode, Slide};
use super::state::{BodyState, Side};
use super::trajectory::{Counters, Event, Party, Segment, TangentError, Track, Trajectory};
use crate::controls::Controls;
use crate::geometry::{Corner, FeaturePair, PartKind, PatchCorner};
use crate::math::{Vec3, exp_so3, left_jacobian};
use crate::scene::{Block, Method, Scene};
use nalgebra::{DMatrix, DVector, Isometry3, Translation3, UnitQuaternion};

mod bound;
mod impact;
mod islands;
mod pivot;
mod roll;
mod saltation;
mod slide;
mod sustained;

use super::error::MAX_SUBSTEPS;
pub use super::error::{SimError, SimOptions};
use bound::ObstacleBound;

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
    obstacle_bounds: Vec<ObstacleBound>,
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
                pivot: None,
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
                    push: false,
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
                push: false,
            });
        }
    }
    if scene.effects.collisions {
        starts_apart(scene)?;
    }
    let obstacle_bounds: Vec<ObstacleBound> =
        scene.obstacles.iter().map(ObstacleBound::of).collect();
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
        obstacle_bounds,
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
            // A pivot that ends (lands, lifts off, slips) or a slide that
            // reaches its face's edge ends the window.
            let pivot_end = self.next_contact_end().filter(|(te, _)| *te < t + win);
            let end = pivot_end.map_or(t + win, |(te, _)| te.max(t)).min(duration);
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
            // so the next events' windows find their searches done. Not
            // past a pivot's or a face slide's end: there its motion stops
            // (held at the end pose) while its velocity does not, and a
            // search's Newton probe beyond it could not bracket a root.
            let ahead = if self.cursors.iter().any(Option::is_some) {
                end
            } else {
                let stop = self.next_contact_end().map_or(duration, |(te, _)| te);
                (end + window).min(duration).min(stop.max(end))
            };
            let found = self.next_impact(t, end, ahead)?;
            // A sliding ball that stops slipping first: the switch is an
            // event (run/roll.rs), and the search goes on from there.
            if let Some((ts, i)) = self.next_switch(found.as_ref().map_or(end, |f| f.0)) {
                self.roll_switch(ts, i)?;
                t = ts;
                if self.traj.events.len() > self.opts.max_events {
                    return Err(SimError::TooManyEvents {
                        limit: self.opts.max_events,
                        t,
                    });
                }
                continue;
            }
            match found {
                None if pivot_end.is_some_and(|(te, _)| te <= end) => {
                    let (te, i) = pivot_end.unwrap_or((end, 0));
                    self.truncate(te);
                    frontier = te;
                    self.end_contact(te, i)?;
                    t = te;
                }
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
            if !self.traj.state(i, duration, Side::Post).is_finite() {
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
        let frozen: Vec<bool> = (0..n).map(|i| self.frozen(i)).collect();
        // Sweep and prune on x for body–body pairs (not quadratic in N).
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by(|&a, &b| boxes[a].0.x.total_cmp(&boxes[b].0.x));
        let mut close: Vec<usize> = Vec::new();
        let mut active: Vec<usize> = Vec::new();
        for &i in &order {
            active.retain(|&j| boxes[j].1.x >= boxes[i].0.x);
            for &j in &active {
                let key = (i.min(j), i.max(j));
                // Two frozen bodies never meet: their pair is not searched.
                if let Some(&k) = self.body_pairs.get(&key)
                    && bound::overlap(&boxes[i], &boxes[j])
                    && !(frozen[i] && frozen[j])
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
                    !self.traj.supported_by(a, t0, o) && self.obstacle_bounds[o].may_meet(&boxes[a])
                }
                Party::Body(_) => false,
            })
            .collect();
        candidates.extend(close);
        candidates.sort_unstable();
        let mut best: Option<(f64, usize, crate::geometry::Contact, bool)> = None;
        for k in candidates {
            let p = &self.pairs[k];
            let limit = best.as_ref().map_or(t1, |b| b.0);
            // A search that creeps (or crawls to a stall) at `t` inside the
            // window: the sustained contact is pushed apart there
            // (run/sustained.rs); without a micro-collision floor the stall
            // stops the run.
            let stall = |t| self.stall(&world, p, t);
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
                Ok(found) => Ok((found, ahead, false)),
                Err(t) if t > t1 => Ok((None, t, false)),
                Err(t) => stall(t).map(|hit| (Some(hit), t, true)),
            };
            // A push is never cached: the pair's search runs afresh.
            let keep = |found: Option<(f64, crate::geometry::Contact)>, push: bool| {
                (!push).then_some(found)
            };
            let (found, push) = match cached {
                Some(Searched {
                    hit: Some((tc, c)), ..
                }) if tc >= t0 => (Some((tc, c)), false),
                Some(s) if s.hit.is_none() && s.until >= t1 => (None, false),
                Some(s) if s.hit.is_none() => {
                    let (found, until, push) = ahead_from(s.until)?;
                    self.searched[k] = keep(found, push).map(|hit| Searched { until, hit, ..s });
                    (found, push)
                }
                _ if p.armed => {
                    let (found, until, push) = ahead_from(t0)?;
                    self.searched[k] = keep(found, push).map(|hit| Searched {
                        from: t0,
                        until,
                        hit,
                    });
                    (found, push)
                }
                _ => match world.find_impact(p, t0, limit, &self.tol) {
                    Ok(found) => (found, false),
                    Err(t) => (Some(stall(t)?), true),
                },
            };
            if let Some((tc, c)) = found.filter(|(tc, _)| *tc <= limit)
                && best.as_ref().is_none_or(|b| tc < b.0)
            {
                best = Some((tc, k, c, push));
            }
        }
        Ok(best.map(|(tc, k, c, push)| {
            self.pairs[k].push = push;
            (tc, k, c)
        }))
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
