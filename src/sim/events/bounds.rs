//! Motion bounds of the parties over a horizon (speed, spin, acceleration)
//! and the time steps they allow: conservative advancement and the plane
//! certificates' steps.

use super::planes::{FacePlane, Heights, TurningPlane, first_cross};
use super::{Pair, World};
use crate::geometry::{Contact, Geometry, Part, PartKind};
use crate::math::Vec3;
use crate::sim::state::{BodyState, Side};
use crate::sim::trajectory::Party;
use nalgebra::Isometry3;
use smallvec::SmallVec;

impl World<'_, '_> {
    pub(super) fn geometry(&self, p: Party) -> &Geometry {
        match p {
            Party::Body(i) => &self.scene.bodies[i].geometry,
            Party::Obstacle(i) => &self.scene.obstacles[i].geometry,
        }
    }

    pub(super) fn state(&self, p: Party, t: f64) -> Option<BodyState> {
        match p {
            Party::Body(i) => Some(self.traj.state(i, t, Side::Post)),
            Party::Obstacle(_) => None,
        }
    }

    pub(super) fn pose(&self, p: Party, s: &Option<BodyState>) -> Isometry3<f64> {
        match (p, s) {
            (Party::Obstacle(i), _) => self.scene.obstacles[i].pose,
            (_, Some(s)) => s.pose(),
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
    pub(super) fn bounds(&self, p: Party, s: &Option<BodyState>, t: f64) -> [(f64, f64); 2] {
        let (Party::Body(i), Some(s)) = (p, s) else {
            return [(0.0, 0.0); 2];
        };
        if s.v == Vec3::zeros() && s.w == Vec3::zeros() && self.traj.resting_state(i, s) {
            return [(0.0, 0.0); 2];
        }
        let d = &self.traj.dynamics[i];
        if let Some(pv) = self.traj.pivot(i, t, Side::Post) {
            // Turning about a fixed line (every point within `lever +
            // reach` of it, at most `w_max`) or skidding (the centre at
            // most `v_max`); the centre's acceleration is in `slide_decel`.
            return [(pv.speed_bound(&s.x, d.reach), 0.0); 2];
        }
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
    pub(super) fn spin_bounds(&self, i: usize, s: &BodyState, t: f64) -> (f64, f64) {
        let d = &self.traj.dynamics[i];
        let Some(slide) = self.traj.slide(i, t, Side::Post) else {
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
    pub(super) fn advance(ba: &[(f64, f64); 2], bb: &[(f64, f64); 2], gap: f64) -> f64 {
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
    pub(super) fn reach_in(ba: &[(f64, f64); 2], bb: &[(f64, f64); 2], tau: f64) -> f64 {
        let mut best = f64::INFINITY;
        for x in ba {
            for y in bb {
                best = best.min((x.0 + y.0) * tau + (x.1 + y.1) * tau * tau);
            }
        }
        best
    }

    /// The friction deceleration of a sliding body at `t` (0 when not
    /// sliding), or the bound on a pivoting body's centre acceleration: its
    /// acceleration is bounded by `|g|` plus this.
    pub(super) fn slide_decel(&self, body: usize, t: f64) -> f64 {
        if let Some(pv) = self.traj.pivot(body, t, Side::Post) {
            return pv.accel_max;
        }
        self.traj
            .slide(body, t, Side::Post)
            .map_or(0.0, |s| s.decel)
    }

    /// How a party's points accelerate relative to a frame that accelerates
    /// with `frame_g`: an exact part (m/s²) and a bound on the rest, plus
    /// the angular bounds `(ω_max, α_max)` (see [`World::bounds`]).
    pub(super) fn accel_terms(
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
        if let Some(pv) = self.traj.pivot(i, t, Side::Post) {
            // The hinge's force and gravity together: the centre's whole
            // acceleration is bounded by `accel_max`.
            return (-frame_g, pv.accel_max, pv.w_max, pv.alpha_max);
        }
        let drag = d.drag_k.unwrap_or(0.0) * (s.v.norm() + g.norm());
        let (exact, rem) = match self.traj.slide(i, t, Side::Post) {
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
    pub(super) fn plane_steps<const K: usize>(
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
                let va = s.velocity_at(&c.point_a);
                let vb = moving_b.map_or(Vec3::zeros(), |(_, sb)| sb.velocity_at(&c.point_b));
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
            // Against an obstacle the plane must support its part (see
            // `supporting`): a touching contact's normal can be far off.
            let (n, top) = match (pair.b, moving_b) {
                (Party::Obstacle(o), None) => {
                    supporting(&gb.parts[c.part_b], &self.scene.obstacles[o].pose, n, &p0)
                }
                _ => (n, 0.0),
            };
            // The plane moves with b's witness point (and falls with gravity
            // for two bodies): two bodies moving together see slow heights.
            let vf = moving_b.map_or(Vec3::zeros(), |(_, sb)| sb.velocity_at(&p0));
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
                            *b = b.min(first_cross(h, hd, acc, level + top));
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
}

/// Cosine of the widest angle, 0.02 rad, between a contact's normal and a
/// face of the obstacle's part that [`supporting`] puts in its place.
pub(super) const FACE_COS: f64 = 0.9998;

/// The plane through the contact point `p0` to certify a step with,
/// against an obstacle's part at `pose`: its normal, and how far the part
/// rises above it (the plane is raised by that much). The contact normal
/// `n` serves when the part rises at most 1e-10 m above its plane (a
/// tenth of the event skin: the steps hardly shorten, and a body on a
/// face of a hull meets the same certificates as on a half-space). For a
/// contact that touches (a gap of 1e-15 m) it need not: the normal is the
/// direction of a gap of round-off, off by up to 1e-2 rad, and the part
/// then rises above the plane by that tilt times its extent (2e-3 m on
/// the coatrack's base), so raising the plane would stall the search. A
/// face of the part within 0.02 rad of `n` whose plane holds the part
/// with less rising takes its place (the contact is on that face).
fn supporting(part: &Part, pose: &Isometry3<f64>, n: Vec3, p0: &Vec3) -> (Vec3, f64) {
    let PartKind::Convex {
        vertices, faces, ..
    } = &part.kind
    else {
        return (n, 0.0);
    };
    let w = pose * part.offset;
    let base = w.translation.vector - p0;
    let top = |m: &Vec3| {
        let (ml, b) = (w.rotation.inverse() * m, m.dot(&base));
        vertices.iter().map(|v| b + ml.dot(v)).fold(0.0, f64::max)
    };
    let rise = top(&n);
    if rise <= 1e-10 {
        return (n, rise);
    }
    faces
        .iter()
        .map(|(f, _)| w.rotation * f)
        .filter(|m| m.dot(&n) >= FACE_COS)
        .map(|m| (m, top(&m)))
        .fold((n, rise), |best, c| if c.1 < best.1 { c } else { best })
}
