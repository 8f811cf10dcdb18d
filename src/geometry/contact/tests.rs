use super::*;
use nalgebra::{Translation3, UnitQuaternion};

fn at(x: f64, y: f64, z: f64) -> Isometry3<f64> {
    Isometry3::from_parts(Translation3::new(x, y, z), UnitQuaternion::identity())
}

/// A face holds the points on it and near its edges, not those beside
/// it or off its plane.
#[test]
fn a_flat_face_holds_the_points_on_it() {
    let cube = Geometry::cuboid(Vec3::new(0.5, 0.5, 0.5)).unwrap();
    let top = flat_faces(&cube.parts[0], &at(0.0, 0.0, 0.0), &Vec3::z(), 0.999);
    assert_eq!(top.len(), 1, "{top:?}");
    let f = &top[0];
    assert!((f.normal - Vec3::z()).norm() < 1e-12 && (f.offset - 0.5).abs() < 1e-12);
    assert_eq!(f.polygon.len(), 4);
    assert!(f.holds(&Vec3::new(0.2, -0.4, 0.5), 1e-9));
    assert!(f.holds(&Vec3::new(0.5 + 1e-10, 0.0, 0.5), 1e-9));
    assert!(!f.holds(&Vec3::new(0.6, 0.0, 0.5), 1e-9));
    assert!(!f.holds(&Vec3::new(0.0, 0.0, 0.51), 1e-3));
    let tilted = flat_faces(
        &cube.parts[0],
        &at(0.0, 0.0, 0.0),
        &Vec3::new(0.0, 0.1, 1.0).normalize(),
        0.999,
    );
    assert!(tilted.is_empty(), "5.7° off is not flat at cos 0.999");
}

/// A plank lying across a narrower support touches it in a rectangle
/// whose four corners are crossings of the plank's long edges with the
/// support's top edges: all four are found, and nothing else (no
/// diagonal of a box face, no vertex of either box is in the patch).
#[test]
fn a_plank_across_a_support_touches_it_at_four_edge_crossings() {
    let plank = Geometry::cuboid(Vec3::new(0.6, 0.1, 0.03)).unwrap();
    let support = Geometry::cuboid(Vec3::new(0.05, 0.2, 0.25)).unwrap();
    let near = near_points(
        &plank,
        &at(0.3, 0.0, 0.53),
        &support,
        &at(0.0, 0.0, 0.25),
        1e-6,
    );
    assert_eq!(near.len(), 4, "{near:?}");
    for w in [[-0.05, -0.1], [-0.05, 0.1], [0.05, -0.1], [0.05, 0.1]] {
        assert!(
            near.iter()
                .any(|p| (p.point.x - w[0]).abs() < 1e-12 && (p.point.y - w[1]).abs() < 1e-12),
            "no corner at {w:?}: {near:?}"
        );
    }
    assert!(
        near.iter()
            .all(|p| matches!(p.corner, Corner::Crossing { .. }))
    );
    assert!(
        near.iter()
            .all(|p| (p.normal - Vec3::z()).norm() < 1e-9 && p.distance.abs() < 1e-9)
    );
    // The support's corner under a plank lying over it is a vertex of b.
    let near = near_points(
        &plank,
        &at(0.6, 0.25, 0.53),
        &support,
        &at(0.0, 0.0, 0.25),
        1e-6,
    );
    assert!(
        near.iter().any(|p| matches!(p.corner, Corner::B { .. })),
        "{near:?}"
    );
}

/// parry's `query::contact` reported −2.5 for a unit ball 1.5 above the
/// ground when the half-space was passed second; nudge passes it first.
#[test]
fn regression_halfspace_second_reports_wrong_distance() {
    let ball = Geometry::sphere(1.0).unwrap();
    let ground = Geometry::half_space(Vec3::z()).unwrap();
    let c = contact(
        &ball,
        &at(0.0, 0.0, 2.5),
        &ground,
        &Isometry3::identity(),
        10.0,
    )
    .unwrap();
    assert!((c.distance - 1.5).abs() < 1e-12, "distance {}", c.distance);
    assert!(
        (c.normal - Vec3::z()).norm() < 1e-12,
        "normal points from ground to ball"
    );
    assert!((c.point_a - Vec3::new(0.0, 0.0, 1.5)).norm() < 1e-12);
    assert!(c.point_b.z.abs() < 1e-12);
    // And the reverse order gives the flipped result.
    let r = contact(
        &ground,
        &Isometry3::identity(),
        &ball,
        &at(0.0, 0.0, 2.5),
        10.0,
    )
    .unwrap();
    assert!((r.distance - 1.5).abs() < 1e-12);
    assert!((r.normal + Vec3::z()).norm() < 1e-12);
}

/// docs/design.md §4: with `a` as parry's shape 1, `n = −normal1` points from b to a.
#[test]
fn normal_points_from_b_towards_a_for_two_balls() {
    let ball = Geometry::sphere(0.5).unwrap();
    let c = contact(&ball, &at(2.0, 0.0, 0.0), &ball, &at(0.0, 0.0, 0.0), 10.0).unwrap();
    assert!((c.distance - 1.0).abs() < 1e-12);
    assert!((c.normal - Vec3::x()).norm() < 1e-12);
    assert!((c.point_a - Vec3::new(1.5, 0.0, 0.0)).norm() < 1e-12);
}

#[test]
fn parabola_foot_is_the_closest_point() {
    let k = 0.7;
    for (x, z) in [(0.3, 1.0), (-1.2, 0.4), (2.0, -5.0), (0.0, 2.0)] {
        let s = point_parabola(k, x, z);
        let d = |t: f64| (x - t).powi(2) + (z + k * t * t).powi(2);
        for t in [s - 1e-4, s + 1e-4] {
            assert!(d(t) >= d(s) - 1e-15, "({x},{z}) foot {s}");
        }
    }
}

/// `contact` asks the part pairs in the order of their distance bounds
/// and stops at the first bounded beyond the closest found: it must
/// return exactly the closest of all part contacts (the first of equals
/// in part order), for compounds in any pose, overlapping or apart,
/// with or without a distance limit. `part_contacts` culls by the same
/// bounds, so the closest of all is found here by asking parry for
/// every part pair.
#[test]
fn contact_is_the_closest_of_all_part_pairs() {
    let cuboid = |x: f64, y: f64, z: f64| Geometry::cuboid(Vec3::new(x, y, z)).unwrap();
    let body = Geometry::compound(vec![
        (at(-0.3, 0.0, 0.0), cuboid(0.2, 0.05, 0.05)),
        (at(0.3, 0.0, 0.1), cuboid(0.05, 0.2, 0.05)),
        (at(0.0, 0.2, -0.1), Geometry::sphere(0.08).unwrap()),
    ])
    .unwrap();
    let rack = Geometry::compound(vec![
        (at(0.0, 0.0, 0.0), cuboid(0.5, 0.5, 0.02)),
        (at(0.0, 0.0, 0.4), cuboid(0.02, 0.02, 0.4)),
        (at(0.2, 0.0, 0.5), cuboid(0.2, 0.02, 0.02)),
        (at(-0.2, 0.1, 0.3), Geometry::sphere(0.05).unwrap()),
    ])
    .unwrap();
    let mut rng = crate::math::Rng(0x2545_f491_4f6c_dd1d);
    let mut next = || rng.range(-1.0, 1.0);
    let (mut apart, mut touching) = (0, 0);
    for i in 0..500 {
        let pose = Isometry3::from_parts(
            Translation3::new(0.8 * next(), 0.8 * next(), 0.5 + 0.6 * next()),
            UnitQuaternion::from_scaled_axis(Vec3::new(3.0 * next(), 3.0 * next(), 3.0 * next())),
        );
        let limit = if i % 2 == 0 { f64::INFINITY } else { 0.2 };
        let origin = at(0.0, 0.0, 0.0);
        let all: Vec<Contact> = (0..body.parts.len())
            .flat_map(|ia| (0..rack.parts.len()).map(move |ib| (ia, ib)))
            .filter_map(|(ia, ib)| {
                let (x, y) = (&body.parts[ia], &rack.parts[ib]);
                let c = unculled_part_contact(x, &pose, y, &origin, limit)?;
                Some(Contact {
                    part_a: ia,
                    part_b: ib,
                    ..c
                })
            })
            .collect();
        let want = all.iter().fold(None::<&Contact>, |m, c| match m {
            Some(m) if m.distance <= c.distance => Some(m),
            _ => Some(c),
        });
        let got = contact(&body, &pose, &rack, &origin, limit);
        assert_eq!(got.as_ref(), want, "pose {i}: {pose:?}");
        let culled = part_contacts(&body, &pose, &rack, &origin, limit);
        assert_eq!(culled, all, "pose {i}: the culled part contacts");
        match got {
            Some(c) if c.distance > 0.0 => apart += 1,
            Some(_) => touching += 1,
            None => {}
        }
    }
    assert!(
        apart > 100 && touching > 20,
        "{apart} apart, {touching} overlapping"
    );
}

/// The bound that culls part pairs (bounding spheres, then the
/// separation of bounding boxes along their faces' normals, or a box's
/// height over a half-space) never exceeds the distance parry finds,
/// for boxes, hulls, balls and a tilted half-space in random poses,
/// apart and overlapping; and it is tight enough to be worth having:
/// for boxes apart, it is often within a tenth of the distance while
/// the spheres' gap is not.
#[test]
fn a_part_pairs_bound_never_exceeds_its_distance() {
    let hull = Geometry::convex_hull(&[
        Vec3::new(0.1, 0.0, -0.01),
        Vec3::new(-0.05, 0.08, -0.01),
        Vec3::new(-0.05, -0.08, -0.01),
        Vec3::new(0.1, 0.0, 0.01),
        Vec3::new(-0.05, 0.08, 0.01),
        Vec3::new(-0.05, -0.08, 0.01),
    ])
    .unwrap();
    let shapes = [
        Geometry::cuboid(Vec3::new(0.3, 0.02, 0.01)).unwrap(),
        Geometry::cuboid(Vec3::new(0.05, 0.05, 0.4)).unwrap(),
        hull,
        Geometry::sphere(0.05).unwrap(),
        Geometry::half_space(Vec3::new(0.2, -0.1, 1.0)).unwrap(),
    ];
    let mut rng = crate::math::Rng(0x9e37_79b9_7f4a_7c15);
    let mut next = || rng.range(-1.0, 1.0);
    let (mut checked, mut tight, mut spheres_tight) = (0, 0, 0);
    for i in 0..4000 {
        let mut pose = || {
            Isometry3::from_parts(
                Translation3::new(0.5 * next(), 0.5 * next(), 0.3 + 0.3 * next()),
                UnitQuaternion::from_scaled_axis(Vec3::new(
                    3.0 * next(),
                    3.0 * next(),
                    3.0 * next(),
                )),
            )
        };
        let (pa, pb) = (pose(), pose());
        let (ga, gb) = (&shapes[i % 4], &shapes[(i / 4) % 5]);
        let (x, y) = (&ga.parts[0], &gb.parts[0]);
        let Some(c) = unculled_part_contact(x, &pa, y, &pb, f64::INFINITY) else {
            continue;
        };
        let (px, py) = (Placed::new(0, x, &pa), Placed::new(0, y, &pb));
        let bound = px.bound(&py);
        assert!(
            bound <= c.distance + 1e-12,
            "pair {i}: bound {bound} over distance {}",
            c.distance
        );
        let swapped = py.bound(&px);
        assert!(
            (bound - swapped).abs() <= 1e-12 || bound == swapped,
            "pair {i}: the bound is symmetric ({bound} vs {swapped})"
        );
        checked += 1;
        if i % 4 < 2 && (i / 4) % 5 < 2 && c.distance > 0.01 {
            tight += usize::from(bound > 0.9 * c.distance);
            spheres_tight += usize::from(px.sphere_gap(&py) > 0.9 * c.distance);
        }
    }
    assert!(checked > 3500, "{checked} pairs checked");
    assert!(
        tight > 3 * spheres_tight.max(10),
        "boxes within 10 %: {tight}, spheres: {spheres_tight}"
    );
}

#[test]
fn far_pairs_return_none() {
    let ball = Geometry::sphere(0.5).unwrap();
    assert!(contact(&ball, &at(5.0, 0.0, 0.0), &ball, &at(0.0, 0.0, 0.0), 1.0).is_none());
}

/// Extreme but finite numbers (and non-finite ones) never panic the
/// parabola's closest-point search: its answer is a foot on the curve,
/// or NaN when no foot exists, which the simulation turns into a typed
/// error. It used to panic in `clamp` on a NaN bracket.
#[test]
fn the_parabola_search_never_panics_on_extreme_numbers() {
    let extremes = [
        0.0,
        1.0,
        -1.0,
        1e308,
        -1e308,
        1e-308,
        -1e-308,
        f64::MIN_POSITIVE / 4.0,
        f64::MAX,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NAN,
    ];
    for &k in &extremes {
        for &x in &extremes {
            for &z in &extremes {
                let s = point_parabola(k, x, z);
                let all_finite = k.is_finite() && x.is_finite() && z.is_finite();
                assert!(all_finite || s.is_nan(), "k={k} x={x} z={z}: {s}");
            }
        }
    }
}
