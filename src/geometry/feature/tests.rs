use super::super::contact::contact;
use super::*;
use nalgebra::{Translation3, UnitQuaternion};

fn pose(x: Vec3, r: Vec3) -> Isometry3<f64> {
    Isometry3::from_parts(Translation3::from(x), UnitQuaternion::from_scaled_axis(r))
}

/// The feature model reproduces parry's distance and normal at the
/// configuration where it was classified.
#[test]
fn feature_model_agrees_with_parry() {
    let cube = Geometry::cuboid(Vec3::new(0.5, 0.3, 0.2)).unwrap();
    let ground = Geometry::half_space(Vec3::new(0.1, 0.0, 1.0)).unwrap();
    let ball = Geometry::sphere(0.25).unwrap();
    let hill = Geometry::parabola(0.8, 2.0).unwrap();
    let cases: Vec<(&Geometry, Isometry3<f64>, &Geometry, Isometry3<f64>)> = vec![
        (
            &cube,
            pose(Vec3::new(0.0, 0.0, 1.0), Vec3::new(0.3, 0.2, 0.1)),
            &ground,
            Isometry3::identity(),
        ),
        (
            &cube,
            pose(Vec3::new(0.2, 0.1, 1.3), Vec3::new(0.7, -0.4, 0.3)),
            &cube,
            pose(Vec3::zeros(), Vec3::new(-0.2, 0.5, 0.9)),
        ),
        (
            &ball,
            pose(Vec3::new(0.3, 0.0, 1.0), Vec3::zeros()),
            &cube,
            pose(Vec3::zeros(), Vec3::new(0.1, 0.2, 0.3)),
        ),
        (
            &ball,
            pose(Vec3::new(0.4, 0.0, 1.0), Vec3::zeros()),
            &hill,
            Isometry3::identity(),
        ),
        (
            &ball,
            pose(Vec3::new(0.4, 0.1, 1.0), Vec3::zeros()),
            &ball,
            pose(Vec3::new(0.0, 0.0, 0.2), Vec3::zeros()),
        ),
    ];
    for (ga, pa, gb, pb) in cases {
        let c = contact(ga, &pa, gb, &pb, 100.0).unwrap();
        let f = FeaturePair::classify(ga, &pa, gb, &pb, &c);
        let e = f.evaluate(&PoseT::from_isometry(&pa), &PoseT::from_isometry(&pb));
        assert!(
            (e.distance - c.distance).abs() < 1e-9,
            "{}: {} vs {}",
            f.key(),
            e.distance,
            c.distance
        );
        assert!(
            (e.normal - c.normal).norm() < 1e-6,
            "{}: {:?} vs {:?}",
            f.key(),
            e.normal,
            c.normal
        );
    }
}
