//! Settling a body that comes to rest (or starts sliding) lying on a face.
//!
//! The rest rule freezes a body whose every point moves slower than `v_r`
//! and whose support points lie within the band `δ` of the obstacles'
//! surfaces (`sim::rest`), so a body that came down on a corner and rocked
//! onto a face stops wherever its last micro-collision left it: up to the
//! hop height above the surface and tilted by up to `δ / size` (60 µm and
//! 3e-4 rad for a 40 cm box). When it lies on a face — three or more
//! non-collinear support points, all on one obstacle, on one flat face of
//! the obstacle and one of the body — [`onto_face`] puts it there exactly:
//! the smallest rotation about the centre of mass that makes the body's
//! face flush with the obstacle's, then a shift along the face normal to
//! contact height. The tangent follows the same projection (the height and
//! the tilt no longer depend on the controls): see [`Settled::project`].
//! The run keeps the body where it is instead when settling would push it
//! deeper than the event skin into another body it collides with (a box
//! settling on the floor under another lying on it).

use super::rest::{over_hull, supports};
use super::state::BodyState;
use crate::geometry::{PartKind, flat_faces};
use crate::math::{Mat3, Vec3};
use crate::scene::Scene;
use nalgebra::{DMatrix, UnitQuaternion};

/// Faces within this angle (rad) of each other count as lying on each
/// other (the patch angle of an impact).
const FACE_ANGLE: f64 = 0.02;

/// A body put flat onto an obstacle's face.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Settled {
    /// The settled state (velocities unchanged).
    pub state: BodyState,
    /// The obstacle face's outward unit normal, world.
    pub normal: Vec3,
}

impl Settled {
    /// The settled body's Jacobian from the unsettled one: its height
    /// along the normal and its tilt are fixed by the face, so their rows
    /// vanish; in-plane position and turn about the normal carry over.
    pub(crate) fn project(&self, j: &mut DMatrix<f64>) {
        let n = self.normal;
        let nn: Mat3 = n * n.transpose();
        let jx = (Mat3::identity() - nn) * j.rows(0, 3);
        let jt = nn * j.rows(3, 3);
        j.rows_mut(0, 3).copy_from(&jx);
        j.rows_mut(3, 3).copy_from(&jt);
    }
}

/// Put body `body`, in state `s` and supported within `band` only by the
/// obstacles `among`, flat onto the face it lies on; `None` when it does
/// not lie on a face (a corner, an edge, supports on several obstacles, a
/// ball). `reach` is the body's size (tolerances scale with it).
pub(crate) fn onto_face(
    scene: &Scene,
    body: usize,
    s: &BodyState,
    among: &[usize],
    band: f64,
    reach: f64,
) -> Option<Settled> {
    let mut on = None;
    for &o in among {
        let sup = supports(scene, body, o, s, band);
        if sup.is_empty() {
            continue;
        }
        if on.is_some() {
            return None;
        }
        on = Some((o, sup));
    }
    let (o, sup) = on?;
    let n = sup
        .iter()
        .map(|p| p.normal)
        .sum::<Vec3>()
        .try_normalize(1e-12)?;
    let pts: Vec<Vec3> = sup.iter().map(|p| p.point).collect();
    let tol = 1e-9 + 1e-6 * reach;
    if !over_hull(&pts, &s.x, &n, tol).1 {
        return None;
    }
    let cos = FACE_ANGLE.cos();
    let obstacle = &scene.obstacles[o];
    let face = obstacle
        .geometry
        .parts
        .iter()
        .flat_map(|p| flat_faces(p, &obstacle.pose, &n, cos))
        .filter(|f| pts.iter().all(|p| f.holds(p, band)))
        .max_by(|a, b| a.normal.dot(&n).total_cmp(&b.normal.dot(&n)))?;
    let nf = face.normal;
    let pose = s.pose();
    let own = scene.bodies[body]
        .geometry
        .parts
        .iter()
        .filter(|p| matches!(p.kind, PartKind::Convex { .. }))
        .flat_map(|p| flat_faces(p, &pose, &-nf, cos))
        .filter(|f| {
            pts.iter()
                .all(|p| (f.normal.dot(p) - f.offset).abs() <= band)
        })
        .max_by(|a, b| a.normal.dot(&-nf).total_cmp(&b.normal.dot(&-nf)))?;
    let turn = UnitQuaternion::rotation_between(&own.normal, &-nf)?;
    let on_face = s.x + turn * (own.normal * own.offset - s.x);
    let x = s.x + nf * (face.offset - nf.dot(&on_face));
    let state = BodyState {
        x,
        q: turn * s.q,
        ..*s
    };
    state.is_finite().then_some(Settled { state, normal: nf })
}
