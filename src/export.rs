//! `nudge export --gltf`: a simulated motion as binary glTF 2.0 (docs/export.md §2).
//!
//! One node and mesh per body (its shape's triangles, compounds merged),
//! one per obstacle (planes as a large quad, parabolas as a strip, both
//! over the motion's extent), and one animation: per body a translation
//! and a rotation channel, LINEAR, keyed at the frame rate plus just
//! before and at every collision of the body, so an impact is a corner of
//! the curve, not smeared over a frame.
//!
//! nudge is z-up, glTF y-up: every position `(x, y, z)` is written as
//! `(x, z, −y)` and every rotation conjugated by that turn (−90° about x).
//! glTF stores `f32`: poses and times are rounded to it (about 1e-7
//! relative), and a number beyond `f32`'s range is an error, never an
//! infinity in the file.
//!
//! One job per file: [`mesh`] builds the meshes, [`keys`] samples the
//! motion, [`glb`] writes the file.

pub mod glb;
pub mod keys;
pub mod mesh;

use crate::math::Vec3;
use crate::scene::Scene;
use crate::sim::Trajectory;
use nalgebra::UnitQuaternion;

/// Default frames per second.
pub const DEFAULT_FPS: f64 = 60.0;

/// Highest frame rate, per second: the keys are per frame and per body.
pub const MAX_FPS: f64 = 10_000.0;

/// Most animation keys an export may hold over all bodies (each 32 bytes):
/// the file stays below 256 MiB and far below glb's 4 GiB limit.
pub const MAX_KEYS: usize = 1 << 23;

/// Why a motion could not be exported.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ExportError {
    #[error("--fps {0}: give a frame rate above 0 and at most {MAX_FPS}, e.g. --fps 60")]
    Fps(f64),
    #[error(
        "the animation would need {keys} keys (more than {MAX_KEYS}): give a lower --fps or a shorter duration"
    )]
    TooManyKeys { keys: usize },
    #[error(
        "{what} {value:e} is beyond the range of glTF's 32-bit floats: move the scene nearer the origin or shorten it"
    )]
    OutOfRange { what: String, value: f64 },
    #[error("the glTF file would be {bytes} bytes, over the format's 4 GiB: give a lower --fps")]
    TooLarge { bytes: usize },
    #[error("the glTF document could not be written: {0}")]
    Document(String),
}

/// nudge's z-up world to glTF's y-up: `(x, y, z) → (x, z, −y)`.
pub fn to_y_up(v: &Vec3) -> Vec3 {
    Vec3::new(v.x, v.z, -v.y)
}

/// A rotation of nudge's world as the same rotation of glTF's: conjugated
/// by the turn of [`to_y_up`], which maps the quaternion's axis alike.
pub fn rotation_to_y_up(q: &UnitQuaternion<f64>) -> UnitQuaternion<f64> {
    let v = to_y_up(&q.imag());
    UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(q.w, v.x, v.y, v.z))
}

/// Round to `f32`, refusing what is beyond its range (named `what`).
pub(crate) fn single(value: f64, what: impl Fn() -> String) -> Result<f32, ExportError> {
    let v = value as f32;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ExportError::OutOfRange {
            what: what(),
            value,
        })
    }
}

/// The binary glTF of `traj`, the motion of `scene`, sampled at `fps`.
///
/// # Errors
/// A frame rate out of range, too many keys, or a number beyond `f32`.
pub fn to_glb(scene: &Scene, traj: &Trajectory, fps: f64) -> Result<Vec<u8>, ExportError> {
    if !(fps.is_finite() && fps > 0.0 && fps <= MAX_FPS) {
        return Err(ExportError::Fps(fps));
    }
    let tracks = keys::tracks(scene, traj, fps)?;
    let extent = keys::extent(scene, &tracks);
    let bodies = scene
        .bodies
        .iter()
        .map(|b| mesh::body(&b.name, &b.geometry))
        .collect::<Result<Vec<_>, _>>()?;
    let obstacles = scene
        .obstacles
        .iter()
        .map(|o| mesh::obstacle(o, &extent))
        .collect::<Result<Vec<_>, _>>()?;
    glb::write(scene, &bodies, &obstacles, &tracks)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn z_up_becomes_y_up_as_a_proper_rotation() {
        assert_eq!(to_y_up(&Vec3::z()), Vec3::y());
        assert_eq!(to_y_up(&Vec3::y()), -Vec3::z());
        // A turn about nudge's vertical is a turn about glTF's.
        let q = UnitQuaternion::from_axis_angle(&Vec3::z_axis(), 0.7);
        let p = Vec3::new(0.3, -1.2, 2.0);
        let turned = rotation_to_y_up(&q) * to_y_up(&p);
        assert!((turned - to_y_up(&(q * p))).norm() < 1e-15);
        let up = rotation_to_y_up(&q).axis().expect("a turn");
        assert!((up.into_inner() - Vec3::y()).norm() < 1e-15);
    }

    #[test]
    fn numbers_beyond_f32_are_refused() {
        assert_eq!(single(1.5, || "x".into()), Ok(1.5));
        assert!(matches!(
            single(1e39, || "body x".into()),
            Err(ExportError::OutOfRange { .. })
        ));
    }
}
