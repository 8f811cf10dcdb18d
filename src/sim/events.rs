//! Collision detection between steps: a broad phase over each window, then
//! conservative advancement per candidate pair (no tunnelling: the time
//! step is bounded by distance / maximum approach speed, or, far longer, by
//! the time any vertex needs to cross a plane separating two parts: fixed
//! in the contact normal's direction, turning with two crossing edges, or
//! carried with the moving body's face),
//! Newton probes to bracket the root early, and a safeguarded
//! Newton–bisection refinement of the time of impact to the root tolerance.

use super::state::{BodyState, StateSide};
use super::trajectory::{Counters, Party, Trajectory};
use crate::geometry::{Contact, Geometry, Part, PartContacts, Placement};
use crate::math::Vec3;
use crate::scene::Scene;
use nalgebra::{Isometry3, Point3, Translation3};
use smallvec::SmallVec;

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
}

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
type Heights = SmallVec<[(f64, f64, f64); 16]>;

fn isometry(s: &BodyState) -> Isometry3<f64> {
    Isometry3::from_parts(Translation3::from(s.x), s.q)
}

/// First time `h + ḣ τ + ½ c τ² = lvl` going down; for a point already
/// below `lvl` but rising, its next descent (the later root).
fn first_cross(h: f64, hd: f64, c: f64, lvl: f64) -> f64 {
    let h = h - lvl;
    if h <= 0.0 && hd >= 0.0 && c >= 0.0 {
        // Below the level but its bound never falls: it cannot get
        // deeper than it is (a point sliding along a surface it
        // touches, without gravity).
        return f64::INFINITY;
    }
    if h <= 0.0 && hd <= 0.0 {
        return 0.0;
    }
    if c < 0.0 {
        let disc = hd * hd - 2.0 * c * h;
        if disc < 0.0 {
            return 0.0;
        }
        (hd + disc.sqrt()) / -c
    } else if h <= 0.0 {
        0.0
    } else if hd < 0.0 {
        // Convex lower bound: the tangent line's root is earlier.
        h / -hd
    } else {
        f64::INFINITY
    }
}

/// The separating plane of an edge–edge contact with a static part,
/// turned with the crossing edges, and what each vertex does over it.
///
/// The contact normal `n = ê_a × ê_b / |ê_a × ê_b|` of two crossing edges
/// turns as `a`'s edge does. A plane fixed in its direction is a poor
/// certificate then: when `a` turns about the crossing point, the far end of
/// its edge, which lies in that plane at the contact's tiny gap, sinks
/// through it at `|ω| ℓ` (a separating pair of scissors rattling on an edge
/// of the coatrack's base stepped 1e-6 s at a time) although the edges
/// themselves separate. This plane contains `b`'s edge, passes through
/// `b`'s witness point `p₀`, and turns about that edge at the constant
/// `Ω = λ ê_b`, with `λ` chosen so that `a`'s edge stays parallel to it
/// (to first order): its endpoints are then exactly as high as the edges'
/// line distance, which moves at the contact's separation speed.
///
/// Over `[t, t + T]` (`T`: the horizon, s) the height
/// `h = n(τ)·(p − p₀)` of a point `p` in the turning frame has
/// `ḧ = n·(p̈ − 2 Ω × ṗ + Ω × (Ω × (p − p₀)))`, so with `a`'s acceleration
/// terms (see [`World::accel_terms`]; `g` their exact part)
/// `ḧ ≥ n₀·g − |g| min(2, |Ω| T) − B − 2 |Ω| V − |Ω|² D`, `B` bounding
/// the rest of `|p̈ − g|`, `V` the point's speed and `D` its distance from
/// `p₀` over the horizon. A static point has `|ḧ| = |Ω|² |q_⊥|` (`q_⊥`:
/// its offset from the axis). Sound whatever `Ω` is: the choice only
/// decides how long the plane separates the parts.
#[derive(Debug)]
struct TurningPlane {
    /// `(h, ḣ, lower bound of ḧ)` of each vertex of `a` over the plane
    /// (m, m/s, m/s²), valid over the horizon.
    a: Vec<(f64, f64, f64)>,
    /// The same for the vertices of `b`, measured downwards (depths).
    b: Vec<(f64, f64, f64)>,
    /// The plane's angular velocity, rad/s (`p₀` is on its axis).
    #[cfg_attr(not(test), allow(dead_code))]
    spin: Vec3,
    /// The horizon `T` the bounds hold over, s.
    horizon: f64,
}

impl TurningPlane {
    /// The plane of contact `c` between convex parts `part_a` (of body
    /// state `s`, acceleration terms `terms`) and `part_b` (static, at
    /// `pose_b`), with bounds over `horizon` s; `None` unless the contact
    /// is edge–edge with edges not within a few degrees of parallel.
    fn new(
        c: &Contact,
        (part_a, s, terms): (&Part, &BodyState, &(Vec3, f64, f64, f64)),
        (part_b, pose_b): (&Part, &Isometry3<f64>),
        horizon: f64,
    ) -> Option<TurningPlane> {
        let n = c.normal;
        let p0 = c.point_b;
        let (wa, wb) = (isometry(s) * part_a.offset, pose_b * part_b.offset);
        // The obstacle's side first: most contacts are on its faces, and it
        // has few vertices.
        let eb = edge_nearest(world_vertices(part_b, wb).map(|p| (p, -n.dot(&(p - p0)))))?;
        let ea = edge_nearest(world_vertices(part_a, wa).map(|p| (p, n.dot(&(p - p0)))))?;
        let denom = eb.dot(&ea.cross(&n));
        if denom.abs() < 0.05 {
            return None;
        }
        let spin = eb * (s.w.dot(&ea.cross(&n)) / denom);
        let wn = spin.norm();
        let (exact, rem, w_max, alpha) = *terms;
        let g = exact.norm();
        let big_t = horizon.max(0.0);
        let a = world_vertices(part_a, wa)
            .map(|p| {
                let q = p - p0;
                let h = n.dot(&q);
                let r = p - s.x;
                let v = s.v + s.w.cross(&r);
                let turn = (w_max * w_max + alpha) * r.norm();
                let speed = (v.norm() + (g + rem + turn) * big_t)
                    .min(s.v.norm() + (g + rem) * big_t + w_max * r.norm());
                let dist = q.norm() + speed * big_t;
                let hd = n.dot(&(v - spin.cross(&q)));
                let acc = n.dot(&exact)
                    - g * (wn * big_t).min(2.0)
                    - rem
                    - turn
                    - 2.0 * wn * speed
                    - wn * wn * dist;
                (h, hd, acc)
            })
            .collect::<Vec<_>>();
        let b = world_vertices(part_b, wb)
            .map(|p| {
                let q = p - p0;
                let h = -n.dot(&q);
                let off_axis = (q - eb * eb.dot(&q)).norm();
                (h, n.dot(&spin.cross(&q)), -wn * wn * off_axis)
            })
            .collect::<Vec<_>>();
        a.iter()
            .chain(&b)
            .all(|p| p.0.is_finite() && p.1.is_finite() && p.2.is_finite())
            .then_some(TurningPlane {
                a,
                b,
                spin,
                horizon: big_t,
            })
    }

    /// Raises each of `steps` to how long the plane keeps the parts at
    /// least `levels[i]` (m) apart, where that is longer: every vertex of
    /// `a` above a level `l_a` and every vertex of `b` below `l_b`, with
    /// `l_a − l_b` the asked level. The gap above it is split between the
    /// two sides in a few proportions, the best split counts, and no step
    /// goes past the horizon. A split is given up at the first vertex that
    /// crosses before the step to beat (most tries do not beat it).
    fn raise<const K: usize>(&self, levels: [f64; K], steps: &mut [f64; K]) {
        let lowest =
            |pts: &[(f64, f64, f64)]| pts.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
        let (min_a, min_b) = (lowest(&self.a), lowest(&self.b));
        for (step, level) in steps.iter_mut().zip(levels) {
            let gap = min_a + min_b - level;
            if gap.is_nan() || gap <= 0.0 || *step >= self.horizon {
                continue;
            }
            for share in [0.5, 0.1, 0.01] {
                let (la, lb) = (min_a - (1.0 - share) * gap, min_b - share * gap);
                let mut until = self.horizon;
                for (h, hd, acc, lvl) in self
                    .a
                    .iter()
                    .map(|&(h, hd, acc)| (h, hd, acc, la))
                    .chain(self.b.iter().map(|&(h, hd, acc)| (h, hd, acc, lb)))
                {
                    until = until.min(first_cross(h, hd, acc, lvl));
                    if until <= *step {
                        break;
                    }
                }
                *step = step.max(until);
            }
        }
    }
}

/// The plane of a face of the moving part `a` that faces a static part
/// `b` across contact `c`, carried with `a`, and how deep each vertex of
/// `b` stays in front of it.
///
/// A plane fixed in the contact normal's direction is a poor certificate
/// when `a`'s feature is a face and `a` turns: the face's far edge sinks
/// through the fixed plane at `|ω| ℓ` (a plank pivoting on the edge of a
/// support after landing on its end face stepped 4e-11 s at a time) while
/// the face itself leaves `b`. All of `a` stays behind the plane of its
/// own face whatever `a` does, so the distance is at least the smallest
/// depth of `b`'s vertices in front of it. The face is the one whose
/// outward normal `m` is within 1e-3 rad of the contact's `−n`: `m` is
/// exact, where the contact query's normal has noise (3e-8 rad), which
/// puts a long face's vertices under a plane through the witness point.
///
/// For a static point `p`, the depth `D = m·w`, `w = p − c` from the face
/// point `c`, has `D̈ = m̈·w − 2 ṁ·ċ − m·c̈`, so with `a`'s acceleration
/// terms (see [`World::accel_terms`]; `g` their exact part, `B` the rest)
/// over the horizon `T`: `D̈ ≥ −m₀·g − |g| min(2, ω_max T) − B −
/// (α + ω²)(|c − x| + |w|) − 2 ω_max S`, `S` bounding `|ċ|`, and `|w|`
/// growing at most by `S T`.
#[derive(Debug)]
struct FacePlane {
    /// `(D, Ḋ, lower bound of D̈)` of each vertex of `b` (m, m/s, m/s²),
    /// valid over the horizon.
    b: Vec<(f64, f64, f64)>,
    /// The face's outward unit normal now (world).
    #[cfg_attr(not(test), allow(dead_code))]
    normal: Vec3,
    /// A point of the face now (world).
    #[cfg_attr(not(test), allow(dead_code))]
    point: Vec3,
    /// The horizon `T` the bounds hold over, s.
    horizon: f64,
}

impl FacePlane {
    /// The plane of `part_a`'s face across contact `c` from static
    /// `part_b` (see [`TurningPlane::new`] for the arguments); `None`
    /// unless a face of a convex `part_a` is within 1e-3 rad of facing `b`
    /// and `part_b` is convex.
    fn new(
        c: &Contact,
        (part_a, s, terms): (&Part, &BodyState, &(Vec3, f64, f64, f64)),
        (part_b, pose_b): (&Part, &Isometry3<f64>),
        horizon: f64,
    ) -> Option<FacePlane> {
        let crate::geometry::PartKind::Convex { faces, .. } = &part_a.kind else {
            return None;
        };
        if !matches!(part_b.kind, crate::geometry::PartKind::Convex { .. }) {
            return None;
        }
        let wa = isometry(s) * part_a.offset;
        let (m, cos) = faces
            .iter()
            .map(|(normal, _)| {
                let m = wa.rotation * normal;
                (m, -m.dot(&c.normal))
            })
            .max_by(|x, y| x.1.total_cmp(&y.1))?;
        if cos < (1e-3f64).cos() {
            return None;
        }
        // The face's plane supports the part: its highest vertex along `m`.
        let point = world_vertices(part_a, wa).max_by(|p, q| m.dot(p).total_cmp(&m.dot(q)))?;
        let (exact, rem, w_max, alpha) = *terms;
        let g = exact.norm();
        let big_t = horizon.max(0.0);
        let lever = (point - s.x).norm();
        let turn = w_max * w_max + alpha;
        let vc = s.v + s.w.cross(&(point - s.x));
        let speed = (vc.norm() + (g + rem + turn * lever) * big_t)
            .min(s.v.norm() + (g + rem) * big_t + w_max * lever);
        let md = s.w.cross(&m);
        let base = -m.dot(&exact)
            - g * (w_max * big_t).min(2.0)
            - rem
            - turn * lever
            - 2.0 * w_max * speed;
        let b = world_vertices(part_b, pose_b * part_b.offset)
            .map(|p| {
                let w = p - point;
                let depth = m.dot(&w);
                let rate = md.dot(&w) - m.dot(&vc);
                (depth, rate, base - turn * (w.norm() + speed * big_t))
            })
            .collect::<Vec<_>>();
        (!b.is_empty()
            && b.iter()
                .all(|p| p.0.is_finite() && p.1.is_finite() && p.2.is_finite()))
        .then_some(FacePlane {
            b,
            normal: m,
            point,
            horizon: big_t,
        })
    }

    /// Raises each of `steps` to how long every vertex of `b` stays at
    /// least `levels[i]` (m) in front of the plane, where that is longer,
    /// never past the horizon.
    fn raise<const K: usize>(&self, levels: [f64; K], steps: &mut [f64; K]) {
        for (step, level) in steps.iter_mut().zip(levels) {
            if *step >= self.horizon {
                continue;
            }
            let mut until = self.horizon;
            for &(d, dd, acc) in &self.b {
                until = until.min(first_cross(d, dd, acc, level));
                if until <= *step {
                    break;
                }
            }
            *step = step.max(until);
        }
    }
}

/// The unit direction of the edge of a convex part that lies nearest a
/// plane, from its vertices with their heights over it: the two lowest
/// vertices, when the third is at least ten times further up (`None` for a
/// vertex or a face nearest the plane).
fn edge_nearest(vertices: impl Iterator<Item = (Vec3, f64)>) -> Option<Vec3> {
    // The three lowest, in one pass.
    let mut low = [(Vec3::zeros(), f64::INFINITY); 3];
    for v in vertices {
        if v.1 < low[0].1 {
            low = [v, low[0], low[1]];
        } else if v.1 < low[1].1 {
            low = [low[0], v, low[1]];
        } else if v.1 < low[2].1 {
            low[2] = v;
        }
    }
    let [(p0, h0), (p1, h1), (_, h2)] = low;
    (h2 - h0 > 10.0 * (h1 - h0))
        .then(|| (p1 - p0).try_normalize(1e-12))
        .flatten()
}

/// The vertices of a part placed at `pose` (the owner's pose times the
/// part's offset); none for balls and unbounded parts.
fn world_vertices(part: &Part, pose: Isometry3<f64>) -> impl Iterator<Item = Vec3> + '_ {
    let vertices = match &part.kind {
        crate::geometry::PartKind::Convex { vertices, .. } => vertices.as_slice(),
        _ => &[],
    };
    vertices
        .iter()
        .map(move |v| (pose * Point3::from(*v)).coords)
}

impl World<'_, '_> {
    fn geometry(&self, p: Party) -> &Geometry {
        match p {
            Party::Body(i) => &self.scene.bodies[i].geometry,
            Party::Obstacle(i) => &self.scene.obstacles[i].geometry,
        }
    }

    fn state(&self, p: Party, t: f64) -> Option<BodyState> {
        match p {
            Party::Body(i) => Some(self.traj.state(i, t, StateSide::After)),
            Party::Obstacle(_) => None,
        }
    }

    fn pose(&self, p: Party, s: &Option<BodyState>) -> Isometry3<f64> {
        match (p, s) {
            (Party::Obstacle(i), _) => self.scene.obstacles[i].pose,
            (_, Some(s)) => isometry(s),
            _ => Isometry3::identity(),
        }
    }

    /// Two speed bounds of a party over `[t, t + τ]`, each as `a + b τ`
    /// (m/s); the displacement is bounded by the smaller of the two. The
    /// linear speed grows at most by `|g| τ` (drag only slows it). The
    /// angular speed of a torque-free body never exceeds
    /// `ω_max = min(|L| / I_min, √(ωᵀIω / I_min))` (momentum and energy are
    /// conserved) — the first bound — and changes at most at
    /// `|ω̇| ≤ ω_max |L| / I_min` — the second, far tighter for short steps
    /// of a fast-spinning body whose `|L| / I_min` is huge (a rod spinning
    /// about its long axis's normal: 40 rad/s gave a 1.7e4 m/s bound).
    fn bounds(&self, p: Party, s: &Option<BodyState>, t: f64) -> [(f64, f64); 2] {
        let (Party::Body(i), Some(s)) = (p, s) else {
            return [(0.0, 0.0); 2];
        };
        if s.v == Vec3::zeros() && s.w == Vec3::zeros() && self.traj.resting_state(i, s) {
            return [(0.0, 0.0); 2];
        }
        let d = &self.traj.dynamics[i];
        let lin = self.traj.gravity.norm() + self.slide_decel(i, t);
        let w = s.w.norm();
        if !d.integrate {
            return [(s.v.norm() + w * d.reach, lin); 2];
        }
        let (w_max, alpha) = self.spin_bounds(i, s, t);
        [
            (s.v.norm() + w_max * d.reach, lin),
            (s.v.norm() + w * d.reach, lin + alpha * d.reach),
        ]
    }

    /// `(ω_max, α_max)` of an integrated body (see [`World::bounds`]).
    fn spin_bounds(&self, i: usize, s: &BodyState, t: f64) -> (f64, f64) {
        let d = &self.traj.dynamics[i];
        let Some(slide) = self.traj.slide(i, t, StateSide::After) else {
            // Torque-free: the exact extremes of its motion.
            return d.spin_envelope(s);
        };
        // Sliding, friction's torque spends energy: bounds from the energy
        // and the momentum as they are now.
        let r = *s.q.to_rotation_matrix().matrix();
        let iw = r * d.inertia * r.transpose() * s.w;
        let l = iw.norm();
        let i_min = d.principal.min();
        let w_max = (l / i_min)
            .min((s.w.dot(&iw).max(0.0) / i_min).sqrt())
            .max(s.w.norm());
        // |ω̇_i| = |I_j − I_k| / I_i · |ω_j ω_k| ≤ that · ω_max² / 2 per axis,
        // and |ω̇| ≤ |ω × Iω| / I_min overall: the smaller bound.
        let p = d.principal;
        let euler = (0..3)
            .map(|a| ((p[(a + 1) % 3] - p[(a + 2) % 3]) / p[a]).powi(2))
            .sum::<f64>()
            .sqrt()
            * 0.5
            * w_max
            * w_max;
        (w_max, (w_max * l / i_min).min(euler) + slide.spin_decel)
    }

    /// The largest safe advance over a gap (m) for any combination of the
    /// two parties' bounds.
    fn advance(ba: &[(f64, f64); 2], bb: &[(f64, f64); 2], gap: f64) -> f64 {
        let mut best: f64 = 0.0;
        for x in ba {
            for y in bb {
                let (a, b) = (x.0 + y.0, x.1 + y.1);
                let tau = if a <= 0.0 && b <= 0.0 {
                    f64::INFINITY
                } else {
                    2.0 * gap / (a + (a * a + 4.0 * b * gap).sqrt())
                };
                best = best.max(tau);
            }
        }
        best
    }

    /// The smallest bound on how far the parties can close in `τ` seconds.
    fn reach_in(ba: &[(f64, f64); 2], bb: &[(f64, f64); 2], tau: f64) -> f64 {
        let mut best = f64::INFINITY;
        for x in ba {
            for y in bb {
                best = best.min((x.0 + y.0) * tau + (x.1 + y.1) * tau * tau);
            }
        }
        best
    }

    /// The friction deceleration of a sliding body at `t` (0 when not
    /// sliding): its acceleration is bounded by `|g|` plus this.
    fn slide_decel(&self, body: usize, t: f64) -> f64 {
        self.traj
            .slide(body, t, StateSide::After)
            .map_or(0.0, |s| s.decel)
    }

    /// How a party's points accelerate relative to a frame that accelerates
    /// with `frame_g`: an exact part (m/s²) and a bound on the rest, plus
    /// the angular bounds `(ω_max, α_max)` (see [`World::bounds`]).
    fn accel_terms(
        &self,
        i: usize,
        s: &BodyState,
        t: f64,
        frame_g: &Vec3,
    ) -> (Vec3, f64, f64, f64) {
        let d = &self.traj.dynamics[i];
        let seg_rest =
            s.v == Vec3::zeros() && s.w == Vec3::zeros() && self.traj.resting_state(i, s);
        if seg_rest {
            return (-frame_g, 0.0, 0.0, 0.0);
        }
        let g = self.traj.gravity;
        let drag = d.drag_k.unwrap_or(0.0) * (s.v.norm() + g.norm());
        let (exact, rem) = match self.traj.slide(i, t, StateSide::After) {
            Some(sl) => (-frame_g, sl.accel.norm() + sl.decel + drag),
            None => (g - frame_g, drag),
        };
        let (w_max, alpha) = if d.integrate {
            self.spin_bounds(i, s, t)
        } else {
            (s.w.norm(), 0.0)
        };
        (exact, rem, w_max, alpha)
    }

    /// A safe advance by separating planes, point by point. For each pair
    /// of parts within `reach`, the plane through `b`'s witness point with
    /// the contact normal separates them (both are convex); every point's
    /// height over it obeys `h(t+τ) ≥ h + ḣ τ + ½ (a·n) τ² − ½ B τ²`, with
    /// `a` the exact part of its acceleration and `B` bounding the rest
    /// (drag, sliding friction, centripetal and angular acceleration). For
    /// two bodies the plane moves with `b`'s witness point and accelerates
    /// with gravity, which then cancels, and the gap above `−skin` is
    /// shared equally by the two sides. No
    /// point can cross before the returned time — far larger than the
    /// speed-bound step when a body separates slowly after a bounce, or
    /// spins fast. For crossing edges against an obstacle, a plane turning
    /// with the edges ([`TurningPlane`]) is a second certificate; each part
    /// pair takes the longer of its two, the pair the shortest over its
    /// part pairs.
    ///
    /// `planes` are the pair's part contacts within `reach` at `t`
    /// ([`World::part_contacts_at`]). One call serves several skins
    /// (`skins[i]` gives `steps[i]`): the contact queries, the costly part,
    /// do not depend on the skin.
    #[allow(clippy::too_many_arguments)]
    fn plane_steps<const K: usize>(
        &self,
        pair: &Pair,
        sa: &Option<BodyState>,
        sb: &Option<BodyState>,
        planes: &[Contact],
        skins: [f64; K],
        reach: f64,
        t: f64,
        rem: f64,
    ) -> Option<[f64; K]> {
        let s = sa.as_ref()?;
        let levels = skins.map(|skin| -skin);
        let ga = self.geometry(Party::Body(pair.a));
        let gb = self.geometry(pair.b);
        let moving_b = match (pair.b, sb) {
            (Party::Body(j), Some(s)) => Some((j, s)),
            _ => None,
        };
        let frame_g = if moving_b.is_some() {
            self.traj.gravity
        } else {
            Vec3::zeros()
        };
        let terms_a = self.accel_terms(pair.a, s, t, &frame_g);
        let terms_b = moving_b.map(|(j, sb)| self.accel_terms(j, sb, t, &frame_g));
        // Heights of a part's points over a plane moving at `vf` (sign +1:
        // above, the a side), into `out` (reused: this runs for every part
        // contact of every search step).
        #[allow(clippy::too_many_arguments)]
        fn heights(
            g: &crate::geometry::Geometry,
            part: usize,
            st: &BodyState,
            terms: &(Vec3, f64, f64, f64),
            n: &Vec3,
            p0: &Vec3,
            vf: &Vec3,
            sign: f64,
            out: &mut Heights,
        ) -> Option<()> {
            let part = &g.parts[part];
            let (exact, rem, w_max, alpha) = terms;
            // A point `v` of the part (its own frame) is at `r = t + R v` from
            // the owner's centre: the height `n·(x + r − p0)` and its rate
            // `n·(v_x + ω × r − v_f)` (`n·(ω × r) = r·(n × ω)`) are affine in
            // `v`, with coefficients computed once per part; `|r|` does not
            // depend on the owner's orientation.
            let rot = (st.q * part.offset.rotation).to_rotation_matrix();
            let t = st.q * part.offset.translation.vector;
            let nw = n.cross(&st.w);
            let (dh, dhd) = (rot.inverse() * n, rot.inverse() * nw);
            let h0 = n.dot(&(st.x + t - p0));
            let hd0 = n.dot(&(st.v - vf)) + t.dot(&nw);
            let acc0 = sign * n.dot(exact) - rem;
            let spin = w_max * w_max + alpha;
            let centre = part.offset.rotation.inverse() * part.offset.translation.vector;
            let height = |v: &Vec3, radius: f64| {
                let h = sign * (h0 + dh.dot(v)) - radius;
                let hd = sign * (hd0 + dhd.dot(v));
                let acc = acc0 - spin * (v + centre).norm();
                (h, hd, acc)
            };
            out.clear();
            match &part.kind {
                crate::geometry::PartKind::Ball { radius } => {
                    out.push(height(&Vec3::zeros(), *radius));
                }
                crate::geometry::PartKind::Convex { vertices, .. } => {
                    out.extend(vertices.iter().map(|v| height(v, 0.0)));
                }
                _ => return None,
            }
            Some(())
        }
        let (mut ha, mut hb) = (Heights::new(), Heights::new());
        let mut best = [f64::INFINITY; K];
        // Part contacts with an obstacle and their fixed-plane steps.
        let mut fixed = SmallVec::<[_; 4]>::with_capacity(planes.len());
        let ball = |g: &crate::geometry::Geometry, part: usize| {
            matches!(g.parts[part].kind, crate::geometry::PartKind::Ball { .. })
        };
        for c in planes {
            let n = c.normal;
            let p0 = c.point_b;
            if ball(ga, c.part_a) != ball(gb, c.part_b) {
                // A ball against a flat-sided part: the plane through the
                // witness is only tangent to the ball, and an edge lying in it
                // would seem to approach while it turns about the ball. Use
                // instead that the distance from the ball's centre to a convex
                // part is convex in the centre's position in that part's frame:
                // gap(τ) ≥ gap + ġap τ − ½ A τ², A bounding the centre's
                // acceleration seen from the part's (rotating) frame.
                let va = s.v + s.w.cross(&(c.point_a - s.x));
                let vb = moving_b.map_or(Vec3::zeros(), |(_, sb)| {
                    sb.v + sb.w.cross(&(c.point_b - sb.x))
                });
                let rate = n.dot(&(va - vb));
                let (centre_on_a, part_c) = if ball(ga, c.part_a) {
                    (true, &ga.parts[c.part_a])
                } else {
                    (false, &gb.parts[c.part_b])
                };
                let none = (Vec3::zeros(), 0.0, 0.0, 0.0);
                let (sp, tp, sq, tq) = if centre_on_a {
                    (
                        Some(s),
                        terms_a,
                        moving_b.map(|(_, sb)| sb),
                        terms_b.unwrap_or(none),
                    )
                } else {
                    (
                        moving_b.map(|(_, sb)| sb),
                        terms_b.unwrap_or(none),
                        Some(s),
                        terms_a,
                    )
                };
                let r = sp.map_or(part_c.offset.translation.vector, |st| {
                    st.q * part_c.offset.translation.vector
                });
                let centre = sp.map_or(r, |st| st.x + r);
                let (ex_p, rem_p, w_p, al_p) = tp;
                let (ex_q, rem_q, w_q, al_q) = tq;
                let (xq, vq) = sq.map_or((centre, Vec3::zeros()), |st| (st.x, st.v));
                let wq_vec = sq.map_or(Vec3::zeros(), |st| st.w);
                let vc = sp.map_or(Vec3::zeros(), |st| st.v + st.w.cross(&r));
                let rho = (centre - xq).norm() + reach;
                let v_rel = (vc - vq - wq_vec.cross(&(centre - xq))).norm()
                    + reach / rem.max(1e-300)
                    + w_q * reach;
                let acc = (ex_p - ex_q).norm()
                    + rem_p
                    + rem_q
                    + (w_p * w_p + al_p) * r.norm()
                    + (al_q + w_q * w_q) * rho
                    + 2.0 * w_q * v_rel;
                for (b, &level) in best.iter_mut().zip(&levels) {
                    *b = b.min(first_cross(c.distance, rate, -acc, level));
                }
                if best.iter().all(|&b| b == 0.0) {
                    return Some(best);
                }
                continue;
            }
            // The plane moves with b's witness point (and falls with gravity
            // for two bodies): two bodies moving together see slow heights.
            let vf = moving_b.map_or(Vec3::zeros(), |(_, sb)| sb.v + sb.w.cross(&(p0 - sb.x)));
            heights(ga, c.part_a, s, &terms_a, &n, &p0, &vf, 1.0, &mut ha)?;
            let mut step = [f64::INFINITY; K];
            match (moving_b, &terms_b) {
                (Some((_, sb)), Some(tb)) => {
                    heights(gb, c.part_b, sb, tb, &n, &p0, &vf, -1.0, &mut hb)?;
                    let min_a = ha.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
                    let min_b = hb.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
                    for (b, &level) in step.iter_mut().zip(&levels) {
                        let spare = 0.5 * (min_a + min_b - level);
                        if spare.is_nan() || spare <= 0.0 {
                            *b = 0.0;
                            continue;
                        }
                        for &(h, hd, acc) in &ha {
                            *b = b.min(first_cross(h, hd, acc, min_a - spare));
                        }
                        for &(h, hd, acc) in &hb {
                            *b = b.min(first_cross(h, hd, acc, min_b - spare));
                        }
                    }
                }
                _ => {
                    for (b, &level) in step.iter_mut().zip(&levels) {
                        for &(h, hd, acc) in &ha {
                            *b = b.min(first_cross(h, hd, acc, level));
                        }
                    }
                    if let Party::Obstacle(o) = pair.b {
                        fixed.push((c, o, step, false));
                        continue;
                    }
                }
            }
            for (b, t) in best.iter_mut().zip(step) {
                *b = b.min(t);
            }
            if best.iter().all(|&b| b == 0.0) {
                return Some(best);
            }
        }
        // Against an obstacle, two planes may certify far longer than the
        // fixed one: a plane turning with crossing edges (`TurningPlane`)
        // and the plane of `a`'s face (`FacePlane`). Only a part pair that
        // binds the pair's step, short of the window's end, is worth them;
        // the binding pair may change as steps grow.
        loop {
            let step = fixed.iter().fold(best, |m, (_, _, st, _)| {
                std::array::from_fn(|k| m[k].min(st[k]))
            });
            let binding = fixed.iter().position(|(_, _, st, tried)| {
                !tried && st.iter().zip(&step).any(|(s, m)| s <= m && *s < rem)
            });
            let Some(i) = binding else {
                return Some(step);
            };
            let (c, o, st, tried) = &mut fixed[i];
            *tried = true;
            let (part_a, pose_b) = (&ga.parts[c.part_a], &self.scene.obstacles[*o].pose);
            if let Some(plane) =
                TurningPlane::new(c, (part_a, s, &terms_a), (&gb.parts[c.part_b], pose_b), rem)
            {
                plane.raise(levels, st);
            }
            // A little past the window's end, so that a certificate to its
            // end ends the search.
            if let Some(plane) = FacePlane::new(
                c,
                (part_a, s, &terms_a),
                (&gb.parts[c.part_b], pose_b),
                rem * (1.0 + 1e-6),
            ) {
                plane.raise(levels, st);
            }
        }
    }

    /// Contact of a pair at time `t`, with the relative normal velocity at
    /// the witness points (negative when approaching).
    pub fn contact(&self, pair: &Pair, t: f64, max_distance: f64) -> Option<(Contact, f64)> {
        let sa = self.state(Party::Body(pair.a), t);
        let sb = self.state(pair.b, t);
        self.contact_with(pair, &sa, &sb, max_distance)
    }

    /// Every part pair's contact within `max_distance` (one contact query).
    fn part_contacts_at(
        &self,
        pair: &Pair,
        sa: &Option<BodyState>,
        sb: &Option<BodyState>,
        max_distance: f64,
    ) -> PartContacts {
        Counters::bump(&self.traj.counters.collisions, 1);
        self.placed(pair, sa, sb, |a, b| a.part_contacts(b, max_distance))
    }

    /// `query` of the pair's two parties placed for contact queries (an
    /// obstacle's placement is the simulation's).
    fn placed<R>(
        &self,
        pair: &Pair,
        sa: &Option<BodyState>,
        sb: &Option<BodyState>,
        query: impl FnOnce(&Placement, &Placement) -> R,
    ) -> R {
        let pa = self.pose(Party::Body(pair.a), sa);
        let a = Placement::new(self.geometry(Party::Body(pair.a)), &pa);
        match pair.b {
            Party::Obstacle(o) => query(&a, &self.obstacles[o]),
            Party::Body(_) => {
                let pb = self.pose(pair.b, sb);
                query(&a, &Placement::new(self.geometry(pair.b), &pb))
            }
        }
    }

    /// The closest of `contacts` (the first of equals, as [`contact`]
    /// picks it), with its relative normal velocity (negative when
    /// approaching).
    fn closest(
        contacts: &[Contact],
        sa: &Option<BodyState>,
        sb: &Option<BodyState>,
    ) -> Option<(Contact, f64)> {
        let c = *contacts
            .iter()
            .min_by(|x, y| x.distance.total_cmp(&y.distance))?;
        Some((c, Self::normal_rate(&c, sa, sb)))
    }

    fn normal_rate(c: &Contact, sa: &Option<BodyState>, sb: &Option<BodyState>) -> f64 {
        let va = sa
            .map(|s| s.v + s.w.cross(&(c.point_a - s.x)))
            .unwrap_or_default();
        let vb = sb
            .map(|s| s.v + s.w.cross(&(c.point_b - s.x)))
            .unwrap_or_default();
        c.normal.dot(&(va - vb))
    }

    fn contact_with(
        &self,
        pair: &Pair,
        sa: &Option<BodyState>,
        sb: &Option<BodyState>,
        max_distance: f64,
    ) -> Option<(Contact, f64)> {
        Counters::bump(&self.traj.counters.collisions, 1);
        let c = self.placed(pair, sa, sb, |a, b| a.contact(b, max_distance))?;
        Some((c, Self::normal_rate(&c, sa, sb)))
    }

    /// Axis-aligned box containing body `i` over `[t0, t1]`.
    pub fn sweep_box(&self, i: usize, t0: f64, t1: f64) -> (Vec3, Vec3) {
        let a = self.traj.state(i, t0, StateSide::After);
        let b = self.traj.state(i, t1, StateSide::After);
        let dt = t1 - t0;
        let d = &self.traj.dynamics[i];
        let g = self.traj.gravity.norm();
        let accel = g + self.slide_decel(i, t0) + d.drag_k.unwrap_or(0.0) * (a.v.norm() + g * dt);
        let pad = d.reach + accel * dt * dt / 8.0 + 1e-9;
        let lo = a.x.inf(&b.x).add_scalar(-pad);
        let hi = a.x.sup(&b.x).add_scalar(pad);
        (lo, hi)
    }

    /// Safeguarded Newton–bisection on `E(t) = distance + skin` in
    /// `[lo, hi]` with `E(lo) > 0 ≥ E(hi)`.
    fn refine(
        &self,
        pair: &Pair,
        skin: f64,
        mut lo: f64,
        mut hi: f64,
        tol: f64,
    ) -> Option<(f64, Contact)> {
        let mut t = hi;
        let mut best: Option<(f64, Contact)> = None;
        for _ in 0..200 {
            let (c, rate) = self.contact(pair, t, f64::INFINITY)?;
            let e = c.distance + skin;
            if e.abs() <= tol {
                return Some((t, c));
            }
            if e > 0.0 {
                lo = t;
            } else {
                hi = t;
                best = Some((t, c));
            }
            if hi - lo <= 4.0 * f64::EPSILON * hi.abs().max(1.0) {
                break;
            }
            let tn = if rate != 0.0 { t - e / rate } else { f64::NAN };
            t = if tn > lo && tn < hi {
                tn
            } else {
                0.5 * (lo + hi)
            };
        }
        best.or_else(|| self.contact(pair, hi, f64::INFINITY).map(|(c, _)| (hi, c)))
    }

    /// The first time in `[t0, t1]` at which the pair's event function
    /// crosses zero while approaching, by conservative advancement: from a
    /// gap `e` and a speed bound `a + b τ`, no contact can happen before
    /// the `τ` solving `a τ + b τ² = e`.
    ///
    /// # Errors
    /// The time reached when the search ran out of iterations without
    /// deciding (see [`super::SimError::EventSearchStalled`]).
    pub fn find_impact(
        &self,
        pair: &Pair,
        t0: f64,
        t1: f64,
        tol: &Tolerances,
    ) -> Result<Option<(f64, Contact)>, f64> {
        let mut skin = if pair.armed { 0.0 } else { tol.arm };
        let hit = 10.0 * tol.root;
        let mut t = t0.max(pair.hold);
        if t > t1 {
            return Ok(None);
        }
        let mut last_positive: Option<f64> = None;
        // Whether a Newton probe has landed short of the root: the gap
        // closes ever slower (a convex approach, a corner turning in), so
        // Newton from above never brackets it, while the certified steps'
        // quadratic bound converges as fast. Probe again only near it.
        let mut short = false;
        for _ in 0..10_000 {
            let sa = self.state(Party::Body(pair.a), t);
            let sb = self.state(pair.b, t);
            let ba = self.bounds(Party::Body(pair.a), &sa, t);
            let bb = self.bounds(pair.b, &sb, t);
            let rem = t1 - t;
            let reach = Self::reach_in(&ba, &bb, rem) + hit + skin;
            // One query serves both the closest contact and the
            // separating planes of every part pair.
            let planes = self.part_contacts_at(pair, &sa, &sb, reach);
            let Some((c, rate)) = Self::closest(&planes, &sa, &sb) else {
                return Ok(None);
            };
            if c.distance > tol.arm {
                // Separated by more than the arm distance: the event is armed
                // again for the rest of the search.
                skin = 0.0;
            }
            let e = c.distance + skin;
            if e <= hit && rate < 0.0 {
                if e.abs() <= tol.root {
                    return Ok(Some((t, c)));
                }
                if e < 0.0 {
                    return Ok(match last_positive {
                        Some(lo) => self.refine(pair, skin, lo, t, tol.root),
                        None => Some((t, c)),
                    });
                }
            }
            if e > hit {
                last_positive = Some(t);
            }
            if rate < 0.0 && (!short || e <= 1e3 * hit) {
                // Newton probe: bracket the root early when it is near.
                let tn = t - e / rate;
                if tn > t
                    && tn <= t1
                    && let Some((cn, rate_n)) = self.contact(pair, tn, f64::INFINITY)
                {
                    let en = cn.distance + skin;
                    if en <= 0.0 {
                        return Ok(self.refine(pair, skin, t, tn, tol.root));
                    }
                    if en <= tol.root && rate_n < 0.0 {
                        // The probe landed on the root itself, approaching:
                        // the bracket's refinement would return this very
                        // time. (Certified steps would crawl the last
                        // nanometres to it.)
                        return Ok(Some((tn, cn)));
                    }
                    short = true;
                }
            }
            if ba.iter().chain(&bb).all(|&(a, b)| a <= 0.0 && b <= 0.0) {
                return Ok(None);
            }
            // Largest safe advance; inside the contact band, step just past it.
            let gap = if e > hit {
                e - 0.5 * hit
            } else {
                (2.0 * hit - e).max(hit)
            };
            let mut tau = Self::advance(&ba, &bb, gap);
            let [rearm, in_skin, graze] = self
                .plane_steps(
                    pair,
                    &sa,
                    &sb,
                    &planes,
                    [-0.5 * hit, skin - 0.5 * hit, skin - tol.root],
                    reach,
                    t,
                    rem,
                )
                .map_or([None; 3], |steps| steps.map(Some));
            if let Some(tp) = rearm
                && tp > tau
            {
                // Every point's next descent to the plane is bounded: the
                // contact just resolved is behind us, so re-arm.
                tau = tp;
                skin = 0.0;
            } else if skin > 0.0
                && let Some(tp) = in_skin
                && tp > tau
            {
                // A disarmed pair whose point still sits in the skin (a slow
                // separation after an impulse): the global speed bound would
                // crawl here for thousands of steps; the per-point bound says
                // no point sinks below the skin before `tp`. Stay disarmed.
                tau = tp;
            } else if e <= hit
                && rate < 0.0
                && let Some(tp) = graze
                && tp > tau
            {
                // Approaching inside the contact band, but too slowly for the
                // speed bound (a grazing contact): step to the earliest time
                // the gap could reach the root tolerance.
                tau = tp;
            }
            t += tau.max(f64::EPSILON * t.abs().max(1.0));
            if t > t1 {
                return Ok(None);
            }
        }
        // No progress in the iteration budget: report it rather than let
        // the pair pass through each other unseen (that was the "bodies
        // sink through the floor" bug).
        Err(t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::contact;
    use crate::math::{Rng, exp_so3};
    use nalgebra::UnitQuaternion;

    const G: Vec3 = Vec3::new(0.0, 0.0, -9.81);

    /// A random vector, each component in `[−1, 1]`.
    fn random(rng: &mut Rng) -> Vec3 {
        Vec3::new(
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
            rng.range(-1.0, 1.0),
        )
    }

    /// The static slab (40 × 40 × 4 cm, top face at z = 4 cm) the plane
    /// tests throw bodies at.
    struct Slab {
        geometry: Geometry,
        pose: Isometry3<f64>,
    }

    impl Slab {
        fn new() -> Slab {
            Slab {
                geometry: Geometry::cuboid(Vec3::new(0.2, 0.2, 0.02)).unwrap(),
                pose: Isometry3::from_parts(
                    Translation3::new(0.0, 0.0, 0.02),
                    UnitQuaternion::identity(),
                ),
            }
        }

        /// Its vertices, world.
        fn vertices(&self) -> Vec<Vec3> {
            self.geometry.parts[0]
                .vertices()
                .iter()
                .map(|v| (self.pose * Point3::from(*v)).coords)
                .collect()
        }

        /// The distance of `body` in state `s` (infinite without a contact).
        fn distance(&self, body: &Geometry, s: &BodyState) -> f64 {
            contact(
                body,
                &isometry(s),
                &self.geometry,
                &self.pose,
                f64::INFINITY,
            )
            .map_or(f64::INFINITY, |c| c.distance)
        }

        /// `s` moved along the contact normal to a gap of 1e-9 to 1e-5 m,
        /// and its contact there; in half the cases the body instead turns
        /// about the contact point as it drifts at `drift`. `None` without
        /// a contact.
        fn near(
            &self,
            rng: &mut Rng,
            body: &Geometry,
            mut s: BodyState,
            drift: Vec3,
        ) -> Option<(BodyState, Contact)> {
            let gap = 10f64.powf(rng.range(-9.0, -5.0));
            let query = |s: &BodyState| {
                contact(
                    body,
                    &isometry(s),
                    &self.geometry,
                    &self.pose,
                    f64::INFINITY,
                )
            };
            let c0 = query(&s)?;
            s.x -= c0.normal * (c0.distance - gap);
            let c = query(&s)?;
            if rng.uniform() < 0.5 {
                s.v = drift - s.w.cross(&(c.point_a - s.x));
            }
            Some((s, c))
        }

        /// Asserts that `body` in state `st`, `tau` into a step certified
        /// from `(s, c)`, is at least `level` away.
        fn assert_apart(
            &self,
            body: &Geometry,
            st: &BodyState,
            (level, tau, step): (f64, f64, f64),
            (s, c): (&BodyState, &Contact),
        ) {
            let d = self.distance(body, st);
            assert!(
                d >= level - 1e-12,
                "distance {d:.3e} below level {level:.3e} at τ = {tau:.3e} of a \
                 certified {step:.3e} s (gap {:.3e}, v {:?}, ω {:?})",
                c.distance,
                s.v,
                s.w
            );
        }
    }

    /// The exact motion from `s` of a torque-free isotropic body: constant
    /// spin, parabolic flight.
    fn exact(s: BodyState) -> impl Fn(f64) -> BodyState {
        move |tau| BodyState {
            x: s.x + s.v * tau + 0.5 * G * tau * tau,
            q: exp_so3(&(s.w * tau)) * s.q,
            ..s
        }
    }

    /// Times over a certified step: uniform, and ever closer to its end.
    fn samples(step: f64) -> impl Iterator<Item = f64> {
        (0..=200)
            .map(move |k| step * f64::from(k) / 200.0)
            .chain((1..40).map(move |k| step * (1.0 - 0.5f64.powi(k))))
    }

    /// `h + ḣ τ + ½ ḧ τ²` of a bound `(h, ḣ, ḧ)`.
    fn bound((h, hd, acc): (f64, f64, f64), tau: f64) -> f64 {
        h + hd * tau + 0.5 * acc * tau * tau
    }

    /// A blade (16 × 1 × 0.4 cm) whose lowest edge crosses the top edge
    /// of a static slab (40 × 40 × 4 cm) at a gap of 1e-9 to 1e-5 m, thrown
    /// under gravity with a random velocity (to 3 m/s per axis) and spin (to
    /// 30 rad/s), or turning about the crossing point as it drifts at 2 cm/s
    /// (the rattle that made the fixed plane creep). The motion is exact (a
    /// torque-free isotropic body: constant spin, parabolic flight) and the
    /// plane gets its exact acceleration terms. Over the certified step,
    /// every vertex's height over the turning plane stays above its
    /// quadratic bound, and the true distance (sampled densely, and ever
    /// closer to the step's end) above the level. Sign errors in the rates,
    /// and a missing Coriolis, spin or axis term, each fail this test.
    #[test]
    fn the_turning_plane_bounds_every_vertex_and_never_certifies_past_a_contact() {
        let slab = Slab::new();
        let blade = Geometry::cuboid(Vec3::new(0.08, 0.005, 0.002)).unwrap();
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let (mut certified, mut long) = (0, 0);
        for _ in 0..400 {
            // Tilted down over the edge (pitch), rolled onto an edge, yawed.
            let q = exp_so3(&Vec3::new(0.0, 0.0, rng.range(-0.6, 0.6)))
                * exp_so3(&Vec3::new(0.0, rng.range(0.05, 0.5), 0.0))
                * exp_so3(&Vec3::new(rng.range(0.1, 0.6), 0.0, 0.0));
            let (v, w, drift) = (
                3.0 * random(&mut rng),
                30.0 * random(&mut rng),
                0.02 * random(&mut rng),
            );
            let s = BodyState {
                x: Vec3::new(0.2 + rng.range(-0.02, 0.02), rng.range(-0.05, 0.05), 0.1),
                q,
                v,
                w,
            };
            let Some((s, c)) = slab.near(&mut rng, &blade, s, drift) else {
                continue;
            };
            let terms = (G, 0.0, s.w.norm(), 0.0);
            let Some(plane) = TurningPlane::new(
                &c,
                (&blade.parts[0], &s, &terms),
                (&slab.geometry.parts[0], &slab.pose),
                0.05,
            ) else {
                continue;
            };
            let levels = [0.0, 0.5 * c.distance];
            let mut steps = [0.0; 2];
            plane.raise(levels, &mut steps);
            certified += 1;
            if steps[0] > 1e3 * c.distance / (s.w.norm() * 0.08 + s.v.norm()) {
                long += 1;
            }
            let at = exact(s);
            let normal = |tau: f64| exp_so3(&(plane.spin * tau)) * c.normal;
            let va = blade.parts[0].vertices();
            let vb = slab.vertices();
            for (&step, &level) in steps.iter().zip(&levels) {
                for tau in samples(step) {
                    let st = at(tau);
                    let n = normal(tau);
                    for (p, &b) in va.iter().zip(&plane.a) {
                        let h = n.dot(&(st.point(p) - c.point_b));
                        assert!(
                            h >= bound(b, tau) - 1e-15,
                            "a vertex at {h:.3e} under its bound {:.3e} at τ = {tau:.3e}",
                            bound(b, tau)
                        );
                    }
                    for (p, &b) in vb.iter().zip(&plane.b) {
                        let d = -n.dot(&(p - c.point_b));
                        assert!(
                            d >= bound(b, tau) - 1e-15,
                            "a depth of b {d:.3e} under its bound {:.3e} at τ = {tau:.3e}",
                            bound(b, tau)
                        );
                    }
                    slab.assert_apart(&blade, &st, (level, tau, step), (&s, &c));
                }
            }
        }
        assert!(certified > 300, "{certified} edge–edge contacts certified");
        assert!(long > 50, "only {long} steps beat the fixed plane's scale");
    }

    /// A plate (20 × 10 × 2 cm) whose lower face nears a static slab
    /// (40 × 40 × 4 cm) at a gap of 1e-9 to 1e-5 m, sloping over the slab's
    /// edge, parallel to it, or over its corner, which then meets the face,
    /// thrown under gravity with a
    /// random velocity (to 3 m/s per axis) and spin (to 30 rad/s), or
    /// pivoting about the contact point as it drifts at 2 cm/s (the plank
    /// on its support). The motion is exact (constant spin, parabolic
    /// flight). Over the certified step, every slab vertex's depth in front
    /// of the face's plane (carried with the plate) stays above its
    /// quadratic bound, and the true distance (sampled densely, and ever
    /// closer to the step's end) above the level. Dropping the turning
    /// term of a depth's rate, or the Coriolis term of its bound, fails
    /// this test.
    #[test]
    fn the_face_plane_bounds_every_vertex_and_never_certifies_past_a_contact() {
        let slab = Slab::new();
        let plate = Geometry::cuboid(Vec3::new(0.1, 0.05, 0.01)).unwrap();
        let mut rng = Rng(0x51_7cc1_b727_220a);
        let (mut certified, mut long) = (0, 0);
        for _ in 0..400 {
            // Sloping down away from the slab over its edge at x = 0.2 m
            // (pitch): parallel to the edge, which meets the face, or also
            // rolled down over the corner at y = 0.2 m, which meets it.
            let pitch = rng.range(0.02, 0.4);
            let corner = rng.uniform() < 0.5;
            let roll = if corner { rng.range(-0.4, -0.02) } else { 0.0 };
            let q = exp_so3(&Vec3::new(0.0, pitch, 0.0)) * exp_so3(&Vec3::new(roll, 0.0, 0.0));
            let (v, w, drift) = (
                3.0 * random(&mut rng),
                30.0 * random(&mut rng),
                0.02 * random(&mut rng),
            );
            let s = BodyState {
                x: Vec3::new(
                    0.2 + rng.range(-0.07, 0.07) * pitch.cos(),
                    if corner {
                        0.2 + rng.range(-0.03, 0.03) * roll.cos()
                    } else {
                        rng.range(-0.1, 0.1)
                    },
                    0.1,
                ),
                q,
                v,
                w,
            };
            let Some((s, c)) = slab.near(&mut rng, &plate, s, drift) else {
                continue;
            };
            let terms = (G, 0.0, s.w.norm(), 0.0);
            let Some(plane) = FacePlane::new(
                &c,
                (&plate.parts[0], &s, &terms),
                (&slab.geometry.parts[0], &slab.pose),
                0.05,
            ) else {
                continue;
            };
            let levels = [0.0, 0.5 * c.distance];
            let mut steps = [0.0; 2];
            plane.raise(levels, &mut steps);
            certified += 1;
            if steps[0] > 10.0 * c.distance / (s.w.norm() * 0.12 + s.v.norm()) {
                long += 1;
            }
            let at = exact(s);
            // The face's normal and point, carried with the plate.
            let (m_body, c_body) = (
                s.q.inverse() * plane.normal,
                s.q.inverse() * (plane.point - s.x),
            );
            let vb = slab.vertices();
            for (&step, &level) in steps.iter().zip(&levels) {
                for tau in samples(step) {
                    let st = at(tau);
                    let (m, point) = (st.q * m_body, st.point(&c_body));
                    for (p, &b) in vb.iter().zip(&plane.b) {
                        let d = m.dot(&(p - point));
                        assert!(
                            d >= bound(b, tau) - 1e-15,
                            "a depth {d:.3e} under its bound {:.3e} at τ = {tau:.3e}",
                            bound(b, tau)
                        );
                    }
                    slab.assert_apart(&plate, &st, (level, tau, step), (&s, &c));
                }
            }
        }
        assert!(certified > 300, "{certified} face contacts certified");
        assert!(long > 50, "only {long} steps beat the speed bound's scale");
    }
}
