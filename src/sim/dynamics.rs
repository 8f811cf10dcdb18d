//! Per-body constants the simulator needs, resolved once from the scene.

use super::state::BodyState;
use crate::controls::Controls;
use crate::math::{Mat3, Vec3};
use crate::scene::{Block, Scene};

/// A body's mass properties and which terms of its motion are assembled.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyDynamics {
    /// kg.
    pub mass: f64,
    /// Principal moments, kg·m².
    pub principal: Vec3,
    /// Principal axes in the body frame (columns).
    pub axes: Mat3,
    /// Inertia tensor in the body frame and its inverse.
    pub inertia: Mat3,
    pub inertia_inv: Mat3,
    /// Drag rate `k = c/m` (1/s) when the `drag` effect is listed, else `None`
    /// (the drag term is then never evaluated).
    pub drag_k: Option<f64>,
    /// Drag coefficient `c`, kg/s.
    pub drag_c: f64,
    /// Whether rotation is integrated numerically (gyroscopic term listed and
    /// the body non-isotropic or its inertia a free control); otherwise the
    /// angular velocity is constant and rotation is closed form.
    pub integrate: bool,
    /// Distance from the centre of mass to the farthest point, m.
    pub reach: f64,
}

impl BodyDynamics {
    /// Resolve body `i` of the scene.
    pub fn new(scene: &Scene, i: usize, controls: &Controls) -> BodyDynamics {
        let b = &scene.bodies[i];
        let axes = *b.inertia_axes.to_rotation_matrix().matrix();
        let inertia = b.inertia_tensor();
        let inv_diag = Mat3::from_diagonal(&b.inertia.map(|v| 1.0 / v));
        let inertia_inv = axes * inv_diag * axes.transpose();
        let inertia_free = controls.body_column(i, Block::Inertia).is_some();
        BodyDynamics {
            mass: b.mass,
            principal: b.inertia,
            axes,
            inertia,
            inertia_inv,
            drag_k: scene.effects.drag.then(|| b.drag / b.mass),
            drag_c: b.drag,
            integrate: scene.effects.gyroscopic && (!b.isotropic() || inertia_free),
            reach: b.geometry.reach(),
        }
    }

    /// How fast the body-frame angular velocity `w` turns under Euler's
    /// equations, rad/s: `max |I_j − I_k| / I_i · max(|ω_j|, |ω_k|)` over
    /// the principal axes. A fixed step must be well below its inverse.
    pub fn precession_rate(&self, w: &Vec3) -> f64 {
        let wp = self.axes.transpose() * w;
        let i = self.principal;
        (0..3)
            .map(|a| {
                let (j, k) = ((a + 1) % 3, (a + 2) % 3);
                (i[j] - i[k]).abs() / i[a] * wp[j].abs().max(wp[k].abs())
            })
            .fold(0.0, f64::max)
    }

    /// The largest angular speed and angular acceleration (rad/s,
    /// rad/s²) the body reaches in torque-free motion from state `s`:
    /// exact maxima over the motion, not bounds of a single conserved
    /// quantity.
    ///
    /// In principal coordinates, `u_i = ω_i²` obeys two linear
    /// conservation laws, `Σ I_i u_i = 2E` and `Σ I_i² u_i = |L|²`, so the
    /// motion keeps `u` on the segment `u(s) = u₀ + s d`, `u ≥ 0`, with
    /// `d = (I₁ I₂ (I₂ − I₁), I₀ I₂ (I₀ − I₂), I₀ I₁ (I₁ − I₀))` (the cross
    /// product of `(I_i)` and `(I_i²)`; the polhode sweeps the segment to
    /// its ends). `|ω|² = Σ u_i` is linear in `s` and
    /// `|ω̇|² = Σ k_i² u_j u_k` (`k_i = (I_j − I_k) / I_i`, Euler's
    /// equations) quadratic: both are maximised at an end or at the
    /// parabola's vertex. The maxima carry a 1e-6 relative margin for the
    /// integrator's drift off the conserved values.
    pub fn spin_envelope(&self, s: &BodyState) -> (f64, f64) {
        let w = self.axes.transpose() * (s.q.inverse() * s.w);
        let i = self.principal;
        let u = w.component_mul(&w);
        let d = Vec3::new(
            i[1] * i[2] * (i[2] - i[1]),
            i[0] * i[2] * (i[0] - i[2]),
            i[0] * i[1] * (i[1] - i[0]),
        );
        let scale = d.amax();
        let (lo, hi) = if scale > 0.0 {
            let d = d / scale;
            (0..3).fold((f64::NEG_INFINITY, f64::INFINITY), |(lo, hi), k| {
                if d[k] > 0.0 {
                    (lo.max(-u[k] / d[k]), hi)
                } else if d[k] < 0.0 {
                    (lo, hi.min(u[k] / -d[k]))
                } else {
                    (lo, hi)
                }
            })
        } else {
            (0.0, 0.0)
        };
        let d = if scale > 0.0 { d / scale } else { d };
        let (lo, hi) = (lo.min(0.0), hi.max(0.0));
        let speed2 = |x: f64| (u + d * x).sum();
        let k = Vec3::from_fn(|a, _| (i[(a + 1) % 3] - i[(a + 2) % 3]) / i[a]);
        let accel2 = |x: f64| {
            let v = u + d * x;
            (0..3)
                .map(|a| k[a] * k[a] * v[(a + 1) % 3].max(0.0) * v[(a + 2) % 3].max(0.0))
                .sum::<f64>()
        };
        // `|ω̇|²(s) = A + B s + C s²`: its vertex, when a maximum inside.
        let c = (0..3)
            .map(|a| k[a] * k[a] * d[(a + 1) % 3] * d[(a + 2) % 3])
            .sum::<f64>();
        let b = (0..3)
            .map(|a| {
                k[a] * k[a] * (u[(a + 1) % 3] * d[(a + 2) % 3] + u[(a + 2) % 3] * d[(a + 1) % 3])
            })
            .sum::<f64>();
        let vertex = -b / (2.0 * c);
        let mut a2 = accel2(lo).max(accel2(hi));
        if c < 0.0 && vertex > lo && vertex < hi {
            a2 = a2.max(accel2(vertex));
        }
        let margin = 1.0 + 1e-6;
        let w_max = (speed2(lo).max(speed2(hi)).max(0.0).sqrt() * margin).max(s.w.norm());
        // Euler's equations' own rounding (an isotropic body's `ω × Iω`).
        let round = 1e-12 * w_max * w_max * i.max() / i.min();
        (w_max, a2.max(0.0).sqrt() * margin + round)
    }

    /// World inverse inertia for orientation matrix `r`.
    pub fn world_inertia_inv(&self, r: &Mat3) -> Mat3 {
        r * self.inertia_inv * r.transpose()
    }

    /// Angular acceleration (world) of the torque-free motion; zero when
    /// rotation is not integrated (the term is then absent or vanishes).
    pub fn angular_acceleration(&self, s: &BodyState) -> Vec3 {
        if !self.integrate {
            return Vec3::zeros();
        }
        let wb = s.q.inverse() * s.w;
        s.q * super::integrator::euler_rhs(&self.inertia, &self.inertia_inv, &wb)
    }

    /// Linear acceleration under gravity `g` and drag.
    pub fn linear_acceleration(&self, s: &BodyState, g: &Vec3) -> Vec3 {
        match self.drag_k {
            Some(k) => g - s.v * k,
            None => *g,
        }
    }

    /// `F(q)` in tangent coordinates: `(ẋ, θ̇, v̇, ω̇) = (v, ω, a, α)`.
    pub fn state_derivative(&self, s: &BodyState, g: &Vec3) -> [Vec3; 4] {
        [
            s.v,
            s.w,
            self.linear_acceleration(s, g),
            self.angular_acceleration(s),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Rng, exp_so3};
    use crate::sim::integrator::euler_rhs;

    /// Torque-free motion from random spins of random bodies (all moments
    /// distinct, two equal, two within 1e-7, all equal), integrated finely
    /// with RK4 over about thirty turns: the angular speed and acceleration
    /// never exceed the envelope, and the envelope is reached (the
    /// polhode sweeps its segment end to end).
    #[test]
    fn the_spin_envelope_bounds_torque_free_motion_and_is_reached() {
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let (mut reached_w, mut reached_a, mut distinct) = (Vec::new(), Vec::new(), 0);
        for case in 0..80 {
            let mut principal = Vec3::new(
                rng.range(0.1, 2.0),
                rng.range(0.1, 2.0),
                rng.range(0.1, 2.0),
            );
            match case % 4 {
                1 => principal.y = principal.x,
                2 => principal.y = principal.x * (1.0 + 1e-7),
                3 => principal = Vec3::repeat(principal.x),
                _ => distinct += 1,
            }
            let axes = *exp_so3(&Vec3::new(
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
            ))
            .to_rotation_matrix()
            .matrix();
            let inertia = axes * Mat3::from_diagonal(&principal) * axes.transpose();
            let inertia_inv =
                axes * Mat3::from_diagonal(&principal.map(|i| 1.0 / i)) * axes.transpose();
            let d = BodyDynamics {
                mass: 1.0,
                principal,
                axes,
                inertia,
                inertia_inv,
                drag_k: None,
                drag_c: 0.0,
                integrate: true,
                reach: 1.0,
            };
            let q = exp_so3(&Vec3::new(
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
                rng.range(-2.0, 2.0),
            ));
            let mut wb = Vec3::new(
                rng.range(-10.0, 10.0),
                rng.range(-10.0, 10.0),
                rng.range(-10.0, 10.0),
            );
            let s = BodyState {
                x: Vec3::zeros(),
                q,
                v: Vec3::zeros(),
                w: q * wb,
            };
            let (w_max, a_max) = d.spin_envelope(&s);
            let f = |w: &Vec3| euler_rhs(&inertia, &inertia_inv, w);
            let h = 0.002 / wb.norm();
            let (mut top_w, mut top_a): (f64, f64) = (0.0, 0.0);
            for _ in 0..15_000 {
                let (wn, an) = (wb.norm(), f(&wb).norm());
                assert!(
                    wn <= w_max && an <= a_max,
                    "|ω| {wn} over {w_max} or |ω̇| {an} over {a_max} (moments {principal:?})"
                );
                (top_w, top_a) = (top_w.max(wn), top_a.max(an));
                let k1 = f(&wb);
                let k2 = f(&(wb + k1 * (0.5 * h)));
                let k3 = f(&(wb + k2 * (0.5 * h)));
                let k4 = f(&(wb + k3 * h));
                wb += (k1 + 2.0 * (k2 + k3) + k4) * (h / 6.0);
            }
            reached_w.push(top_w / w_max);
            if a_max > 0.0 {
                reached_a.push(top_a / a_max);
            }
        }
        let median = |v: &mut Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v[v.len() / 2]
        };
        assert_eq!(distinct, 20);
        let (mw, ma) = (median(&mut reached_w), median(&mut reached_a));
        assert!(
            mw > 0.999 && ma > 0.99,
            "envelope reached: median |ω| {mw}, |ω̇| {ma}"
        );
    }
}
