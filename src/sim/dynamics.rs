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
