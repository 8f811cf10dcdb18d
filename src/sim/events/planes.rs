//! Certificates that two parts stay apart: planes separating them whose
//! vertices' heights are bounded over a horizon (fixed, turning with two
//! crossing edges, or carried with a face).

use crate::geometry::{Contact, Part};
use crate::math::Vec3;
use crate::sim::state::BodyState;
use nalgebra::{Isometry3, Point3};
use smallvec::SmallVec;

pub(super) type Heights = SmallVec<[(f64, f64, f64); 16]>;

/// First time `h + ḣ τ + ½ c τ² = lvl` going down; for a point already
/// below `lvl` but rising, its next descent (the later root).
pub(super) fn first_cross(h: f64, hd: f64, c: f64, lvl: f64) -> f64 {
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
pub(super) struct TurningPlane {
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
    pub(super) fn new(
        c: &Contact,
        (part_a, s, terms): (&Part, &BodyState, &(Vec3, f64, f64, f64)),
        (part_b, pose_b): (&Part, &Isometry3<f64>),
        horizon: f64,
    ) -> Option<TurningPlane> {
        let n = c.normal;
        let p0 = c.point_b;
        let (wa, wb) = (s.pose() * part_a.offset, pose_b * part_b.offset);
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
    pub(super) fn raise<const K: usize>(&self, levels: [f64; K], steps: &mut [f64; K]) {
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
pub(super) struct FacePlane {
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
    pub(super) fn new(
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
        let wa = s.pose() * part_a.offset;
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
        let vc = s.velocity_at(&point);
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
    pub(super) fn raise<const K: usize>(&self, levels: [f64; K], steps: &mut [f64; K]) {
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
pub(super) fn edge_nearest(vertices: impl Iterator<Item = (Vec3, f64)>) -> Option<Vec3> {
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
pub(super) fn world_vertices(part: &Part, pose: Isometry3<f64>) -> impl Iterator<Item = Vec3> + '_ {
    let vertices = match &part.kind {
        crate::geometry::PartKind::Convex { vertices, .. } => vertices.as_slice(),
        _ => &[],
    };
    vertices
        .iter()
        .map(move |v| (pose * Point3::from(*v)).coords)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Geometry, contact};
    use crate::math::{Rng, exp_so3};
    use nalgebra::{Translation3, UnitQuaternion};

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
            contact(body, &s.pose(), &self.geometry, &self.pose, f64::INFINITY)
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
            let query =
                |s: &BodyState| contact(body, &s.pose(), &self.geometry, &self.pose, f64::INFINITY);
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
