//! Pivoting on an edge: a sustained contact along a line of support with
//! sticking friction, moved as a hinge (one degree of freedom).
//!
//! A body standing on an edge (a box tipped onto an edge, scissors landed
//! on the edge of their blades and handle) turns about that edge while
//! gravity topples it or rocks it back. As impacts only, that motion is a
//! train of micro-collisions at the edge (`sim::rest`, rule 3), each a hop
//! of at least `2 v_r / g`: some 250 events for the scissors of
//! `scenes/scissors-bounce.toml` toppling over on the peg in 0.22 s.
//!
//! When an impact against an obstacle falls in the Zeno regime and the
//! body's support points on that obstacle lie on one line ([`Pivot::enter`]),
//! the body pivots instead: the contact line is fixed, the body keeps only
//! its rotation about it — a plastic impact of the whole edge, which keeps
//! the angular momentum about the line, `θ̇ = a·H_p / I_a` with `H_p` the
//! momentum about a point of the line and `I_a = aᵀ I_p a` the inertia about
//! it (constant while it turns about the line) — and turns by
//! `I_a θ̈ = a·(r(θ) × m g)`, a pendulum integrated by fixed-step RK4 (step
//! [`STEP`]) when the pivot starts, up to its end:
//!
//! - **lands**: a body point off the line reaches the plane of the contact
//!   (the body rolls onto a face): an ordinary impact there;
//! - **lifts off**: the normal force at either end of the line (from the
//!   hinge's force and moment balance) would turn negative;
//! - **slips**: the tangential force leaves the friction cone (taken on the
//!   total contact force);
//! - or the simulation ends.
//!
//! After lift-off or slip the body flies on freely from the same state.
//! Energy is conserved within the pivot (the hinge does no work); it is
//! lost only at the impact that starts it. While pivoting, the part the
//! body turns on is not searched: the landing is found on the contact
//! plane (a half-space, or the face the edge lies on, taken as unbounded),
//! and that part must lie below it. On a face, the landing point must be
//! over the face's polygon, or there is no pivot (beyond the face's edge
//! the body would swing on below the plane). The obstacle's other parts (a shelf's
//! lip, the pole of a coatrack) are searched as usual when they come near
//! the space the body sweeps, and a contact with one ends the pivot in an
//! impact; when none comes near, the pair is not searched at all. The body's
//! Jacobian is lost from the pivot on (`TangentError::Contact`): the start
//! and end times jump with the controls and the hinge's tangent is not
//! propagated.
//!
//! When friction cannot hold the line still (the hinge slips at once), the
//! impact starts a skid instead ([`Pivot::enter_skid`], `pivot::skid`): the
//! line's ends slide on the plane under Coulomb friction while the body
//! turns freely; it ends like a hinge, when the ends stop slipping (the
//! hinge takes over), or, on a face of a hull, when an end slides off the
//! face. A body on a single slipping corner skids on that corner, and one
//! on a corner that friction holds turns about it, pinned (a ball joint).
//! A body lying on a face with its centre of mass beyond its supports
//! topples over their hull's edge as a hinge (`pivot::topple`). A body
//! whose only two supports lie on surfaces with different normals (a rod
//! in the corner of a floor and a wall) leans: it turns about the line
//! through them as a hinge, held by friction at both ends (`pivot::lean`).
//! A body chattering where none of these applies (on two obstacles, on an
//! edge crossing an edge) is time-stepped on all its contacts instead
//! (`pivot::stepped`).

mod clear;
mod lean;
mod skid;
pub(crate) mod stepped;
pub(crate) mod topple;
mod turning;

use super::dynamics::BodyDynamics;
use super::state::BodyState;
use crate::geometry::{NearPoint, PartKind, flat_faces};
use crate::math::{Vec3, exp_so3};
use crate::scene::Scene;
use clear::{Boxes, Clear};
pub use lean::Lean;
pub use skid::Skid;
pub use stepped::Stepped;
use turning::{Hinge, Landing, Turn};

/// Integration step of the hinge angle, s.
pub const STEP: f64 = 1e-4;

/// Why a pivot ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PivotEnd {
    /// A body point off the line reaches the contact plane: an impact.
    Lands,
    /// A normal force at the line's ends would pull: free flight.
    LiftsOff,
    /// The friction cone is left: free flight (micro-collisions again).
    Slips,
    /// A skid's slipping ends stop slipping: the hinge takes over if it
    /// holds, else free flight.
    Sticks,
    /// A skid's end slides off the face of the hull it skids on: free
    /// flight (the body tips over the face's edge).
    OffFace,
    /// A stepped body comes to rest (`pivot::stepped`).
    Rests,
    /// The simulation ends first.
    Duration,
}

/// A body turning about a fixed line of support (see the module notes).
#[derive(Debug, Clone, PartialEq)]
pub struct Pivot {
    /// The supporting obstacle (its pair is not searched while pivoting)
    /// and the part of it that the line lies on.
    pub obstacle: usize,
    pub part: usize,
    /// A point of the line, world, m (the first support end).
    pub point: Vec3,
    /// Unit direction of the line.
    pub axis: Vec3,
    /// Unit contact normal, out of the obstacle.
    pub normal: Vec3,
    /// The other end of the support, along `axis` from `point`, m.
    pub length: f64,
    /// How the body moves: turning about the fixed line, or skidding.
    motion: Motion,
    /// Duration of the pivot, s, and why it ends.
    pub duration: f64,
    pub end: PivotEnd,
    /// At a landing: the body point that lands (its part, and its offset
    /// from the centre of mass in the body frame).
    pub landing: Option<(usize, Vec3)>,
    /// The line's far end touches another surface, with another normal
    /// (`pivot::lean`): its part and normal; and whether the body lands on
    /// that surface's plane rather than on the first.
    pub lean: Option<Lean>,
    pub lands_on_lean: bool,
    /// Whether other parts of the obstacle come near the space the body
    /// sweeps: the pair is then searched, without the part it turns on.
    pub beside: bool,
    /// Bounds over the pivot: speed of the centre of mass (a skid's; a
    /// hinge's is in `w_max`), spin, angular acceleration and the
    /// acceleration of the centre of mass (m/s, rad/s, rad/s², m/s²).
    pub v_max: f64,
    pub w_max: f64,
    pub alpha_max: f64,
    pub accel_max: f64,
}

/// The two motions of a pivot.
#[derive(Debug, Clone, PartialEq)]
enum Motion {
    /// About the fixed line (friction holds it).
    Hinge(Turn),
    /// The line slides on a plane (see `pivot::skid`).
    Skid(Box<Skid>),
    /// Time-stepped on all its contacts (see `pivot::stepped`).
    Stepped(Box<Stepped>),
}

/// Everything [`Pivot::enter`] needs about the impact.
pub(crate) struct PivotStart<'a> {
    pub scene: &'a Scene,
    pub dynamics: &'a BodyDynamics,
    pub gravity: Vec3,
    pub body: usize,
    pub obstacle: usize,
    pub part: usize,
    /// Post-impulse state (ordinary impulse).
    pub post: BodyState,
    /// Support points on the obstacle (within the support band).
    pub supports: &'a [NearPoint],
    /// Friction coefficient of the pair.
    pub friction: f64,
    /// Longest the pivot may last, s.
    pub horizon: f64,
    /// The rest speed in force for the body, m/s: a skid's ends stick
    /// below it.
    pub v_rest: f64,
    /// The line is the edge of the support polygon of a body lying on a
    /// face, toppling over it (`pivot::topple`): the plastic impact of the
    /// whole patch stops any turn back onto it.
    pub topple: bool,
    /// The supports are two points whose surfaces have different normals
    /// (`pivot::lean`): the second one's part and normal (`supports[1]`;
    /// `part` is the first one's).
    pub lean: Option<Lean>,
}

/// The line a body's support points make on one obstacle.
pub(crate) struct SupportLine {
    /// Its first end, unit direction, the contact normal and its length.
    point: Vec3,
    axis: Vec3,
    normal: Vec3,
    length: f64,
}

impl SupportLine {
    /// The line through `supports`, if there are two or more, with one
    /// normal, all within `1e-6 · reach` of the line through the two
    /// farthest apart (at least `1e-3 · reach` apart).
    pub(crate) fn of(supports: &[NearPoint], reach: f64) -> Option<SupportLine> {
        let first = supports.first()?;
        let n = first.normal;
        if supports.len() < 2 || supports.iter().any(|q| q.normal.dot(&n) < 1.0 - 1e-6) {
            return None;
        }
        let (mut i1, mut i2, mut far) = (0, 0, 0.0);
        for (i, a) in supports.iter().enumerate() {
            for (j, b) in supports.iter().enumerate().skip(i + 1) {
                let l = (a.point - b.point).norm();
                if l > far {
                    (i1, i2, far) = (i, j, l);
                }
            }
        }
        if far < 1e-3 * reach {
            return None;
        }
        let point = supports[i1].point;
        let axis = (supports[i2].point - point) / far;
        let off_line = |q: &Vec3| {
            let r = q - point;
            (r - axis * axis.dot(&r)).norm()
        };
        if supports.iter().any(|q| off_line(&q.point) > 1e-6 * reach) {
            return None;
        }
        Some(SupportLine {
            point,
            axis,
            normal: n,
            length: far,
        })
    }

    /// The line through two supports whose normals differ (`pivot::lean`;
    /// its normal is the first one's), at least `1e-3 · reach` apart.
    pub(crate) fn across(supports: &[NearPoint], reach: f64) -> Option<SupportLine> {
        let [a, b] = supports else {
            return None;
        };
        let far = (b.point - a.point).norm();
        (far >= 1e-3 * reach).then(|| SupportLine {
            point: a.point,
            axis: (b.point - a.point) / far,
            normal: a.normal,
            length: far,
        })
    }

    /// A single support corner as a line of no length (its axis any unit
    /// vector in the contact plane).
    pub(crate) fn corner(q: &NearPoint) -> SupportLine {
        let n = q.normal;
        let other = if n.x.abs() < 0.9 {
            Vec3::x()
        } else {
            Vec3::y()
        };
        SupportLine {
            point: q.point,
            axis: n.cross(&other).normalize(),
            normal: n,
            length: 0.0,
        }
    }
}

/// Body points of body `i`: part, offset from the centre of mass in the
/// body frame, radius (0 for hull vertices).
fn points(scene: &Scene, i: usize) -> Vec<(usize, Vec3, f64)> {
    let mut out = Vec::new();
    for (k, p) in scene.bodies[i].geometry.parts.iter().enumerate() {
        match &p.kind {
            PartKind::Ball { radius } => out.push((k, p.offset.translation.vector, *radius)),
            PartKind::Convex { .. } => out.extend(p.vertices().into_iter().map(|v| (k, v, 0.0))),
            _ => {}
        }
    }
    out
}

impl Pivot {
    /// The pivot that an impact in the Zeno regime starts, with the state
    /// it starts from, or `None` when the supports are not one line, do not
    /// hold the line in contact (lift-off or slip at once), or a point off
    /// the line already meets the plane.
    pub(crate) fn enter(p: &PivotStart<'_>) -> Option<(Pivot, BodyState)> {
        let g = p.gravity;
        let d = p.dynamics;
        let s = &p.post;
        if g.norm() == 0.0 || p.friction <= 0.0 {
            return None;
        }
        let SupportLine {
            point,
            axis,
            normal: n,
            length: far,
        } = match p.lean {
            Some(_) => SupportLine::across(p.supports, d.reach)?,
            None => SupportLine::of(p.supports, d.reach)?,
        };
        let tol = 1e-6 * d.reach;
        // Plastic impact of the whole line: keep the momentum about it.
        let rot = *s.q.to_rotation_matrix().matrix();
        let ic = rot * d.inertia * rot.transpose();
        let r0 = s.x - point;
        let ip =
            ic + (nalgebra::Matrix3::identity() * r0.norm_squared() - r0 * r0.transpose()) * d.mass;
        let i_a = axis.dot(&(ip * axis));
        let h_p = ic * s.w + r0.cross(&s.v) * d.mass;
        let rate = axis.dot(&h_p) / i_a;
        let r_perp = r0 - axis * axis.dot(&r0);
        let c_cos = d.mass * g.dot(&axis.cross(&r_perp)) / i_a;
        let c_sin = -d.mass * g.dot(&r_perp) / i_a;
        // Gravity turns the body the way `c_cos` (its pull at θ = 0)
        // points; a toppling body's patch takes any turn the other way.
        let rate = if p.topple && rate * c_cos < 0.0 {
            0.0
        } else {
            rate
        };
        let mut turn = Turn {
            q0: s.q,
            r0,
            c_cos,
            c_sin,
            table: vec![[0.0, rate]],
        };
        let mut pv = Pivot {
            obstacle: p.obstacle,
            part: p.part,
            point,
            axis,
            normal: n,
            length: far,
            // The turn so far; set again from `turn` at each end below.
            motion: Motion::Hinge(turn.clone()),
            duration: 0.0,
            end: PivotEnd::Duration,
            landing: None,
            lean: p.lean,
            lands_on_lean: false,
            beside: false,
            v_max: 0.0,
            w_max: rate.abs(),
            alpha_max: 0.0,
            accel_max: 0.0,
        };
        if pv
            .forces(&r0, &(ip * axis), turn.accel(0.0), rate, p)
            .is_some()
        {
            return None;
        }
        let all: Vec<(usize, Vec3, f64, Vec3)> = points(p.scene, p.body)
            .into_iter()
            .map(|(k, v, radius)| (k, v, radius, r0 + s.q * v))
            .collect();
        // Every point off the line starts on the outer side of the contact
        // plane (a body reaching down beside the support, a hat's brim
        // around a pole, is not on one face).
        let off: Vec<&(usize, Vec3, f64, Vec3)> = all
            .iter()
            .filter(|(.., r)| (r - axis * axis.dot(r)).norm() > tol)
            .collect();
        let low = |n: &Vec3, level: f64| {
            off.iter()
                .map(|(.., radius, r)| n.dot(r) - level - radius)
                .fold(f64::INFINITY, f64::min)
        };
        // Heights are from the line's point; leaning, the surfaces' own
        // planes are at `level` from it along their normals.
        let levels = p.lean.map(|l| l.levels(&n, &point));
        let level = levels.map_or(0.0, |[first, _]| first);
        let start_low = low(&n, level);
        if start_low < -tol {
            return None;
        }
        let floor = start_low.min(0.0) + level;
        let landing = Landing::new(&axis, &n, &off, floor);
        // Leaning, the far end's surface is a second plane to land on.
        let second = match p.lean.zip(levels) {
            Some((l, [_, level])) => {
                let start_low = low(&l.normal, level);
                if start_low < -tol {
                    return None;
                }
                Some(Landing::new(
                    &axis,
                    &l.normal,
                    &off,
                    start_low.min(0.0) + level,
                ))
            }
            None => None,
        };
        // The point that has landed at angle `th`, and whether on the
        // second plane.
        let crossed = |th: f64| {
            landing
                .crossed(th)
                .map(|q| (q, false))
                .or_else(|| second.as_ref()?.crossed(th).map(|q| (q, true)))
        };
        // Points move at most this far between two samples of the sweep.
        let reach = all
            .iter()
            .map(|(.., radius, r)| r.norm() + radius)
            .fold(0.0, f64::max);
        // The part turned on must lie below the contact plane already at
        // the start (the sweep's box only grows): refuse before integrating.
        if pv.clear(p, &pv.padded(&pv.sweep(&all, 0.0, 0.0), reach, p)) == Clear::Blocked {
            return None;
        }
        // The angles the body turns through (the sweep is their box).
        let (mut th_lo, mut th_hi) = (0.0_f64, 0.0_f64);
        let hinge = Hinge::new(&axis, &r0, &(ip * axis));
        let steps = (p.horizon / STEP).ceil().min(1e7) as usize;
        let (mut th, mut w) = (0.0, rate);
        for k in 0..steps {
            let h = STEP.min(p.horizon - k as f64 * STEP);
            let (th1, w1) = turn.rk4(th, w, h);
            let t1 = k as f64 * STEP + h;
            (th_lo, th_hi) = (th_lo.min(th1), th_hi.max(th1));
            pv.w_max = pv.w_max.max(w1.abs());
            let alpha = turn.accel(th1);
            pv.alpha_max = pv.alpha_max.max(alpha.abs());
            pv.accel_max = pv.accel_max.max((alpha.abs() + w1 * w1) * r0.norm());
            if let Some((point, on_lean)) = crossed(th1) {
                // Lands between the steps: bisect the step on the angle.
                let (mut lo, mut hi) = (0.0, h);
                for _ in 0..60 {
                    let mid = 0.5 * (lo + hi);
                    let (tm, _) = turn.rk4(th, w, mid);
                    if crossed(tm).is_some() {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                pv.duration = k as f64 * STEP + hi;
                pv.end = PivotEnd::Lands;
                pv.landing = Some(point);
                pv.lands_on_lean = on_lean;
                let swept = pv.sweep(&all, th_lo, th_hi);
                pv.motion = Motion::Hinge(turn);
                return pv.started(s, p, &swept, reach);
            }
            let (r1, ipa1) = hinge.at(th1);
            if let Some(end) = pv.forces(&r1, &ipa1, turn.accel(th1), w1, p) {
                pv.duration = t1;
                pv.end = end;
                turn.table.push([th1, w1]);
                let swept = pv.sweep(&all, th_lo, th_hi);
                pv.motion = Motion::Hinge(turn);
                return pv.started(s, p, &swept, reach);
            }
            (th, w) = (th1, w1);
            turn.table.push([th, w]);
        }
        pv.duration = p.horizon;
        let swept = pv.sweep(&all, th_lo, th_hi);
        pv.motion = Motion::Hinge(turn);
        pv.started(s, p, &swept, reach)
    }

    /// The pivot and its start, unless it lands within its first step or
    /// the part turned on rises into its sweep (other parts there mark it
    /// [`Pivot::beside`]).
    fn started(
        mut self,
        s: &BodyState,
        p: &PivotStart<'_>,
        swept: &Boxes,
        reach: f64,
    ) -> Option<(Pivot, BodyState)> {
        // A landing within the first step is an impact of two supports at
        // once, not a pivot: it stays a micro-collision.
        if self.end == PivotEnd::Lands && self.duration < STEP {
            return None;
        }
        // The landing is found on the contact plane; on a face of a hull it
        // must be over the face (beyond its edge the body swings on past
        // the plane, which this hinge does not follow).
        if let (PivotEnd::Lands, Some((_, v))) = (self.end, self.landing) {
            let o = &p.scene.obstacles[p.obstacle];
            let (part, normal) = match self.lean {
                Some(l) if self.lands_on_lean => (l.part, l.normal),
                _ => (p.part, self.normal),
            };
            let face = o.geometry.parts.get(part).and_then(|part| {
                flat_faces(part, &o.pose, &normal, 1.0 - 1e-6)
                    .into_iter()
                    .next()
            });
            let at = self.at(self.duration).point(&v);
            if face.is_none_or(|f| f.depth(&at) < 0.0) {
                return None;
            }
        }
        match self.clear(p, &self.padded(swept, reach, p)) {
            Clear::Blocked => return None,
            Clear::Beside => self.beside = true,
            Clear::Free => {}
        }
        let start = self.at(0.0);
        debug_assert!((start.x - s.x).norm() <= 1e-9 * (1.0 + s.x.norm()));
        Some((self, start))
    }

    /// The speed of the body's points at most, m/s, the centre of mass
    /// being at `x`, points within `reach` of it.
    pub fn speed_bound(&self, x: &Vec3, reach: f64) -> f64 {
        match self.motion {
            Motion::Hinge(_) => self.w_max * ((x - self.point).norm() + reach),
            Motion::Skid(_) | Motion::Stepped(_) => self.v_max + self.w_max * reach,
        }
    }

    /// Whether the line slides (a skid) rather than staying put (a hinge,
    /// or a pinned corner).
    pub fn skids(&self) -> bool {
        matches!(&self.motion, Motion::Skid(skid) if !skid.pinned)
    }

    /// Whether the body turns about a corner pinned by friction (a ball
    /// joint; `pivot::skid`).
    pub fn pinned(&self) -> bool {
        matches!(&self.motion, Motion::Skid(skid) if skid.pinned)
    }

    /// Whether the hinge stops holding at angle `th`, rate `w`, with the
    /// centre of mass at `r` from `point` and `ipa` the inertia about
    /// `point` applied to the axis (`I_p a`): a normal force at an end of
    /// the line below zero, or the total force outside the friction cone.
    fn forces(
        &self,
        r: &Vec3,
        ipa: &Vec3,
        accel: f64,
        w: f64,
        p: &PivotStart<'_>,
    ) -> Option<PivotEnd> {
        let (d, friction, g) = (p.dynamics, p.friction, &p.gravity);
        let a = self.axis;
        let alpha = a * accel;
        let omega = a * w;
        let acc = alpha.cross(r) + omega.cross(&omega.cross(r));
        // Contact force and moment about `point` that keep the hinge
        // (`I_p α + ω × I_p ω` with `α`, `ω` along the axis).
        let f = (acc - g) * d.mass;
        let m = ipa * accel + omega.cross(&(ipa * w)) - r.cross(&(g * d.mass));
        let n = self.normal;
        let scale = 1e-9 * d.mass * g.norm();
        if let Some(l) = self.lean {
            return lean::fails(&f, &m, &a, self.length, [&n, &l.normal], friction, scale);
        }
        let fn_total = f.dot(&n);
        let n2 = m.dot(&a.cross(&n)) / self.length;
        let n1 = fn_total - n2;
        if n1 < -scale || n2 < -scale {
            return Some(PivotEnd::LiftsOff);
        }
        if (f - n * fn_total).norm() > friction * fn_total + scale {
            return Some(PivotEnd::Slips);
        }
        None
    }

    /// The body's state `tau` seconds into the pivot.
    pub fn at(&self, tau: f64) -> BodyState {
        let tau = tau.clamp(0.0, self.duration);
        let turn = match &self.motion {
            Motion::Hinge(turn) => turn,
            Motion::Skid(skid) => return skid.at(tau),
            Motion::Stepped(stepped) => return stepped.at(tau),
        };
        let (th, w) = turn.angle(tau);
        let rot = exp_so3(&(self.axis * th));
        let r = rot * turn.r0;
        let omega = self.axis * w;
        BodyState {
            x: self.point + r,
            q: rot * turn.q0,
            v: omega.cross(&r),
            w: omega,
        }
    }

    /// The skid this pivot follows, if its line slides.
    pub fn skid(&self) -> Option<&Skid> {
        match &self.motion {
            Motion::Skid(skid) => Some(skid),
            Motion::Hinge(_) | Motion::Stepped(_) => None,
        }
    }

    /// The stepped motion this pivot follows, if it is one.
    pub fn stepped(&self) -> Option<&Stepped> {
        match &self.motion {
            Motion::Stepped(stepped) => Some(stepped),
            _ => None,
        }
    }

    /// Mechanical energy `½ I_a θ̇² − m g·r` (J, up to a constant) `tau`
    /// seconds in, for the tests: the hinge does no work.
    pub fn energy(&self, d: &BodyDynamics, g: &Vec3, tau: f64) -> f64 {
        let s = self.at(tau);
        let rot = *s.q.to_rotation_matrix().matrix();
        let ic = rot * d.inertia * rot.transpose();
        0.5 * (d.mass * s.v.norm_squared() + s.w.dot(&(ic * s.w))) - d.mass * g.dot(&s.x)
    }
}
