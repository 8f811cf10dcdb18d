//! How bounces end: rest, sliding contact and micro-collisions.
//!
//! nudge models contact as impacts only, so a body that should lie on the
//! floor would bounce ever lower (a Zeno series), and a body pivoting on a
//! corner or rocking onto a face would chatter in infinitely many impacts.
//! After every impulse against a static obstacle [`decide`] picks how it
//! ends, from the post-impulse state. `v_r` is the rest speed in force for
//! the body: the scene's `rest_speed`, raised to `√(2 |g| h)` so that no
//! hop is lower than `h = HOP · reach` (3e-5 of the body's size: invisible,
//! and hops below it would only cost events). A *support point* is a
//! corner of a contact patch (a body vertex, an obstacle vertex, an edge
//! crossing, or a ball's lowest point; see
//! [`crate::geometry::near_points`]) within the band
//! `δ = 10 v_r² / |g|` (plus the event skin) of an obstacle's surface: a
//! body whose points all move slower than `v_r` cannot rock higher than
//! about `v_r² / 2g`, so every corner of the patch it lies on is inside the
//! band.
//!
//! 1. **Rest** — every point of the body moves slower than `v_r`, and the
//!    body is *statically held*: contact forces at the support points on
//!    every obstacle, inside their friction cones, can balance its weight
//!    (`sim::statics`; without friction: the centre of mass is over the
//!    support polygon). The body is frozen. Without gravity any slow body
//!    rests. A slow body leaning on one vertex or edge with its centre of
//!    mass outside is *not* frozen: it topples; a ladder or a pair of
//!    scissors wedged against a wall by friction is. (The old rule froze
//!    any body whose contact point separated slower than the rest speed,
//!    leaving spinning, tumbling bodies frozen tilted on one corner, or
//!    mid-air against walls.) A body lying on a face is then put on it
//!    exactly (`sim::settle`), here and when it slides.
//! 2. **Slide** — against a half-space, or a face of a hull with the
//!    centre of mass over it (ended where the centre reaches the face's
//!    edge: `rest::face`): the normal speeds of all
//!    support points are below `v_r` and the centre of mass projects (along
//!    the plane normal) into their hull, which is a face (three or more
//!    non-collinear points) or a single ball. The normal motion is removed
//!    (`v ← v − (v·n)n`; for a face also the tilting rotation,
//!    `ω ← (ω·n)n`) and the body moves on in closed form in the plane:
//!    gravity's tangential part accelerates it; with friction a Coulomb
//!    deceleration `μ g_n` of the in-plane speed and `μ g_n m ρ̄ / I_n` of
//!    the spin (ρ̄: mean distance of the support points from the centre of
//!    mass; translation and spin decoupled, an approximation) stops it.
//!    Friction on an inclined plane is not modelled this way (such a body
//!    keeps bouncing). A ball (isotropic, centred, no drag) with friction
//!    on a plane normal to gravity slips under Coulomb friction, which
//!    slows it and spins it up, until its contact point stops slipping; it
//!    then rolls on without slipping, and the switch is an event
//!    (`sim::roll`). Without friction, on an inclined plane or otherwise a
//!    ball slides frictionless; rolling resistance is not modelled.
//! 3. **Bounce** — otherwise an ordinary impulse; and if it approached
//!    slower than `2 v_r` and would separate slower than `v_r` (the Zeno
//!    regime of a contact that should be sustained: pivoting, rolling onto
//!    a face) it is a *micro-collision*: the contact leaves at
//!    `max(u, v_r)` for an approach speed `u`. A
//!    sustained frictionless contact does no work, so elastic is the right
//!    limit, and the floor `v_r` makes every hop last at least `2 v_r / g`:
//!    the impact rate is bounded, no Zeno series, and the contact point
//!    never drifts below the surface. Energy grows only when `u < v_r`, by
//!    at most `½ m v_r²` per micro-collision (`Event::micro` marks them).
//!    The dual-number Jacobian differentiates this map. When the body's
//!    support points on the obstacle lie on one line (an edge), with
//!    friction, the impact starts a *pivot* instead (`sim::pivot`): the
//!    body turns about the edge as a hinge until it rolls onto a face,
//!    lifts off or slips, in one event instead of hundreds of hops; where
//!    friction cannot hold the edge on a half-space (or there is none) it
//!    *skids*, the edge sliding on the plane (`sim::pivot::skid`). A
//!    body on exactly two support points on surfaces with different
//!    normals (a floor and a wall) *leans*, turning about the line through
//!    them while friction holds both ends (`sim::pivot::lean`). A body
//!    that chatters on where none of these takes it (on two obstacles, on
//!    edges crossing edges, beside other parts of a hull) is *stepped*
//!    after two micro-collisions in a row: time-stepped on all its
//!    contacts until it rests, lands or lifts off (`sim::pivot::stepped`).
//!
//! Every path ends: a Zeno series of a supported body falls below `v_r` in
//! finitely many bounces and rests or slides; chatter is bounded by the hop
//! floor; and a body that neither rests nor slides is moving faster than
//! `v_r` somewhere, which gravity and `e < 1` bounces dissipate.

pub(super) mod face;

use super::dynamics::BodyDynamics;
use super::roll::Roll;
use super::state::BodyState;
use super::statics::{self, Support};
use crate::geometry::{NearPoint, PartKind};
use crate::math::{Mat3, Vec3, plane_basis};
use crate::scene::Scene;
pub use face::FaceSlide;

/// A body sliding on a static half-space after its bounces died out
/// (rule 2 above). The motion is closed form from the segment start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Slide {
    /// The supporting obstacle (its pair is not searched while sliding).
    pub obstacle: usize,
    /// Unit plane normal, world, pointing out of the obstacle.
    pub normal: Vec3,
    /// In-plane acceleration: gravity's tangential part `g − (g·n) n`, m/s².
    pub accel: Vec3,
    /// Coulomb deceleration of the in-plane speed, m/s² (0 frictionless;
    /// only on planes normal to gravity, where `accel` is zero).
    pub decel: f64,
    /// Coulomb deceleration of the spin about the normal, rad/s².
    pub spin_decel: f64,
    /// A ball's friction on a level plane: it slips, then rolls
    /// (`sim::roll`; `decel` is then its slipping deceleration).
    pub roll: Option<Roll>,
    /// On a face of a hull (not a half-space): which, and when the slide
    /// reaches its edge (see `rest::face`).
    pub face: Option<FaceSlide>,
}

/// How an impact against an obstacle ends. (Short-lived, one per impact:
/// the size of the sliding variant does not matter.)
#[derive(Debug, Clone, PartialEq)]
#[allow(clippy::large_enum_variant)]
pub(crate) enum Mode {
    /// Keep bouncing (a separation slower than `v_r` makes it a
    /// micro-collision).
    Bounce,
    /// Freeze the body.
    Rest,
    /// Slide on the plane; the post-impulse velocities are projected by
    /// `proj_v`, `proj_w`.
    Slide {
        slide: Slide,
        proj_v: Mat3,
        proj_w: Mat3,
    },
}

/// Everything [`decide`] needs about the impact.
pub(crate) struct Impact<'a> {
    pub scene: &'a Scene,
    pub dynamics: &'a BodyDynamics,
    /// Effective gravity.
    pub gravity: Vec3,
    pub body: usize,
    pub obstacle: usize,
    /// Post-impulse state.
    pub post: BodyState,
    /// Support band δ, m.
    pub band: f64,
    /// The rest speed `v_r` in force for this body (see [`thresholds`]).
    pub v_rest: f64,
    /// The part of the obstacle hit, the impact's unit normal (out of the
    /// obstacle), and how long the simulation has left, s.
    pub part: usize,
    pub normal: Vec3,
    pub horizon: f64,
}

/// An impact is a micro-collision only when it approaches slower than
/// this many times `v_r` (and would separate slower than `v_r`): faster
/// impacts, even inelastic ones, are ordinary bounces.
pub const MICRO: f64 = 2.0;

/// Micro-collision hops rise at most this fraction of the body's reach.
pub const HOP: f64 = 3e-5;

/// The rest speed `v_r` (m/s) in force for a body and its support band
/// `δ` (m): `v_r = max(rest_speed, √(2 |g| h))` with the hop height
/// `h = HOP · reach` (hops lower than that are invisible and only cost
/// events), and `δ = 10 arm + 10 v_r² / |g|`. `v_r = 0` when the scene
/// disables resting (`rest_speed = 0`).
pub(crate) fn thresholds(scene: &Scene, d: &BodyDynamics, gravity: &Vec3, arm: f64) -> (f64, f64) {
    let g = gravity.norm();
    if scene.rest_speed <= 0.0 {
        return (0.0, 10.0 * arm);
    }
    let v_r = scene.rest_speed.max((2.0 * g * HOP * d.reach).sqrt());
    let band = 10.0 * arm + if g > 0.0 { 10.0 * v_r * v_r / g } else { 0.0 };
    (v_r, band)
}

/// Whether every point of the body moves slower than `limit` (m/s).
///
/// The speed of a body point `p` (body frame, from the centre of mass)
/// is `|v_b + w_b × p|` with the velocities turned into the body frame,
/// and into a part's own frame `(R, t)` it is `|R⁻¹(v_b + w_b × t) +
/// R⁻¹w_b × y|` at its vertex `y`: one cross product per vertex, no
/// allocation, stopping at the first point as fast as `limit`. A ball is
/// as fast as its centre plus its spin times its radius.
pub(crate) fn slower_than(scene: &Scene, body: usize, s: &BodyState, limit: f64) -> bool {
    let back = s.q.inverse();
    let (v, w) = (back * s.v, back * s.w);
    let spin = w.norm();
    scene.bodies[body].geometry.parts.iter().all(|p| {
        let (to_part, t) = (p.offset.rotation.inverse(), p.offset.translation.vector);
        match &p.kind {
            PartKind::Ball { radius } => (v + w.cross(&t)).norm() + spin * radius < limit,
            PartKind::Convex { vertices, .. } => {
                let (vp, wp) = (to_part * (v + w.cross(&t)), to_part * w);
                vertices.iter().all(|y| (vp + wp.cross(y)).norm() < limit)
            }
            _ => true,
        }
    })
}

/// The friction coefficient between a body and an obstacle (0 without the
/// friction effect).
pub(crate) fn pair_friction(scene: &Scene, body: usize, obstacle: usize) -> f64 {
    if scene.effects.friction {
        (scene.bodies[body].friction * scene.obstacles[obstacle].friction).sqrt()
    } else {
        0.0
    }
}

/// The support points of a body on one obstacle.
pub(crate) fn supports(
    scene: &Scene,
    body: usize,
    obstacle: usize,
    s: &BodyState,
    band: f64,
) -> Vec<NearPoint> {
    supports_on_parts(scene, body, obstacle, s, band)
        .into_iter()
        .map(|(_, q)| q)
        .collect()
}

/// [`supports`] with the part of the obstacle each lies on.
pub(crate) fn supports_on_parts(
    scene: &Scene,
    body: usize,
    obstacle: usize,
    s: &BodyState,
    band: f64,
) -> Vec<(usize, NearPoint)> {
    let pose = s.pose();
    let o = &scene.obstacles[obstacle];
    let mut out = Vec::new();
    for pa in &scene.bodies[body].geometry.parts {
        for (k, pb) in o.geometry.parts.iter().enumerate() {
            let near = crate::geometry::part_near_points(pa, &pose, pb, &o.pose, band);
            out.extend(near.into_iter().map(|q| (k, q)));
        }
    }
    out
}

/// Whether the line through `com` along `dir` meets the convex hull of
/// `points` (within `tol`, m), and whether the hull is a proper polygon
/// (at least three non-collinear points).
pub(crate) fn over_hull(points: &[Vec3], com: &Vec3, dir: &Vec3, tol: f64) -> (bool, bool) {
    if points.is_empty() {
        return (false, false);
    }
    let (t1, t2) = plane_basis(&dir.normalize());
    let flat = |p: &Vec3| [t1.dot(&(p - com)), t2.dot(&(p - com))];
    let pts: Vec<[f64; 2]> = points.iter().map(flat).collect();
    let hull = convex_hull(pts.clone());
    // Distance from the origin (the centre of mass) to a segment.
    let seg = |a: &[f64; 2], b: &[f64; 2]| {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len2 = dx * dx + dy * dy;
        let s = if len2 > 0.0 {
            (-(a[0] * dx + a[1] * dy) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
        (a[0] + s * dx).hypot(a[1] + s * dy)
    };
    let area: f64 = (0..hull.len())
        .map(|i| cross2(&[0.0, 0.0], &hull[i], &hull[(i + 1) % hull.len()]))
        .sum::<f64>()
        * 0.5;
    let scale = pts
        .iter()
        .map(|p| p[0].hypot(p[1]))
        .fold(0.0, f64::max)
        .max(1e-12);
    let polygon = hull.len() >= 3 && area > 1e-9 * scale * scale;
    let inside = match hull.len() {
        0 => pts.first().is_some_and(|p| p[0].hypot(p[1]) <= tol),
        1 => hull[0][0].hypot(hull[0][1]) <= tol,
        2 => seg(&hull[0], &hull[1]) <= tol,
        n => {
            (0..n).all(|i| cross2(&hull[i], &hull[(i + 1) % n], &[0.0, 0.0]) >= 0.0)
                || (0..n).any(|i| seg(&hull[i], &hull[(i + 1) % n]) <= tol)
        }
    };
    (inside, polygon)
}

/// The convex hull of `pts` counter-clockwise (Andrew's monotone chain),
/// without repeated or collinear corners.
pub(crate) fn convex_hull(mut pts: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    pts.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
    pts.dedup_by(|a, b| (a[0] - b[0]).hypot(a[1] - b[1]) <= 1e-12);
    let mut hull: Vec<[f64; 2]> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &[f64; 2]>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for p in iter {
            while hull.len() >= start + 2
                && cross2(&hull[hull.len() - 2], &hull[hull.len() - 1], p) <= 0.0
            {
                hull.pop();
            }
            hull.push(*p);
        }
        hull.pop();
    }
    hull
}

/// `(a − o) × (b − o)`: positive when `o, a, b` turn counter-clockwise.
pub(crate) fn cross2(o: &[f64; 2], a: &[f64; 2], b: &[f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// Decide how an impact against an obstacle ends (see the module notes).
pub(crate) fn decide(i: &Impact<'_>) -> Mode {
    let scene = i.scene;
    let s = &i.post;
    let v_r = i.v_rest;
    let g = i.gravity;
    let gn = g.norm();
    if v_r <= 0.0 {
        return Mode::Bounce;
    }
    let tol = 1e-9 + 1e-6 * i.dynamics.reach;
    let slow = slower_than(scene, i.body, s, v_r);
    if gn == 0.0 {
        return if slow { Mode::Rest } else { Mode::Bounce };
    }
    let down = g / gn;
    // Whether contact forces inside the friction cones of the support
    // points (on every obstacle) can balance the weight: asked only of a
    // body slow enough to rest (finding the supports is most of the cost
    // of an impact that bounces).
    let held =
        slow && {
            let mut held_by = Vec::new();
            for o in 0..scene.obstacles.len() {
                let friction = pair_friction(scene, i.body, o);
                held_by.extend(supports(scene, i.body, o, s, i.band).into_iter().map(|p| {
                    Support {
                        point: p.point,
                        normal: p.normal,
                        friction,
                    }
                }));
            }
            statics::held(&held_by, &s.x, &down, i.dynamics.reach)
        };
    if held {
        return Mode::Rest;
    }
    let bounce = Mode::Bounce;
    // Sliding: on a half-space (an obstacle of that alone) or on a face of
    // a hull with the centre of mass well inside it (`rest::face`), that
    // gravity presses the body into.
    let o = &scene.obstacles[i.obstacle];
    let Some(part) = o.geometry.parts.get(i.part) else {
        return bounce;
    };
    let sup = || supports(scene, i.body, i.obstacle, s, i.band);
    let (n, sup, face) = match part.kind {
        PartKind::HalfSpace { normal } if o.geometry.parts.len() == 1 => {
            let n = (o.pose * part.offset).rotation * normal;
            if -g.dot(&n) <= 1e-9 * gn {
                return bounce;
            }
            (n, sup(), None)
        }
        PartKind::Convex { .. } => {
            // Asked before the supports are found (most of an impact's
            // cost): a body that gravity does not press onto the face,
            // whose centre leaves it at `v_r` or faster (the centre's
            // normal speed is a mean of the supports' when it lies over
            // them), or whose centre is not over the face, bounces.
            let n = i.normal;
            if -g.dot(&n) <= 1e-9 * gn || n.dot(&s.v).abs() >= v_r {
                return bounce;
            }
            let margin = 10.0 * face::EDGE * i.dynamics.reach;
            let Some((f, sup)) = face::under(part, &o.pose, &n, &s.x, margin, sup) else {
                return bounce;
            };
            (f.normal, sup, Some(f))
        }
        _ => return bounce,
    };
    let g_n = -g.dot(&n);
    if g_n <= 1e-9 * gn {
        return bounce;
    }
    if sup
        .iter()
        .any(|p| n.dot(&(s.velocity_at(&p.point))).abs() >= v_r)
    {
        return bounce;
    }
    let pts: Vec<Vec3> = sup.iter().map(|p| p.point).collect();
    let (inside, polygon) = over_hull(&pts, &s.x, &n, tol);
    let ball = !polygon
        && !i.dynamics.integrate
        && scene.bodies[i.body]
            .geometry
            .parts
            .iter()
            .all(|p| matches!(p.kind, PartKind::Ball { .. }));
    if !inside || !(polygon || ball) {
        return bounce;
    }
    let accel = g + n * g_n;
    let mu = pair_friction(scene, i.body, i.obstacle);
    if mu > 0.0 && polygon && accel.norm() > 1e-9 * gn {
        return bounce;
    }
    let nn = n * n.transpose();
    let proj_v = Mat3::identity() - nn;
    let (proj_w, decel, spin_decel) = if polygon {
        if mu > 0.0 {
            let c = s.x - n * n.dot(&s.x);
            let rho = pts
                .iter()
                .map(|p| ((p - n * n.dot(p)) - c).norm())
                .sum::<f64>()
                / pts.len() as f64;
            let r = *s.q.to_rotation_matrix().matrix();
            let i_n = n.dot(&(r * i.dynamics.inertia * r.transpose() * n));
            (nn, mu * g_n, mu * g_n * i.dynamics.mass * rho / i_n)
        } else {
            (nn, 0.0, 0.0)
        }
    } else {
        // A ball: its spin does not move its contact; with friction on a
        // level plane it slips, then rolls (`sim::roll`).
        (Mat3::identity(), 0.0, 0.0)
    };
    let roll = if ball && mu > 0.0 {
        Roll::new(scene, i.dynamics, i.body, &n, g_n, &accel, mu, s)
    } else {
        None
    };
    let mut slide = Slide {
        obstacle: i.obstacle,
        normal: n,
        accel,
        decel: roll.map_or(decel, |r| r.decel),
        spin_decel,
        roll,
        face: None,
    };
    if let Some(f) = face {
        // Settling the body flat on the face (`sim::run::impact`) moves it
        // along the normal only: the centre's path is this one's.
        let s0 = BodyState {
            v: proj_v * s.v,
            w: proj_w * s.w,
            ..*s
        };
        let edge = face::EDGE * i.dynamics.reach;
        let until = face::until(&slide, &s0, i.dynamics.drag_k, &f, edge, i.horizon);
        slide.face = Some(FaceSlide {
            part: i.part,
            beside: o.geometry.parts.len() > 1,
            until,
        });
    }
    Mode::Slide {
        slide,
        proj_v,
        proj_w,
    }
}

/// A sliding body at `τ` after its slide began, with the coefficients of
/// its tangent: `δx = δx₀ + dx_dv δv₀ (+ dx_dk δk)`, `δv = dv_dv δv₀
/// (+ dv_dk δk)`, `δθ = rot δθ₀ + dth_dw δω₀`, `δω = dw_dw δω₀`. The
/// friction decelerations are held fixed in the tangent.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SlideAt {
    pub state: BodyState,
    pub dx_dv: Mat3,
    pub dv_dv: Mat3,
    pub dx_dk: Vec3,
    pub dv_dk: Vec3,
    pub rot: Mat3,
    pub dth_dw: Mat3,
    pub dw_dw: Mat3,
}

impl Slide {
    /// The closed-form motion `τ` seconds after the slide began from `s0`.
    pub(crate) fn at(&self, s0: &BodyState, drag_k: Option<f64>, tau: f64) -> SlideAt {
        let id = Mat3::identity();
        if let Some(roll) = &self.roll {
            // The state only: `Roll::jacobian` gives its tangent.
            let state = roll.at(&self.normal, s0, tau, false).state;
            let z = Mat3::zeros();
            return SlideAt {
                state,
                dx_dv: z,
                dv_dv: z,
                dx_dk: Vec3::zeros(),
                dv_dk: Vec3::zeros(),
                rot: z,
                dth_dw: z,
                dw_dw: z,
            };
        }
        let (x, v, dx_dv, dv_dv, dx_dk, dv_dk) = if self.decel > 0.0 {
            let speed = s0.v.norm();
            if speed == 0.0 {
                (
                    s0.x,
                    Vec3::zeros(),
                    Mat3::zeros(),
                    Mat3::zeros(),
                    Vec3::zeros(),
                    Vec3::zeros(),
                )
            } else {
                let a = self.decel;
                let u = s0.v / speed;
                let perp = id - u * u.transpose();
                if tau < speed / a {
                    let x = s0.x + s0.v * tau - u * (0.5 * a * tau * tau);
                    let v = u * (speed - a * tau);
                    (
                        x,
                        v,
                        id * tau - perp * (0.5 * a * tau * tau / speed),
                        id - perp * (a * tau / speed),
                        Vec3::zeros(),
                        Vec3::zeros(),
                    )
                } else {
                    let x = s0.x + u * (0.5 * speed * speed / a);
                    (
                        x,
                        Vec3::zeros(),
                        (id + u * u.transpose()) * (0.5 * speed / a),
                        Mat3::zeros(),
                        Vec3::zeros(),
                        Vec3::zeros(),
                    )
                }
            }
        } else {
            let tr = super::flight::translation(&s0.x, &s0.v, &self.accel, drag_k, tau);
            (tr.x, tr.v, id * tr.dx_dv, id * tr.dv_dv, tr.dx_dk, tr.dv_dk)
        };
        let n = self.normal;
        let nn = n * n.transpose();
        let (q, w, rot, dth_dw, dw_dw) = if self.spin_decel > 0.0 {
            let w0 = n.dot(&s0.w);
            let a = self.spin_decel;
            let (phi, w, dphi, dw) = if w0 == 0.0 {
                (0.0, 0.0, 0.0, 0.0)
            } else if tau < w0.abs() / a {
                (
                    w0 * tau - 0.5 * a * tau * tau * w0.signum(),
                    w0 - a * tau * w0.signum(),
                    tau,
                    1.0,
                )
            } else {
                (0.5 * w0 * w0.abs() / a, 0.0, w0.abs() / a, 0.0)
            };
            let e = crate::math::exp_so3(&(n * phi));
            (
                e * s0.q,
                n * w,
                *e.to_rotation_matrix().matrix(),
                nn * dphi,
                nn * dw,
            )
        } else {
            let wt = s0.w * tau;
            let e = crate::math::exp_so3(&wt);
            (
                e * s0.q,
                s0.w,
                *e.to_rotation_matrix().matrix(),
                crate::math::left_jacobian(&wt) * tau,
                id,
            )
        };
        SlideAt {
            state: BodyState { x, q, v, w },
            dx_dv,
            dv_dv,
            dx_dk,
            dv_dk,
            rot,
            dth_dw,
            dw_dw,
        }
    }

    /// `F = (v, ω, a, α)` of a sliding body in state `s`.
    pub(crate) fn flow(&self, s: &BodyState, drag_k: Option<f64>) -> [Vec3; 4] {
        if let Some(roll) = &self.roll {
            return roll.flow(&self.normal, s);
        }
        let a = if self.decel > 0.0 {
            s.v.try_normalize(0.0)
                .map_or(Vec3::zeros(), |u| -u * self.decel)
        } else {
            self.accel - s.v * drag_k.unwrap_or(0.0)
        };
        let w0 = self.normal.dot(&s.w);
        let alpha = if self.spin_decel > 0.0 && w0 != 0.0 {
            -self.normal * (self.spin_decel * w0.signum())
        } else {
            Vec3::zeros()
        };
        [s.v, s.w, a, alpha]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_contains_the_centre_of_a_square_and_not_a_point_outside() {
        let sq = [
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(-1.0, 1.0, 0.0),
            Vec3::new(-1.0, -1.0, 0.0),
            Vec3::new(1.0, -1.0, 0.0),
        ];
        assert_eq!(
            over_hull(&sq, &Vec3::new(0.0, 0.0, 3.0), &Vec3::z(), 1e-9),
            (true, true)
        );
        assert_eq!(
            over_hull(&sq, &Vec3::new(1.5, 0.0, 3.0), &Vec3::z(), 1e-9),
            (false, true)
        );
        // A diagonal of the square (three corners) still holds the centre.
        assert!(over_hull(&sq[..3], &Vec3::zeros(), &Vec3::z(), 1e-9).0);
        // An edge does not hold a centre off it; a single point holds only itself.
        assert_eq!(
            over_hull(&sq[..2], &Vec3::zeros(), &Vec3::z(), 1e-9),
            (false, false)
        );
        assert_eq!(
            over_hull(&sq[..1], &Vec3::new(1.0, 1.0, 5.0), &Vec3::z(), 1e-9),
            (true, false)
        );
    }
}
