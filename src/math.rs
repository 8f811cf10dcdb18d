//! Small linear-algebra helpers on SO(3): skew matrices, the exponential and
//! logarithm maps, and the left/right Jacobians of SO(3) with their inverses.
//!
//! Conventions: a world-frame (left) rotation perturbation `δθ` acts as
//! `R' = exp([δθ]×) R`; a body-frame (right) perturbation `η` as
//! `R' = R exp([η]×)`. The exponential-map vector `r` of an orientation gives
//! `R = exp([r]×)` and `δθ = J_l(r) δr`.

pub mod nnls;
mod rng;
mod so3;

pub use rng::Rng;
pub use so3::{
    Mat3, Vec3, exp_so3, left_jacobian, left_jacobian_inv, log_so3, reparameterize, right_jacobian,
    right_jacobian_inv, right_jacobian_inv_mul, rotation_matrix, skew,
};

/// True when every entry of the slice is finite (neither NaN nor ±∞).
pub fn all_finite(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite())
}
