//! Mass and principal inertia of a body from its shape.
//!
//! Everything is computed from the shape's unit-density properties and then
//! scaled by the mass, so the result is a pure function of (shape, mass):
//! a body given by `density` and the same body saved with the resulting
//! `mass` get bit-identical inertia. That is what lets the writer leave the
//! inertia out of a saved file when it adds nothing.
use crate::geometry::{Geometry, GeometryError, MassProps};
use crate::math::{Mat3, Vec3, exp_so3, log_so3};
use nalgebra::{Rotation3, SymmetricEigen, UnitQuaternion};

/// Unit-density mass properties of a bounded geometry (mass = volume, m³).
pub(super) fn unit_props(g: &Geometry) -> Result<MassProps, GeometryError> {
    g.mass_properties(1.0)
}

/// The principal moments (ascending) and axes of the inertia a body of this
/// `mass` gets from its shape; `unit` are the shape's unit-density props.
pub(super) fn implied(unit: &MassProps, mass: f64) -> (Vec3, UnitQuaternion<f64>) {
    let (moments, axes) = principal(&unit.inertia);
    (moments * (mass / unit.mass), axes)
}

/// Principal moments (ascending) and axes of a symmetric tensor: `T = Q
/// diag(m) Qᵀ` with `Q` a proper rotation. Deterministic: a diagonal tensor
/// keeps the coordinate axes (stably sorted by moment), otherwise each axis
/// has its largest component positive and the third is flipped if needed to
/// make `det Q = +1`. The rotation is returned as `exp(log(Q))`, so an
/// exp-map vector that reproduces it exactly exists (the writer relies on this).
pub(super) fn principal(t: &Mat3) -> (Vec3, UnitQuaternion<f64>) {
    let sym = (t + t.transpose()) * 0.5;
    let scale = sym.diagonal().abs().max();
    let off = sym[(0, 1)]
        .abs()
        .max(sym[(0, 2)].abs())
        .max(sym[(1, 2)].abs());
    let (values, vectors) = if off <= 1e-14 * scale {
        (sym.diagonal(), Mat3::identity())
    } else {
        let eig = SymmetricEigen::new(sym);
        (eig.eigenvalues, eig.eigenvectors)
    };
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    let mut q = Mat3::zeros();
    let mut moments = Vec3::zeros();
    for (k, &i) in order.iter().enumerate() {
        let mut axis = vectors.column(i).into_owned();
        let big = axis.iamax();
        if axis[big] < 0.0 {
            axis = -axis;
        }
        q.set_column(k, &axis);
        moments[k] = values[i];
    }
    if q.determinant() < 0.0 {
        let c = -q.column(2).into_owned();
        q.set_column(2, &c);
    }
    let rot = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(q));
    (moments, exp_so3(&log_so3(&rot)))
}

/// Whether principal moments can belong to a rigid body: each at most the
/// sum of the other two (with a relative slack of 1e-12 for rounding).
pub(super) fn triangle_ok(m: &Vec3) -> bool {
    let slack = 1e-12 * m.max();
    m.x + m.y >= m.z - slack && m.y + m.z >= m.x - slack && m.z + m.x >= m.y - slack
}
