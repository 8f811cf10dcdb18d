//! A body turning about a fixed line: its angle (the hinge's motion) and, in closed form, where its points
//! go (`v(θ) = along + perp cos θ + side sin θ`), the box they sweep over
//! an interval of angles, and the angles at which one first reaches the
//! contact plane (`sim::pivot`).

use crate::math::Vec3;
#[cfg(test)]
use crate::math::exp_so3;
use nalgebra::UnitQuaternion;

/// A vector turned about a fixed unit axis: `v(θ) = along + perp cos θ +
/// side sin θ`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Turning {
    along: Vec3,
    perp: Vec3,
    side: Vec3,
}

impl Turning {
    pub(super) fn new(axis: &Vec3, v: &Vec3) -> Turning {
        let along = axis * axis.dot(v);
        let perp = v - along;
        Turning {
            along,
            perp,
            side: axis.cross(&perp),
        }
    }

    pub(super) fn at(&self, cos: f64, sin: f64) -> Vec3 {
        self.along + self.perp * cos + self.side * sin
    }
}

/// A hinge's motion: `θ̈ = c_cos cos θ + c_sin sin θ` from the start pose.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Turn {
    /// Orientation and centre of mass relative to `point` at `θ = 0`.
    pub(super) q0: UnitQuaternion<f64>,
    pub(super) r0: Vec3,
    /// 1/s².
    pub(super) c_cos: f64,
    pub(super) c_sin: f64,
    /// `(θ, θ̇)` every [`STEP`](super::STEP) from the start.
    pub(super) table: Vec<[f64; 2]>,
}

impl Turn {
    pub(super) fn accel(&self, th: f64) -> f64 {
        self.c_cos * th.cos() + self.c_sin * th.sin()
    }

    pub(super) fn rk4(&self, th: f64, w: f64, h: f64) -> (f64, f64) {
        let k1 = (w, self.accel(th));
        let k2 = (w + 0.5 * h * k1.1, self.accel(th + 0.5 * h * k1.0));
        let k3 = (w + 0.5 * h * k2.1, self.accel(th + 0.5 * h * k2.0));
        let k4 = (w + h * k3.1, self.accel(th + h * k3.0));
        (
            th + h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0),
            w + h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1),
        )
    }

    /// Angle and rate `tau` seconds in (`tau` within the table).
    pub(super) fn angle(&self, tau: f64) -> (f64, f64) {
        let k = ((tau / super::STEP).floor() as usize).min(self.table.len() - 1);
        let [th, w] = self.table[k];
        let rest = tau - k as f64 * super::STEP;
        if rest <= 0.0 {
            (th, w)
        } else {
            self.rk4(th, w, rest)
        }
    }
}

/// What the force check needs at each angle: the centre of mass from the
/// line and `I_p a` (the inertia about the line's point turns with the
/// body: `I_p(θ) a = R(θ) I_p(0) a`).
pub(super) struct Hinge {
    r: Turning,
    ipa: Turning,
}

impl Hinge {
    pub(super) fn new(axis: &Vec3, r0: &Vec3, ipa0: &Vec3) -> Hinge {
        Hinge {
            r: Turning::new(axis, r0),
            ipa: Turning::new(axis, ipa0),
        }
    }

    pub(super) fn at(&self, th: f64) -> (Vec3, Vec3) {
        let (sin, cos) = th.sin_cos();
        (self.r.at(cos, sin), self.ipa.at(cos, sin))
    }
}

/// Where the body lands, in closed form: each point's height over the
/// contact plane is `c₀ + A cos(θ − φ)` less its radius, so the angles
/// about the start at which no point is below `floor` make one interval
/// `[lo, hi]`, and the pivot lands when the angle first leaves it.
pub(super) struct Landing {
    /// The interval, and the point (part, body-frame offset) that lands at
    /// each end.
    lo: (f64, Option<(usize, Vec3)>),
    hi: (f64, Option<(usize, Vec3)>),
}

impl Landing {
    pub(super) fn new(
        axis: &Vec3,
        normal: &Vec3,
        pts: &[&(usize, Vec3, f64, Vec3)],
        floor: f64,
    ) -> Landing {
        let mut out = Landing {
            lo: (f64::NEG_INFINITY, None),
            hi: (f64::INFINITY, None),
        };
        for (k, v, radius, r) in pts {
            let t = Turning::new(axis, r);
            let (c0, c1, c2) = (
                normal.dot(&t.along),
                normal.dot(&t.perp),
                normal.dot(&t.side),
            );
            let amp = c1.hypot(c2);
            // `amp cos(θ − φ) ≥ floor + radius − c₀` on `|θ − φ| ≤ δ`.
            let need = floor + radius - c0;
            if amp <= 0.0 || need <= -amp {
                continue;
            }
            let phi = c2.atan2(c1);
            let delta = (need / amp).clamp(-1.0, 1.0).acos();
            if phi + delta < out.hi.0 {
                out.hi = (phi + delta, Some((*k, *v)));
            }
            if phi - delta > out.lo.0 {
                out.lo = (phi - delta, Some((*k, *v)));
            }
        }
        out
    }

    /// The point that has landed at angle `th`, if any.
    pub(super) fn crossed(&self, th: f64) -> Option<(usize, Vec3)> {
        if th > self.hi.0 {
            self.hi.1
        } else if th < self.lo.0 {
            self.lo.1
        } else {
            None
        }
    }
}

/// The box (intervals along `axis`, across it in the contact plane of
/// `normal`, and along `normal`) of the points `pts` turned through every
/// angle in `[lo, hi]` about `axis`: each coordinate is `c₀ + A cos(θ − φ)`,
/// whose extremes over an interval are at its ends or at `φ` and `φ + π`
/// (mod 2π).
pub(super) fn swept_box(
    axis: &Vec3,
    normal: &Vec3,
    pts: &[(usize, Vec3, f64, Vec3)],
    lo: f64,
    hi: f64,
) -> [(f64, f64); 3] {
    use std::f64::consts::{PI, TAU};
    let dirs = [*axis, axis.cross(normal), *normal];
    // Whether some `θ ≡ at (mod 2π)` lies in `[lo, hi]`.
    let reaches = |at: f64| hi - lo >= TAU || at + TAU * ((lo - at) / TAU).ceil() <= hi;
    let mut swept = [(f64::INFINITY, f64::NEG_INFINITY); 3];
    for (.., radius, r) in pts {
        let t = Turning::new(axis, r);
        for (iv, d) in swept.iter_mut().zip(&dirs) {
            let (c0, c1, c2) = (d.dot(&t.along), d.dot(&t.perp), d.dot(&t.side));
            let at = |th: f64| c0 + c1 * th.cos() + c2 * th.sin();
            let (mut min, mut max) = (at(lo).min(at(hi)), at(lo).max(at(hi)));
            let amp = c1.hypot(c2);
            let phi = c2.atan2(c1);
            if reaches(phi) {
                max = c0 + amp;
            }
            if reaches(phi + PI) {
                min = c0 - amp;
            }
            *iv = (iv.0.min(min - radius), iv.1.max(max + radius));
        }
    }
    swept
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed-form landing angles against the heights of the turned
    /// points sampled every 1e-5 rad: no point is below the floor inside
    /// the interval, and the named point is just past either end.
    #[test]
    fn the_landing_interval_is_where_no_point_is_below_the_floor() {
        let axis = Vec3::new(0.2, 1.0, -0.1).normalize();
        let normal = axis.cross(&Vec3::x()).normalize();
        let pts: Vec<(usize, Vec3, f64, Vec3)> = [
            (Vec3::new(0.3, 0.1, 0.2), 0.0),
            (Vec3::new(-0.2, 0.05, 0.15), 0.01),
            (Vec3::new(0.05, -0.3, 0.4), 0.0),
        ]
        .iter()
        .enumerate()
        .map(|(k, (r, radius))| (k, Vec3::new(k as f64, 0.0, 0.0), *radius, *r))
        .collect();
        let refs: Vec<&(usize, Vec3, f64, Vec3)> = pts.iter().collect();
        let height = |th: f64| {
            let turn = exp_so3(&(axis * th));
            pts.iter()
                .map(|(k, _, radius, r)| (normal.dot(&(turn * r)) - radius, *k))
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .unwrap()
        };
        let floor = height(0.0).0 - 0.01;
        let landing = Landing::new(&axis, &normal, &refs, floor);
        let (lo, hi) = (landing.lo.0, landing.hi.0);
        assert!(
            lo < 0.0 && hi > 0.0 && hi - lo < std::f64::consts::TAU,
            "[{lo}, {hi}]"
        );
        let n = 100_000;
        for k in 0..=n {
            let th = lo + (hi - lo) * k as f64 / n as f64;
            assert!(height(th).0 >= floor - 1e-12, "below at {th}");
            assert!(landing.crossed(th).is_none());
        }
        for (end, step) in [(hi, 1e-5), (lo, -1e-5)] {
            let (h, k) = height(end + step);
            assert!(h < floor, "not below just past {end}");
            assert_eq!(landing.crossed(end + step).map(|p| p.0), Some(k));
            assert_eq!(landing.crossed(end + step).map(|p| p.1.x), Some(k as f64));
        }
    }

    /// The closed-form box against the points turned at 20,001 sampled
    /// angles: it holds every sample and is no larger than they are (to
    /// the angle between two samples).
    #[test]
    fn the_swept_box_is_the_box_of_every_turned_point() {
        let axis = Vec3::new(0.3, -0.2, 0.9).normalize();
        let normal = axis.cross(&Vec3::x()).normalize();
        let pts: Vec<(usize, Vec3, f64, Vec3)> = [
            (Vec3::new(0.4, 0.1, -0.2), 0.0),
            (Vec3::new(-0.1, 0.3, 0.5), 0.02),
            (Vec3::new(0.0, -0.25, 0.05), 0.0),
        ]
        .iter()
        .enumerate()
        .map(|(k, (r, radius))| (k, *r, *radius, *r))
        .collect();
        let dirs = [axis, axis.cross(&normal), normal];
        for (lo, hi) in [
            (0.0, 0.0),
            (-0.3, 0.2),
            (0.0, 2.5),
            (-1.0, 4.0),
            (-7.0, 0.5),
        ] {
            let boxed = swept_box(&axis, &normal, &pts, lo, hi);
            let mut sampled = [(f64::INFINITY, f64::NEG_INFINITY); 3];
            let n = 20_000;
            for k in 0..=n {
                let th = lo + (hi - lo) * k as f64 / n as f64;
                let turn = exp_so3(&(axis * th));
                for (.., radius, r) in &pts {
                    let p = turn * r;
                    for (iv, d) in sampled.iter_mut().zip(&dirs) {
                        *iv = (iv.0.min(d.dot(&p) - radius), iv.1.max(d.dot(&p) + radius));
                    }
                }
            }
            let gap = 0.7 * (hi - lo) / n as f64;
            for (b, s) in boxed.iter().zip(&sampled) {
                assert!(
                    b.0 <= s.0 + 1e-12 && b.1 >= s.1 - 1e-12,
                    "[{lo}, {hi}]: {b:?} {s:?}"
                );
                assert!(
                    b.0 >= s.0 - gap - 1e-12 && b.1 <= s.1 + gap + 1e-12,
                    "[{lo}, {hi}]: {b:?} {s:?}"
                );
            }
        }
    }
}
