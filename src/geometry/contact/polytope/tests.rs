use super::*;
use crate::geometry::Geometry;
use crate::math::Rng;
use nalgebra::{Translation3, UnitQuaternion};
use parry3d_f64::query;

fn pose(x: Vec3, axis_angle: Vec3) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(x),
        UnitQuaternion::from_scaled_axis(axis_angle),
    )
}

fn cuboid(h: [f64; 3]) -> Part {
    Geometry::cuboid(Vec3::from(h)).unwrap().parts.remove(0)
}

/// The scissors' handle: a hexagonal prism, a hull that is not a box.
fn prism() -> Part {
    let mut pts = Vec::new();
    for z in [-0.002, 0.002] {
        for k in 0..6 {
            let a = std::f64::consts::PI / 3.0 * f64::from(k);
            pts.push(Vec3::new(0.016 * a.cos(), 0.016 * a.sin(), z));
        }
    }
    Geometry::convex_hull(&pts).unwrap().parts.remove(0)
}

fn decided(pa: &Part, wa: &Isometry3<f64>, pb: &Part, wb: &Isometry3<f64>) -> Contact {
    match contact(pa, wa, pb, wb, f64::INFINITY) {
        Some(Decided::Contact(c)) => c,
        other => panic!("not decided: {other:?}"),
    }
}

/// A box tilted about two axes so that one corner is lowest, held over
/// a slab's top face: its distance is that corner's height, above or
/// below the face, to round-off, with the face's own normal and the
/// corner and its foot as witnesses.
#[test]
fn a_corner_over_a_face_is_its_height() {
    let (a, slab) = (cuboid([0.05, 0.03, 0.02]), cuboid([0.5, 0.5, 0.1]));
    let turn = Vec3::new(0.3, -0.4, 0.1);
    let low = a
        .vertices()
        .iter()
        .map(|v| UnitQuaternion::from_scaled_axis(turn) * v)
        .fold(
            Vec3::repeat(f64::INFINITY),
            |m, v| if v.z < m.z { v } else { m },
        );
    for h in [0.2, 1e-3, 1e-9, 0.0, -1e-9, -1e-4] {
        let wa = pose(Vec3::new(0.1, -0.05, 0.1 + h - low.z), turn);
        let c = decided(&a, &wa, &slab, &Isometry3::identity());
        assert!((c.distance - h).abs() < 1e-15, "h {h}: {}", c.distance);
        assert_eq!(c.normal, Vec3::z(), "h {h}");
        let corner = wa.translation.vector + low;
        assert!(
            (c.point_a - corner).norm() < 1e-15,
            "h {h}: {:?}",
            c.point_a
        );
        assert!((c.point_b - Vec3::new(corner.x, corner.y, 0.1)).norm() < 1e-15);
    }
}

/// A box stood on an edge along x, over a box stood on an edge along y:
/// the edges cross, and the distance is the gap between them, along the
/// vertical, with the crossing points as witnesses.
#[test]
fn crossing_edges_are_the_gap_between_them() {
    let (a, b) = (cuboid([0.1, 0.02, 0.02]), cuboid([0.02, 0.1, 0.02]));
    let r = 0.02 * 2f64.sqrt();
    let q = std::f64::consts::FRAC_PI_4;
    for gap in [1e-2, 1e-9, -1e-9, -1e-5] {
        let wa = pose(
            Vec3::new(0.01, -0.02, 2.0 * r + gap),
            Vec3::new(q, 0.0, 0.0),
        );
        let wb = pose(Vec3::zeros(), Vec3::new(0.0, q, 0.0));
        let c = decided(&a, &wa, &b, &wb);
        assert!(
            (c.distance - gap).abs() < 1e-15,
            "gap {gap}: {}",
            c.distance
        );
        assert!((c.normal - Vec3::z()).norm() < 1e-15, "{:?}", c.normal);
        assert!((c.point_a - Vec3::new(0.0, -0.02, r + gap)).norm() < 1e-15);
        assert!((c.point_b - Vec3::new(0.0, -0.02, r)).norm() < 1e-15);
    }
}

/// A face lying flush on a face, or an edge on a face: the contact is a
/// patch, and its witness is left to parry.
#[test]
fn flush_contacts_are_left_to_parry() {
    let (a, slab) = (cuboid([0.05, 0.03, 0.02]), cuboid([0.5, 0.5, 0.1]));
    let flat = pose(Vec3::new(0.0, 0.0, 0.12 + 1e-6), Vec3::new(0.0, 0.0, 0.4));
    assert_eq!(contact(&a, &flat, &slab, &Isometry3::identity(), 1.0), None);
    let edge = pose(Vec3::new(0.0, 0.0, 0.12 + 1e-6), Vec3::new(0.3, 0.0, 0.0));
    assert_eq!(contact(&a, &edge, &slab, &Isometry3::identity(), 1.0), None);
}

/// Random poses of a box and of a hexagonal prism against a box, from
/// 1e-3 m inside to 0.1 m apart: where the axes decide, parry agrees
/// (its GJK stops at a relative 1e-7; normals compared where parry's is
/// not that of a gap of round-off)
/// and a pair found beyond the distance asked is beyond it for parry too;
/// and they decide most of them.
#[test]
fn where_the_axes_decide_parry_agrees() {
    let b = cuboid([0.2, 0.2, 0.02]);
    let mut rng = Rng(7);
    let mut asked = 0;
    let mut answered = 0;
    for a in [cuboid([0.08, 0.005, 0.002]), prism()] {
        for _ in 0..2000 {
            let turn = Vec3::new(rng.gauss(), rng.gauss(), rng.gauss());
            let wa = pose(Vec3::zeros(), turn);
            // Lift `a` to a random gap over the slab's top, anywhere over it.
            let low = a
                .vertices()
                .iter()
                .map(|v| (wa * nalgebra::Point3::from(*v)).z)
                .fold(f64::INFINITY, f64::min);
            let gap =
                10f64.powf(rng.range(-12.0, -1.0)) * if rng.uniform() < 0.3 { -0.01 } else { 1.0 };
            let x = Vec3::new(
                rng.range(-0.25, 0.25),
                rng.range(-0.25, 0.25),
                0.02 + gap - low,
            );
            let wa = pose(x, turn);
            let wb = Isometry3::identity();
            let limit = rng.range(0.0, 0.05);
            let sa = a.shape.as_ref().unwrap();
            let sb = b.shape.as_ref().unwrap();
            let theirs = query::contact(&wa, sa.as_ref(), &wb, sb.as_ref(), limit).unwrap();
            asked += 1;
            match contact(&a, &wa, &b, &wb, limit) {
                Some(Decided::Beyond) => {
                    answered += 1;
                    assert!(theirs.is_none_or(|c| c.dist > limit - 1e-9), "{theirs:?}");
                }
                Some(Decided::Contact(c)) => {
                    answered += 1;
                    let t = theirs.expect("parry finds the contact too");
                    let tol = 1e-9 + 1e-7 * t.dist.abs();
                    assert!(
                        (c.distance - t.dist).abs() < tol,
                        "{} vs {}",
                        c.distance,
                        t.dist
                    );
                    // Touching, parry's normal is the direction of a gap of
                    // round-off (1e-5 rad off at 1e-12 m); ours is the face's.
                    if t.dist.abs() > 1e-6 {
                        let n = -t.normal1.into_inner();
                        assert!((c.normal - n).norm() < 1e-6, "{:?} vs {n:?}", c.normal);
                    }
                    assert!(c.distance <= limit);
                }
                None => {}
            }
        }
    }
    assert!(answered * 10 >= asked * 7, "decided {answered} of {asked}");
}
