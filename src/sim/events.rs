//! Collision detection between steps: a broad phase over each window, then
//! conservative advancement per candidate pair (no tunnelling: the time
//! step is bounded by distance / maximum approach speed), Newton probes to
//! bracket the root early, and a safeguarded Newton–bisection refinement of
//! the time of impact to the root tolerance.

use super::state::{BodyState, StateSide};
use super::trajectory::{Counters, Party, Trajectory};
use crate::geometry::{Contact, Geometry, contact};
use crate::math::Vec3;
use crate::scene::Scene;
use nalgebra::{Isometry3, Translation3};

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
}

/// Tolerances of the event search.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Tolerances {
    /// Refine until `|E| ≤ root` (m).
    pub root: f64,
    /// Re-arm distance and skin of disarmed pairs (m).
    pub arm: f64,
}

/// Read-only view of the world at any time during the simulation.
pub(crate) struct World<'a> {
    pub scene: &'a Scene,
    pub traj: &'a Trajectory,
}

fn isometry(s: &BodyState) -> Isometry3<f64> {
    Isometry3::from_parts(Translation3::from(s.x), s.q)
}

impl World<'_> {
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

    /// Speed bound of a party over `[t, t + τ]` as `a + b τ` (m/s): the
    /// linear speed grows at most by `|g| τ` (drag only slows it), and the
    /// angular speed is bounded by `|L| / I_min` in torque-free flight.
    fn bound(&self, p: Party, s: &Option<BodyState>) -> (f64, f64) {
        let (Party::Body(i), Some(s)) = (p, s) else { return (0.0, 0.0) };
        if s.v == Vec3::zeros() && s.w == Vec3::zeros() && self.traj.resting_state(i, s) {
            return (0.0, 0.0);
        }
        let d = &self.traj.dynamics[i];
        let ang = if d.integrate {
            let r = *s.q.to_rotation_matrix().matrix();
            (r * d.inertia * r.transpose() * s.w).norm() / d.principal.min()
        } else {
            s.w.norm()
        };
        (s.v.norm() + ang * d.reach, self.traj.gravity.norm())
    }

    /// A safe advance for a body against a static obstacle, vertex by
    /// vertex: every convex obstacle part lies behind the plane through its
    /// closest point with the contact normal, and each body point's height
    /// `h` over that plane obeys `h(t+τ) ≥ h + ḣ τ − ½ B τ²`, with `B`
    /// bounding its acceleration along the normal (gravity, drag,
    /// centripetal and angular acceleration). No point can reach the
    /// obstacle before the smallest such root — far larger than the
    /// speed-bound step when a body separates slowly after a bounce.
    /// `None` for body–body pairs.
    fn plane_step(&self, pair: &Pair, sa: &Option<BodyState>, skin: f64, reach: f64) -> Option<f64> {
        let Party::Obstacle(o) = pair.b else { return None };
        let obstacle = &self.scene.obstacles[o];
        let s = sa.as_ref()?;
        let body = &self.scene.bodies[pair.a];
        let iso = Isometry3::from_parts(Translation3::from(s.x), s.q);
        Counters::bump(&self.traj.counters.collisions, 1);
        let planes = crate::geometry::part_contacts(&body.geometry, &iso, &obstacle.geometry, &obstacle.pose, reach);
        let d = &self.traj.dynamics[pair.a];
        let (w_max, alpha) = if d.integrate {
            let r = *s.q.to_rotation_matrix().matrix();
            let w = (r * d.inertia * r.transpose() * s.w).norm() / d.principal.min();
            (w, w * w * d.principal.max() / d.principal.min())
        } else {
            (s.w.norm(), 0.0)
        };
        let g = self.traj.gravity;
        let drag = d.drag_k.unwrap_or(0.0) * (s.v.norm() + g.norm());
        let mut best = f64::INFINITY;
        for c in planes {
            let n = c.normal;
            let p0 = c.point_b;
            let lin = n.dot(&g).abs() + drag;
            let part = &body.geometry.parts[c.part_a];
            let points: Vec<(Vec3, f64)> = match &part.kind {
                crate::geometry::PartKind::Ball { radius } => vec![(part.offset.translation.vector, *radius)],
                crate::geometry::PartKind::Convex { .. } => part.vertices().into_iter().map(|v| (v, 0.0)).collect(),
                _ => return None,
            };
            for (local, radius) in points {
                let r = s.q * local;
                let h = n.dot(&(s.x + r - p0)) - radius + skin;
                let hd = n.dot(&(s.v + s.w.cross(&r)));
                if h <= 0.0 && hd <= 0.0 {
                    return Some(0.0);
                }
                let bb = lin + (w_max * w_max + alpha) * r.norm();
                // The later root of h + ḣ τ − ½ B τ² = 0: the next downward
                // crossing (also for a point just below the plane rising out).
                let disc = hd * hd + 2.0 * bb * h;
                let tau = if bb > 0.0 {
                    if disc < 0.0 {
                        return Some(0.0);
                    }
                    (hd + disc.sqrt()) / bb
                } else if h <= 0.0 {
                    return Some(0.0);
                } else if hd < 0.0 {
                    h / -hd
                } else {
                    f64::INFINITY
                };
                best = best.min(tau);
            }
        }
        Some(best)
    }

    /// Contact of a pair at time `t`, with the relative normal velocity at
    /// the witness points (negative when approaching).
    pub fn contact(&self, pair: &Pair, t: f64, max_distance: f64) -> Option<(Contact, f64)> {
        let sa = self.state(Party::Body(pair.a), t);
        let sb = self.state(pair.b, t);
        self.contact_with(pair, &sa, &sb, max_distance)
    }

    fn contact_with(&self, pair: &Pair, sa: &Option<BodyState>, sb: &Option<BodyState>, max_distance: f64) -> Option<(Contact, f64)> {
        let pa = self.pose(Party::Body(pair.a), sa);
        let pb = self.pose(pair.b, sb);
        Counters::bump(&self.traj.counters.collisions, 1);
        let c = contact(self.geometry(Party::Body(pair.a)), &pa, self.geometry(pair.b), &pb, max_distance)?;
        let va = sa.map(|s| s.v + s.w.cross(&(c.point_a - s.x))).unwrap_or_default();
        let vb = sb.map(|s| s.v + s.w.cross(&(c.point_b - s.x))).unwrap_or_default();
        Some((c, c.normal.dot(&(va - vb))))
    }

    /// Axis-aligned box containing body `i` over `[t0, t1]`.
    pub fn sweep_box(&self, i: usize, t0: f64, t1: f64) -> (Vec3, Vec3) {
        let a = self.traj.state(i, t0, StateSide::After);
        let b = self.traj.state(i, t1, StateSide::After);
        let dt = t1 - t0;
        let d = &self.traj.dynamics[i];
        let g = self.traj.gravity.norm();
        let accel = g + d.drag_k.unwrap_or(0.0) * (a.v.norm() + g * dt);
        let pad = d.reach + accel * dt * dt / 8.0 + 1e-9;
        let lo = a.x.inf(&b.x).add_scalar(-pad);
        let hi = a.x.sup(&b.x).add_scalar(pad);
        (lo, hi)
    }

    /// Safeguarded Newton–bisection on `E(t) = distance + skin` in
    /// `[lo, hi]` with `E(lo) > 0 ≥ E(hi)`.
    fn refine(&self, pair: &Pair, skin: f64, mut lo: f64, mut hi: f64, tol: f64) -> Option<(f64, Contact)> {
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
            t = if tn > lo && tn < hi { tn } else { 0.5 * (lo + hi) };
        }
        best.or_else(|| self.contact(pair, hi, f64::INFINITY).map(|(c, _)| (hi, c)))
    }

    /// The first time in `[t0, t1]` at which the pair's event function
    /// crosses zero while approaching, by conservative advancement: from a
    /// gap `e` and a speed bound `a + b τ`, no contact can happen before
    /// the `τ` solving `a τ + b τ² = e`.
    pub fn find_impact(&self, pair: &Pair, t0: f64, t1: f64, tol: &Tolerances) -> Option<(f64, Contact)> {
        let mut skin = if pair.armed { 0.0 } else { tol.arm };
        let hit = 10.0 * tol.root;
        let mut t = t0.max(pair.hold);
        if t > t1 {
            return None;
        }
        let mut last_positive: Option<f64> = None;
        for _ in 0..10_000 {
            let sa = self.state(Party::Body(pair.a), t);
            let sb = self.state(pair.b, t);
            let (a1, b1) = self.bound(Party::Body(pair.a), &sa);
            let (a2, b2) = self.bound(pair.b, &sb);
            let (a, b) = (a1 + a2, b1 + b2);
            let rem = t1 - t;
            let reach = a * rem + b * rem * rem + hit + skin;
            let (c, rate) = self.contact_with(pair, &sa, &sb, reach)?;
            if c.distance > tol.arm {
                // Separated by more than the arm distance: the event is armed
                // again for the rest of the search.
                skin = 0.0;
            }
            let e = c.distance + skin;
            if e <= hit && rate < 0.0 {
                if e.abs() <= tol.root {
                    return Some((t, c));
                }
                if e < 0.0 {
                    return match last_positive {
                        Some(lo) => self.refine(pair, skin, lo, t, tol.root),
                        None => Some((t, c)),
                    };
                }
            }
            if e > hit {
                last_positive = Some(t);
            }
            if rate < 0.0 {
                // Newton probe: bracket the root early when it is near.
                let tn = t - e / rate;
                if tn > t && tn <= t1 {
                    if let Some((cn, _)) = self.contact(pair, tn, f64::INFINITY) {
                        if cn.distance + skin <= 0.0 {
                            return self.refine(pair, skin, t, tn, tol.root);
                        }
                    }
                }
            }
            if a <= 0.0 && b <= 0.0 {
                return None;
            }
            // Largest safe advance; inside the contact band, step just past it.
            let gap = if e > hit { e - 0.5 * hit } else { (2.0 * hit - e).max(hit) };
            let mut tau = 2.0 * gap / (a + (a * a + 4.0 * b * gap).sqrt());
            if e > hit {
                if let Some(tp) = self.plane_step(pair, &sa, -0.5 * hit, reach) {
                    if tp > tau {
                        // Every point's next descent to the plane is bounded:
                        // the contact just resolved is behind us, so re-arm.
                        tau = tp;
                        skin = 0.0;
                    }
                }
            }
            t += tau.max(f64::EPSILON * t.abs().max(1.0));
            if t > t1 {
                return None;
            }
        }
        None
    }
}
