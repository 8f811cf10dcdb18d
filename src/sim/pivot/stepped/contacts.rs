//! The contacts of a stepped body (`sim::pivot::stepped`): found every
//! step on every obstacle, with the features that make each, so that its
//! gap can be followed through the step's drift.

use super::{SteppedStart, drift};
use crate::geometry::{Corner, PartKind, part_near_points};
use crate::math::Vec3;
use crate::scene::Scene;
use crate::sim::rest;
use crate::sim::state::BodyState;

/// One contact of the body with an obstacle.
#[derive(Debug, Clone, Copy)]
pub(super) struct Touch {
    pub(super) obstacle: usize,
    pub(super) part_b: usize,
    pub(super) part_a: usize,
    /// The contact point on the body, from its centre of mass (world).
    pub(super) r: Vec3,
    /// Unit normal out of the obstacle, and the signed gap, m.
    pub(super) normal: Vec3,
    pub(super) distance: f64,
    pub(super) friction: f64,
    pub(super) restitution: f64,
    /// What makes the contact, to follow its gap as the body moves.
    pub(super) feature: Feature,
    /// How far the gap falls short of its linear prediction over the
    /// step (`gap(h) − d − h n · u`), m; set by [`follow`].
    pub(super) turn: f64,
    /// The same contact in the next step has the same key (obstacle,
    /// parts, and the corner's kind and feature indices).
    pub(super) key: [usize; 5],
}

/// The features of a contact, to evaluate its gap at other body states.
#[derive(Debug, Clone, Copy)]
pub(super) enum Feature {
    /// A body point (a corner, or a ball's centre `radius` behind the
    /// surface point) over the obstacle's surface, its plane fixed.
    Point { body: Vec3, radius: f64 },
    /// An obstacle corner (world) under a body face (normal and point,
    /// body frame).
    Under {
        corner: Vec3,
        normal: Vec3,
        point: Vec3,
    },
    /// A body edge (body frame) across an obstacle edge (world), on the
    /// side `sign` of their common normal `u × v`.
    Across {
        a: [Vec3; 2],
        b: [Vec3; 2],
        sign: f64,
    },
}

impl Touch {
    /// The gap at body state `s` (the touch found at `start`).
    pub(super) fn gap_at(&self, start: &BodyState, s: &BodyState) -> f64 {
        let plane = || start.x + self.r - self.normal * self.distance;
        match self.feature {
            Feature::Point { body, radius } => {
                self.normal.dot(&(s.point(&body) - plane())) - radius
            }
            Feature::Under {
                corner,
                normal,
                point,
            } => (s.q * normal).dot(&(s.point(&point) - corner)),
            Feature::Across { a, b, sign } => {
                let (p, u) = (s.point(&a[0]), s.q * (a[1] - a[0]));
                let v = b[1] - b[0];
                let m = u.cross(&v);
                let size = m.norm();
                if size <= 1e-12 * u.norm() * v.norm() {
                    return self.distance + self.normal.dot(&(s.x - start.x));
                }
                sign * m.dot(&(p - b[0])) / size
            }
        }
    }
}

/// Set each touch's [`Touch::turn`] for a step of `h` from `start` with
/// velocities `(v, w)`.
pub(super) fn follow(touches: &mut [Touch], start: &BodyState, v: Vec3, w: Vec3, h: f64) {
    let moved = drift(&BodyState { v, w, ..*start }, h);
    for t in touches {
        let linear = t.distance + h * t.normal.dot(&(v + w.cross(&t.r)));
        t.turn = t.gap_at(start, &moved) - linear;
    }
}

/// Whether a scene's shapes are ones the stepping can find contacts of.
pub(crate) fn supported(scene: &Scene, body: usize) -> bool {
    scene.bodies.len() == 1
        && scene.bodies[body]
            .geometry
            .parts
            .iter()
            .all(|p| matches!(p.kind, PartKind::Convex { .. } | PartKind::Ball { .. }))
        && scene.obstacles.iter().all(|o| {
            o.geometry.parts.iter().all(|p| {
                matches!(
                    p.kind,
                    PartKind::Convex { .. } | PartKind::Ball { .. } | PartKind::HalfSpace { .. }
                )
            })
        })
}

/// How far from the obstacles a body's contacts are looked for: the
/// support band, plus `ahead` seconds at the greatest speed of each
/// part's points (`|v + ω × c| + |ω| ρ` for a part in a sphere of
/// radius `ρ` about `c`), so a part near the axis of a fast spin is
/// not searched as far as the body's reach would take its tips.
#[derive(Debug, Clone, Copy)]
pub(super) struct Margin {
    pub(super) band: f64,
    pub(super) ahead: f64,
    pub(super) v: Vec3,
    pub(super) w: Vec3,
}

impl Margin {
    /// The support band alone.
    pub(super) fn band(band: f64) -> Margin {
        Margin {
            band,
            ahead: 0.0,
            v: Vec3::zeros(),
            w: Vec3::zeros(),
        }
    }

    /// For a part in a sphere of `radius` about `centre` (world, from
    /// the centre of mass).
    fn of(&self, centre: &Vec3, radius: f64) -> f64 {
        let speed = (self.v + self.w.cross(centre)).norm() + self.w.norm() * radius;
        self.band + self.ahead * speed
    }

    /// For the body point at `r` (world, from the centre of mass).
    fn at(&self, r: &Vec3) -> f64 {
        self.band + self.ahead * (self.v + self.w.cross(r)).norm()
    }
}

/// The body's contacts at `s` with every obstacle, within `reach`.
pub(super) fn touches(p: &SteppedStart<'_>, s: &BodyState, reach: &Margin) -> Vec<Touch> {
    let pose = s.pose();
    let body = &p.scene.bodies[p.body];
    let d_reach = p.dynamics.reach;
    let mut out = Vec::new();
    for (o, ob) in p.scene.obstacles.iter().enumerate() {
        let friction = rest::pair_friction(p.scene, p.body, o);
        let restitution = body.restitution * ob.restitution;
        for (part_a, pa) in body.geometry.parts.iter().enumerate() {
            // The part's bounding box, world: centre, axes and half
            // extents (a ball's is its cube).
            let frame_a = pose * pa.offset;
            let margin = reach.of(&(frame_a.translation.vector - s.x), pa.local_radius());
            let (centre, half_a) = pa
                .local_box()
                .unwrap_or((Vec3::zeros(), Vec3::repeat(pa.local_radius())));
            let centre = (frame_a * nalgebra::Point3::from(centre)).coords;
            let axes_a = frame_a.rotation.to_rotation_matrix().into_inner();
            // How far the box reaches along a unit direction.
            let extent = |u: &Vec3| {
                (0..3)
                    .map(|i| u.dot(&axes_a.column(i)).abs() * half_a[i])
                    .sum::<f64>()
            };
            for (part_b, pb) in ob.geometry.parts.iter().enumerate() {
                // Obstacle parts separated from that box by more than the
                // margin (along a half-space's normal, or one of the two
                // boxes' axes) have no near points.
                let frame = ob.pose * pb.offset;
                let far = match (&pb.kind, pb.local_box()) {
                    (PartKind::HalfSpace { normal }, _) => {
                        let n = frame.rotation * normal;
                        n.dot(&(centre - frame.translation.vector)) - extent(&n) > margin
                    }
                    (_, Some((c, half))) => {
                        let axes_b = frame.rotation.to_rotation_matrix().into_inner();
                        let between = centre - (frame * nalgebra::Point3::from(c)).coords;
                        let extent_b = |u: &Vec3| {
                            (0..3)
                                .map(|i| u.dot(&axes_b.column(i)).abs() * half[i])
                                .sum::<f64>()
                        };
                        (0..3).any(|i| {
                            let u: Vec3 = axes_b.column(i).into();
                            u.dot(&between).abs() - half[i] - extent(&u) > margin
                        }) || (0..3).any(|i| {
                            let u: Vec3 = axes_a.column(i).into();
                            u.dot(&between).abs() - half_a[i] - extent_b(&u) > margin
                        })
                    }
                    _ => false,
                };
                if far {
                    continue;
                }
                for q in part_near_points(pa, &pose, pb, &ob.pose, margin) {
                    let back = s.q.inverse();
                    let (kind, index) = match q.corner {
                        Corner::A { index, .. } => (0, index),
                        Corner::B { index, .. } => (1, index),
                        Corner::Crossing { ea, eb, .. } => (2, ea * 4096 + eb),
                        Corner::Ball => (3, 0),
                    };
                    let feature = match q.corner {
                        Corner::A { p, .. } => Feature::Point {
                            body: p,
                            radius: 0.0,
                        },
                        Corner::B { p, .. } => Feature::Under {
                            corner: (ob.pose * nalgebra::Point3::from(p)).coords,
                            normal: back * -q.normal,
                            point: back * (q.point - s.x),
                        },
                        Corner::Crossing { a, b, .. } => {
                            let b = b.map(|e| (ob.pose * nalgebra::Point3::from(e)).coords);
                            let m = (s.q * (a[1] - a[0])).cross(&(b[1] - b[0]));
                            Feature::Across {
                                a,
                                b,
                                sign: if m.dot(&q.normal) < 0.0 { -1.0 } else { 1.0 },
                            }
                        }
                        Corner::Ball => {
                            let radius = match pa.kind {
                                PartKind::Ball { radius } => radius,
                                _ => 0.0,
                            };
                            Feature::Point {
                                body: back * (q.point + q.normal * radius - s.x),
                                radius,
                            }
                        }
                    };
                    // Two edges are kept apart along their common normal
                    // (the part pair's normal there can be a face's).
                    let (normal, distance) = match feature {
                        Feature::Across { a, b, sign } => {
                            let m = (s.q * (a[1] - a[0])).cross(&(b[1] - b[0])) * sign;
                            match m.try_normalize(1e-9 * m.norm().max(f64::MIN_POSITIVE)) {
                                Some(n) if n.dot(&q.normal) > 0.99 => {
                                    (n, n.dot(&(s.point(&a[0]) - b[0])))
                                }
                                _ => (q.normal, q.distance),
                            }
                        }
                        _ => (q.normal, q.distance),
                    };
                    let mut touch = Touch {
                        obstacle: o,
                        part_b,
                        part_a,
                        r: q.point - s.x,
                        normal,
                        distance,
                        friction,
                        restitution,
                        feature,
                        turn: 0.0,
                        key: [o, part_a, part_b, kind, index],
                    };
                    // Features that do not give back the gap found (an edge
                    // crossing beyond an end of either edge) are followed
                    // as the body point there.
                    if (touch.gap_at(s, s) - distance).abs() > 1e-9 * (1.0 + d_reach) {
                        touch.feature = Feature::Point {
                            body: back * (q.point - s.x),
                            radius: 0.0,
                        };
                    }
                    // (The part's margin is its fastest point's.)
                    if touch.distance <= reach.at(&touch.r) {
                        out.push(touch);
                    }
                }
            }
        }
    }
    out
}
