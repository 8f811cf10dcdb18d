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

/// Two unit vectors spanning the plane normal to the unit vector `n`, with
/// `n` a right-handed frame (`t1 × t2 = n`): friction-pyramid edges, a
/// support polygon seen along its normal.
pub fn plane_basis(n: &Vec3) -> (Vec3, Vec3) {
    let t1 = n
        .cross(&Vec3::x())
        .try_normalize(1e-6)
        .unwrap_or_else(|| n.cross(&Vec3::y()).normalize());
    (t1, n.cross(&t1))
}

/// True when every entry of the slice is finite (neither NaN nor ±∞).
pub fn all_finite(values: &[f64]) -> bool {
    values.iter().all(|v| v.is_finite())
}
