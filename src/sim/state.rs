//! The state of one rigid body and the queries on it (a point, its
//! velocity, the pose).

use crate::math::Vec3;
use nalgebra::UnitQuaternion;

/// The state of one rigid body (docs/design.md §2).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyState {
    /// Centre-of-mass position, m.
    pub x: Vec3,
    /// Orientation, body frame to world.
    pub q: UnitQuaternion<f64>,
    /// Linear velocity, m/s.
    pub v: Vec3,
    /// Angular velocity in the world frame, rad/s.
    pub w: Vec3,
}

impl BodyState {
    /// World position of a body-frame point.
    pub fn point(&self, p: &Vec3) -> Vec3 {
        self.x + self.q * p
    }

    /// The body's pose: body frame to world.
    pub fn pose(&self) -> nalgebra::Isometry3<f64> {
        nalgebra::Isometry3::from_parts(nalgebra::Translation3::from(self.x), self.q)
    }

    /// Velocity of the body's material point at the world position `p`.
    pub fn velocity_at(&self, p: &Vec3) -> Vec3 {
        self.v + self.w.cross(&(p - self.x))
    }

    /// Velocity of a body-frame point.
    pub fn point_velocity(&self, p: &Vec3) -> Vec3 {
        self.v + self.w.cross(&(self.q * p))
    }

    /// Whether every number is finite.
    pub fn is_finite(&self) -> bool {
        self.x
            .iter()
            .chain(self.v.iter())
            .chain(self.w.iter())
            .all(|v| v.is_finite())
            && self.q.coords.iter().all(|v| v.is_finite())
    }

    /// The exponential-map vector of the orientation (|r| ≤ π).
    pub fn orientation_vector(&self) -> Vec3 {
        crate::math::log_so3(&self.q)
    }
}

/// Which side of an impulse a state query refers to when the time is
/// exactly an event time: the scene's one [`Side`] (`Post` is also the
/// value at any other time).
pub use crate::scene::Side;
