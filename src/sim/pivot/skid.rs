//! Skidding on an edge or a corner: a body whose line of support (or
//! single support corner) slides on a plane while it turns
//! (`sim::pivot`), the hinge's companion when friction cannot hold the
//! line still. A corner is one end instead of two (`count`): one normal
//! force, a 1×1 system, no turn in the projection.
//!
//! The ends of the line (two body points, `b₁`, `b₂` from the centre of
//! mass) stay on the plane; everything else is free: the body moves with
//! four degrees of freedom. At each end the plane pushes with `N_i n`
//! and, with friction, drags with Coulomb's `−μ N_i ŝ_i` against the
//! end's slip direction `ŝ_i`. The two normal forces are what keeps both
//! ends' normal accelerations zero,
//!
//! ```text
//! m a = m g + Σ N_i d_i,   I α + ω × I ω = Σ N_i r_i × d_i,   d_i = n − μ ŝ_i,
//! n · (a + α × r_j + ω × (ω × r_j)) = 0   (j = 1, 2),
//! ```
//!
//! a 2×2 linear system in `(N₁, N₂)` at every evaluation.
//!
//! A corner that friction holds is *pinned* (a ball joint): it does not
//! move at all, and the contact force `F` is whatever keeps its whole
//! acceleration zero,
//!
//! ```text
//! (E/m − [r]× I⁻¹ [r]×) F = −(g + α₀ × r + ω × (ω × r)),   α₀ = −I⁻¹ (ω × I ω),
//! ```
//!
//! a 3×3 system (the corner's mass matrix, symmetric positive definite);
//! it ends when `F` leaves the friction cone (the corner slips) or its
//! normal part turns negative. The state
//! `(x, q, v, ω)` is integrated by fixed-step RK4 (step [`STEP`]), and
//! after each step put back on the constraint: both ends at their heights
//! (a turn about the line's in-plane normal, then a shift along `n`), and
//! their normal speeds zero (a frictionless impulse at the ends, the least
//! change of kinetic energy; the same map starts the skid as a plastic
//! impact of the whole line). A pinned corner is put back where it
//! started, and its whole velocity to zero.

mod start;
#[cfg(test)]
mod tests;

use super::super::state::BodyState;
use crate::math::{Mat3, Vec3};
use nalgebra::{Quaternion, UnitQuaternion};

/// Integration step of a skid, s: the motion is smooth between its ends
/// (RK4's error per step is of order `(|ω| h)⁵`).
pub const STEP: f64 = 1e-3;

/// The most a body turns in one RK4 substep of a skid, rad.
pub const TURN: f64 = 0.02;

/// The forces at one instant of a skid.
#[derive(Debug, Clone, Copy)]
pub(super) struct Rates {
    /// Acceleration of the centre of mass and angular acceleration (world).
    pub a: Vec3,
    pub alpha: Vec3,
    /// Normal forces at the two ends, N.
    pub normal: [f64; 2],
    /// Slip speeds of the two ends in the plane, m/s.
    pub slip: [f64; 2],
    /// Slip directions (unit, or zero when not slipping).
    pub dir: [Vec3; 2],
    /// Ends slower than the onset speed that friction holds.
    pub held: [bool; 2],
    /// A pinned corner's contact force along the plane, N (zero
    /// otherwise): it slips once this exceeds `μ N`.
    pub grip: f64,
}

/// A body sliding on a line of support (see the module notes).
#[derive(Debug, Clone, PartialEq)]
pub struct Skid {
    /// The ends of the line, body frame, from the centre of mass: two
    /// points, or one corner twice.
    ends: [Vec3; 2],
    /// How many ends there are: 2 for a line, 1 for a corner.
    count: usize,
    /// Unit plane normal, and each end's offset `n · p` (the ends keep
    /// the heights they start at, within the support band of the plane).
    normal: Vec3,
    levels: [f64; 2],
    mass: f64,
    /// Body-frame inertia about the centre of mass, and its inverse.
    inertia: Mat3,
    inertia_inv: Mat3,
    gravity: Vec3,
    friction: f64,
    /// Slip speed below which an end may stick, m/s.
    onset: f64,
    /// A single corner held in place by friction (a ball joint) at
    /// `anchor` (world), rather than sliding.
    pub(super) pinned: bool,
    anchor: Vec3,
    /// States every [`STEP`] from the start.
    pub(super) table: Vec<BodyState>,
}

/// A state with its quaternion as a plain 4-vector (RK4 stages).
#[derive(Clone, Copy)]
struct Y {
    x: Vec3,
    q: Quaternion<f64>,
    v: Vec3,
    w: Vec3,
}

impl Y {
    fn of(s: &BodyState) -> Y {
        Y {
            x: s.x,
            q: *s.q.quaternion(),
            v: s.v,
            w: s.w,
        }
    }

    fn state(&self) -> BodyState {
        BodyState {
            x: self.x,
            q: UnitQuaternion::new_normalize(self.q),
            v: self.v,
            w: self.w,
        }
    }

    fn add(&self, k: &Y, h: f64) -> Y {
        Y {
            x: self.x + k.x * h,
            q: self.q + k.q * h,
            v: self.v + k.v * h,
            w: self.w + k.w * h,
        }
    }
}

impl Skid {
    /// World inertia inverse and the ends from the centre of mass.
    fn frame(&self, s: &BodyState) -> (Mat3, Mat3, [Vec3; 2]) {
        let rot = *s.q.to_rotation_matrix().matrix();
        let i_w = rot * self.inertia * rot.transpose();
        let i_inv = rot * self.inertia_inv * rot.transpose();
        (i_w, i_inv, self.ends.map(|b| rot * b))
    }

    /// The forces and accelerations at state `s`, or `None` when the two
    /// ends cannot be held apart (the 2×2 system is singular). An end
    /// slipping slower than the onset speed takes as its slip direction
    /// the way it would accelerate without friction (where it is about to
    /// slip), and is *held* when friction along that direction would
    /// reverse its acceleration, or nothing pulls it along the plane.
    pub(super) fn rates(&self, s: &BodyState) -> Option<Rates> {
        let (i_w, i_inv, r) = self.frame(s);
        if self.pinned {
            return self.pinned_rates(s, &i_w, &i_inv, &r[0]);
        }
        let mut slip = [0.0; 2];
        let mut dir = [Vec3::zeros(); 2];
        for i in 0..2 {
            let t = self.slip_velocity(s, &r[i]);
            slip[i] = t.norm();
            if slip[i] > 0.0 {
                dir[i] = t / slip[i];
            }
        }
        let mut slow = [0, 1].map(|i| self.friction > 0.0 && slip[i] < self.onset);
        let mut held = [false; 2];
        if slow.iter().any(|&x| x) {
            let free = self.solve(s, &i_w, &i_inv, &r, &[Vec3::zeros(); 2])?;
            for i in 0..2 {
                if !slow[i] {
                    continue;
                }
                let pull = self.tangential(s, &free, &r[i]);
                if pull.dot(&dir[i]) < 0.0 {
                    // Slipping against the pull: friction opposes the
                    // slip (never along it: it does no positive work).
                    slow[i] = false;
                    continue;
                }
                held[i] = pull.norm() <= 1e-12 * self.gravity.norm();
                dir[i] = if held[i] {
                    Vec3::zeros()
                } else {
                    pull.normalize()
                };
            }
        }
        let (a, alpha, normal) = self.solve(s, &i_w, &i_inv, &r, &dir)?;
        for i in 0..2 {
            if slow[i] && !held[i] {
                held[i] = self.tangential(s, &(a, alpha, normal), &r[i]).dot(&dir[i]) < 0.0;
            }
        }
        Some(Rates {
            a,
            alpha,
            normal,
            slip,
            dir,
            held,
            grip: 0.0,
        })
    }

    /// The corner's mass matrix `E/m − [r]× I⁻¹ [r]×` (the velocity an
    /// impulse at `r` from the centre gives the point there), inverted.
    fn point_mass(&self, i_inv: &Mat3, r: &Vec3) -> Option<Mat3> {
        let rx = r.cross_matrix();
        (Mat3::identity() / self.mass - rx * i_inv * rx).try_inverse()
    }

    /// [`Skid::rates`] of a pinned corner at `r` from the centre: the
    /// contact force that keeps the corner's acceleration zero.
    fn pinned_rates(&self, s: &BodyState, i_w: &Mat3, i_inv: &Mat3, r: &Vec3) -> Option<Rates> {
        let n = self.normal;
        let alpha0 = i_inv * (-s.w.cross(&(i_w * s.w)));
        let rhs = -(self.gravity + alpha0.cross(r) + s.w.cross(&s.w.cross(r)));
        let f = self.point_mass(i_inv, r)? * rhs;
        if !f.iter().all(|c| c.is_finite()) {
            return None;
        }
        let normal = n.dot(&f);
        Some(Rates {
            a: self.gravity + f / self.mass,
            alpha: alpha0 + i_inv * r.cross(&f),
            normal: [normal, 0.0],
            slip: [0.0; 2],
            dir: [Vec3::zeros(); 2],
            held: [false; 2],
            grip: (f - n * normal).norm(),
        })
    }

    /// The in-plane acceleration of the body point at `r` from the
    /// centre, under the accelerations `(a, α, _)`.
    fn tangential(&self, s: &BodyState, acc: &(Vec3, Vec3, [f64; 2]), r: &Vec3) -> Vec3 {
        let n = self.normal;
        let p = acc.0 + acc.1.cross(r) + s.w.cross(&s.w.cross(r));
        p - n * n.dot(&p)
    }

    /// The accelerations `(a, α)` and normal forces with the ends' slip
    /// directions `dir` (zero: no friction at that end).
    fn solve(
        &self,
        s: &BodyState,
        i_w: &Mat3,
        i_inv: &Mat3,
        r: &[Vec3; 2],
        dir: &[Vec3; 2],
    ) -> Option<(Vec3, Vec3, [f64; 2])> {
        let n = self.normal;
        let d = dir.map(|s| n - s * self.friction);
        let alpha0 = i_inv * (-s.w.cross(&(i_w * s.w)));
        let turn = [0, 1].map(|i| i_inv * r[i].cross(&d[i]));
        let mut k = [[0.0; 2]; 2];
        let mut rhs = [0.0; 2];
        for j in 0..2 {
            for i in 0..2 {
                k[j][i] = n.dot(&d[i]) / self.mass + n.dot(&turn[i].cross(&r[j]));
            }
            rhs[j] = -(n.dot(&self.gravity)
                + n.dot(&alpha0.cross(&r[j]))
                + n.dot(&s.w.cross(&s.w.cross(&r[j]))));
        }
        let normal = self.linear(&k, &rhs, 1e-9)?;
        let a = self.gravity + (d[0] * normal[0] + d[1] * normal[1]) / self.mass;
        let alpha = alpha0 + turn[0] * normal[0] + turn[1] * normal[1];
        Some((a, alpha, normal))
    }

    fn deriv(&self, y: &Y) -> Option<Y> {
        let s = y.state();
        let r = self.rates(&s)?;
        Some(Y {
            x: s.v,
            q: Quaternion::from_imag(s.w) * s.q.into_inner() * 0.5,
            v: r.a,
            w: r.alpha,
        })
    }

    /// `h` seconds on from `s` by RK4 (not put back on the constraint),
    /// in as many equal substeps as keep each turn within [`TURN`] rad at
    /// the starting spin (one, unless the body spins fast); `None` where
    /// the system is singular.
    pub(super) fn advance(&self, s: &BodyState, h: f64) -> Option<BodyState> {
        let n = (s.w.norm() * h / TURN).ceil().clamp(1.0, 1e4) as usize;
        let mut s = *s;
        for _ in 0..n {
            s = self.rk4(&s, h / n as f64)?;
        }
        Some(s)
    }

    /// One RK4 step of `h` from `s`.
    fn rk4(&self, s: &BodyState, h: f64) -> Option<BodyState> {
        let y = Y::of(s);
        let k1 = self.deriv(&y)?;
        let k2 = self.deriv(&y.add(&k1, 0.5 * h))?;
        let k3 = self.deriv(&y.add(&k2, 0.5 * h))?;
        let k4 = self.deriv(&y.add(&k3, h))?;
        let sum = Y {
            x: k1.x + (k2.x + k3.x) * 2.0 + k4.x,
            q: k1.q + (k2.q + k3.q) * 2.0 + k4.q,
            v: k1.v + (k2.v + k3.v) * 2.0 + k4.v,
            w: k1.w + (k2.w + k3.w) * 2.0 + k4.w,
        };
        Some(y.add(&sum, h / 6.0).state())
    }

    /// `s` put on the constraint: both ends on the plane (a turn about
    /// the in-plane normal of the line, then a shift along `n`) and their
    /// normal speeds zero (frictionless impulses at the ends, the least
    /// change of kinetic energy). `None` when the ends cannot be told
    /// apart.
    pub(super) fn project(&self, s: &BodyState) -> Option<BodyState> {
        let n = self.normal;
        let mut s = *s;
        if self.pinned {
            let (_, i_inv, r) = self.frame(&s);
            s.x += self.anchor - (s.x + r[0]);
            let impulse = -(self.point_mass(&i_inv, &r[0])? * (s.v + s.w.cross(&r[0])));
            s.v += impulse / self.mass;
            s.w += i_inv * r[0].cross(&impulse);
            return Some(s);
        }
        let (_, _, r) = self.frame(&s);
        let height = |i: usize, r: &Vec3, x: &Vec3| n.dot(&(x + r)) - self.levels[i];
        if self.count == 2 {
            let line = r[1] - r[0];
            let across = n.cross(&line);
            let len2 = across.norm_squared();
            if len2.is_nan() || len2 <= 0.0 {
                return None;
            }
            // Turning by δ about `across / |across|` through the centre
            // moves end i by δ (across/|across|) × r_i along n.
            let k = across / len2.sqrt();
            let lift = [0, 1].map(|i| n.dot(&k.cross(&r[i])));
            let gap = height(1, &r[1], &s.x) - height(0, &r[0], &s.x);
            if (lift[1] - lift[0]).abs() > 0.0 {
                // δ is of the integration's round-off: the first-order
                // turn, normalised, is exact to δ².
                let delta = -gap / (lift[1] - lift[0]);
                let half = k * (0.5 * delta);
                s.q = UnitQuaternion::new_normalize(
                    Quaternion::new(1.0, half.x, half.y, half.z) * s.q.into_inner(),
                );
            }
        }
        let (_, i_inv, r) = self.frame(&s);
        let mean = 0.5 * (height(0, &r[0], &s.x) + height(1, &r[1], &s.x));
        s.x -= n * mean;
        // Normal speeds of the ends to zero.
        let push = [0, 1].map(|i| i_inv * r[i].cross(&n));
        let mut k = [[0.0; 2]; 2];
        let mut rhs = [0.0; 2];
        for j in 0..2 {
            for i in 0..2 {
                k[j][i] = 1.0 / self.mass + n.dot(&push[i].cross(&r[j]));
            }
            rhs[j] = -n.dot(&(s.v + s.w.cross(&r[j])));
        }
        let l = self.linear(&k, &rhs, 1e-12)?;
        s.v += n * ((l[0] + l[1]) / self.mass);
        s.w += push[0] * l[0] + push[1] * l[1];
        Some(s)
    }

    /// The solution of `k x = rhs` over the skid's ends (one or two; the
    /// second of one end is zero), or `None` when the system is singular
    /// to `tol` relative.
    fn linear(&self, k: &[[f64; 2]; 2], rhs: &[f64; 2], tol: f64) -> Option<[f64; 2]> {
        if self.count == 1 {
            let x = rhs[0] / k[0][0];
            return x.is_finite().then_some([x, 0.0]);
        }
        let det = k[0][0] * k[1][1] - k[0][1] * k[1][0];
        let scale = (k[0][0] * k[1][1]).abs() + (k[0][1] * k[1][0]).abs();
        if det.is_nan() || det.abs() <= tol * scale {
            return None;
        }
        Some([
            (rhs[0] * k[1][1] - k[0][1] * rhs[1]) / det,
            (k[0][0] * rhs[1] - rhs[0] * k[1][0]) / det,
        ])
    }

    /// The state `tau` seconds in (`tau` within the skid's table).
    pub(super) fn at(&self, tau: f64) -> BodyState {
        let k = ((tau.max(0.0) / STEP).floor() as usize).min(self.table.len() - 1);
        let s = self.table[k];
        let rest = tau - k as f64 * STEP;
        if rest <= 0.0 {
            return s;
        }
        self.advance(&s, rest).unwrap_or(s)
    }

    /// The ends in the world at state `s` (one corner: the same twice).
    pub(super) fn ends_at(&self, s: &BodyState) -> [Vec3; 2] {
        self.ends.map(|b| s.point(&b))
    }

    /// The velocity along the plane of the body point at `r` from the
    /// centre (world), m/s.
    fn slip_velocity(&self, s: &BodyState, r: &Vec3) -> Vec3 {
        let n = self.normal;
        let u = s.v + s.w.cross(r);
        u - n * n.dot(&u)
    }

    /// How fast the first end slips along the plane, m/s.
    pub(super) fn contact_slip(&self, s: &BodyState) -> f64 {
        let (_, _, r) = self.frame(s);
        self.slip_velocity(s, &r[0]).norm()
    }

    /// How far each end has left its starting height and its normal
    /// speed (for the tests: all stay zero).
    pub fn contact(&self, s: &BodyState) -> [(f64, f64); 2] {
        let n = self.normal;
        let (_, _, r) = self.frame(s);
        [0, 1].map(|i| {
            (
                n.dot(&(s.x + r[i])) - self.levels[i],
                n.dot(&(s.v + s.w.cross(&r[i]))),
            )
        })
    }

    /// Power of the friction forces at `s`, W (≤ 0), for the tests.
    pub fn friction_power(&self, s: &BodyState) -> f64 {
        self.rates(s).map_or(0.0, |r| {
            -(0..2)
                .map(|i| self.friction * r.normal[i] * r.slip[i])
                .sum::<f64>()
        })
    }
}
