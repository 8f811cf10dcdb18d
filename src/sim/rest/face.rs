//! Sliding on a face of a hull (`sim::rest`, rule 2): the face a body's
//! supports lie on, and when the slide reaches the face's edge.
//!
//! A body lying on a face of a box or a hull slides as on a half-space
//! while its centre of mass stays over the face: its support patch is its
//! own contact face (which moves with it, rigidly, so the centre of mass
//! stays over it) cut by the obstacle's face, and the centre of mass is
//! over the cut while it is over both. The slide ends when the centre of
//! mass comes within [`EDGE`] of the face's edge: the body flies on from
//! there (it starts to tip over the edge) and its next impact decides
//! again. The time is found by conservative advancement along the
//! closed-form slide (the centre's depth inside the face polygon over a
//! bound of its speed is a time in which it cannot reach the edge), then
//! by Newton's method onto the edge.

use super::Slide;
use crate::geometry::{FlatFace, NearPoint, Part, flat_faces};
use crate::math::Vec3;
use crate::scene::Scene;
use crate::sim::state::BodyState;
use nalgebra::Isometry3;

/// A slide ends this close to the face's edge, in units of the body's
/// reach (it starts only with the centre of mass ten times deeper).
pub(crate) const EDGE: f64 = 1e-7;

/// Conservative-advancement steps before a slide is ended early (creeping
/// along an edge): its end is then only a restart.
const MAX_STEPS: usize = 200;

/// A slide on a face of a hull part of the obstacle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FaceSlide {
    /// The part slid on: the obstacle's other parts are searched as
    /// usual (`beside`: it has some).
    pub part: usize,
    pub beside: bool,
    /// When the slide reaches the face's edge, s after it begins
    /// (infinite when it stops on the face or the simulation ends first).
    pub until: f64,
}

/// The face of `part` (placed by `pose`) facing along `normal` (the
/// impact's) with `com` at least `margin` inside its polygon, and the
/// supports on it: `None` unless every one has the face's normal.
pub(super) fn under(
    part: &Part,
    pose: &Isometry3<f64>,
    normal: &Vec3,
    com: &Vec3,
    margin: f64,
    supports: impl FnOnce() -> Vec<NearPoint>,
) -> Option<(FlatFace, Vec<NearPoint>)> {
    let face = flat_faces(part, pose, normal, 1.0 - 1e-6)
        .into_iter()
        .find(|f| !f.polygon.is_empty() && f.depth(com) >= margin)?;
    let sup = supports();
    let n = face.normal;
    (!sup.is_empty() && sup.iter().all(|p| p.normal.dot(&n) >= 1.0 - 1e-6)).then_some((face, sup))
}

/// When the slide that starts from `s0` first brings the centre of mass
/// within `edge` (m) of the edge of `face`, s after it starts; infinite
/// when not within `horizon` (it stops on the face, or the simulation
/// ends first).
pub(crate) fn until(
    slide: &Slide,
    s0: &BodyState,
    drag_k: Option<f64>,
    face: &FlatFace,
    edge: f64,
    horizon: f64,
) -> f64 {
    // Gravity's pull along an inclined face and a slipping ball's friction
    // can speed a slide up (other friction and drag slow it).
    let lean = slide.accel.norm()
        + if slide.roll.is_some() {
            slide.decel
        } else {
            0.0
        };
    let mut tau = 0.0;
    for _ in 0..MAX_STEPS {
        let s = slide.at(s0, drag_k, tau).state;
        let depth = face.depth(&s.x);
        if depth <= edge {
            return onto_edge(slide, s0, drag_k, face, tau);
        }
        let speed = s.v.norm();
        if speed == 0.0 && lean == 0.0 {
            return f64::INFINITY;
        }
        // Within `dt` the centre moves less than `speed·dt + lean·dt²/2`,
        // which this `dt` keeps below `depth`.
        tau += depth / (speed + (lean * depth).sqrt());
        if tau.is_nan() || tau >= horizon {
            return f64::INFINITY;
        }
    }
    tau
}

/// The face a slide is on; `None` for a slide on a half-space.
pub(crate) fn of(scene: &Scene, slide: &Slide) -> Option<FlatFace> {
    let o = &scene.obstacles[slide.obstacle];
    let part = o.geometry.parts.get(slide.face?.part)?;
    flat_faces(part, &o.pose, &slide.normal, 1.0 - 1e-6)
        .into_iter()
        .find(|f| !f.polygon.is_empty())
}

/// `tau`, within a hair of the edge, moved onto it by Newton's method on
/// the centre's depth (its rate is `−out·v`): the end time's round-off
/// is then the motion's, as the Jacobian's saltation assumes.
fn onto_edge(
    slide: &Slide,
    s0: &BodyState,
    drag_k: Option<f64>,
    face: &FlatFace,
    mut tau: f64,
) -> f64 {
    for _ in 0..8 {
        let s = slide.at(s0, drag_k, tau).state;
        let Some((depth, out)) = face.nearest_edge(&s.x) else {
            break;
        };
        let rate = out.dot(&s.v);
        if rate.is_nan() || rate <= 0.0 {
            break;
        }
        let step = depth / rate;
        tau += step;
        if step.abs() <= 1e-15 * tau.max(1.0) {
            break;
        }
    }
    tau
}
