//! Toppling over the edge of the support polygon (docs/design.md §4,
//! `sim::pivot::topple`): a body lying on a face with its centre of mass
//! beyond its supports turns over their edge as one hinge, where
//! micro-collisions took a hop at a time.

use nalgebra::{Isometry3, Matrix3, Rotation3, Unit};
use nudge::controls::Controls;
use nudge::geometry::Geometry;
use nudge::math::Vec3;
use nudge::scene::Scene;
use nudge::sim::{SimOptions, Trajectory, simulate};
use nudge::testkit;

fn run(s: &Scene) -> Trajectory {
    simulate(s, &Controls::new(s), &SimOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// A 10 cm square foot, 4 cm thick, under a 40 cm arm reaching out 37 cm
/// beyond it along +x, 3 cm up: the centre of mass is 13 cm beyond the
/// foot's +x edge. Set down flat, 1 µm above a grippy floor (friction 1,
/// restitution 0.2), turning at `spin` rad/s about y.
fn overhanging(spin: f64) -> Scene {
    let mut s = testkit::on_ground(1.0, 1.0);
    let foot = Geometry::cuboid(Vec3::new(0.05, 0.05, 0.02)).unwrap();
    let arm = Geometry::cuboid(Vec3::new(0.2, 0.05, 0.02)).unwrap();
    let g = Geometry::compound(vec![
        (Isometry3::identity(), foot),
        (Isometry3::translation(0.22, 0.0, 0.05), arm),
    ])
    .unwrap();
    let com = g.mass_properties(1000.0).unwrap().com;
    let mut b = testkit::body("ell", g, Vec3::new(0.0, 0.0, com.z + 0.02 + 1e-6));
    b.angular_velocity = Vec3::new(0.0, spin, 0.0);
    b.restitution = 0.2;
    b.friction = 1.0;
    s.bodies.push(b);
    s
}

/// The body's first pivot: its start segment's time, start state and pivot.
fn first_pivot(tr: &Trajectory) -> (f64, nudge::sim::BodyState, &nudge::sim::Pivot) {
    tr.tracks[0]
        .segments
        .iter()
        .find_map(|seg| seg.pivot.as_deref().map(|p| (seg.t0, seg.start, p)))
        .unwrap_or_else(|| panic!("no pivot: {:?}", tr.signature()))
}

/// Set down flat, whether still or turning either way, the body turns
/// over the foot's +x edge from its first contact with the floor (no
/// micro-collision before it) until the arm lands, and never back onto
/// the foot: the patch's plastic impact takes a turn that way.
#[test]
fn a_body_lying_over_its_feet_edge_topples_over_it_in_one_pivot() {
    for spin in [0.2, 0.0, -0.2, -0.5] {
        let s = overhanging(spin);
        let tr = run(&s);
        let (t0, start, pv) = first_pivot(&tr);
        let hops = tr.events.iter().filter(|e| e.t <= t0 && e.micro).count();
        assert_eq!(
            hops, 0,
            "spin {spin}: {hops} micro-collisions before the pivot"
        );
        assert!(
            pv.axis.cross(&Vec3::y()).norm() < 1e-12,
            "axis {:?}",
            pv.axis
        );
        // On the foot's +x edge (body frame, from the centre of mass).
        let edge_x = s.bodies[0].geometry.parts[0].offset.translation.x + 0.05;
        let at = start.q.inverse() * (pv.point - start.x);
        assert!(
            (at.x - edge_x).abs() < 1e-6,
            "spin {spin}: pivot at {at:?} from the centre, edge at x = {edge_x}"
        );
        assert!(
            pv.point.z.abs() < 1e-9,
            "the edge is on the floor: {}",
            pv.point.z
        );
        assert_eq!(pv.end, nudge::sim::PivotEnd::Lands, "spin {spin}");
        assert_eq!(pv.landing.map(|(part, _)| part), Some(1), "the arm lands");
        // +y turns the +x side, where the centre is, down.
        let rate = start.w.dot(&pv.axis);
        assert!(
            rate >= 0.0,
            "spin {spin}: turns back onto the foot at {rate}"
        );
        if spin < 0.0 {
            assert_eq!(rate, 0.0, "spin {spin}: the patch stops the turn back");
        }
    }
}
/// Turning back onto its foot as it is set down, the body is stopped by
/// the patch and topples from rest: the hinge is a pendulum, and the arm
/// lands when the energy integral `t = ∫ dθ / θ̇(θ)`,
/// `½ I_a θ̇² = m g (h(0) − h(θ))`, says (to 1e-10 s).
#[test]
fn toppling_from_rest_lands_at_the_pendulums_time() {
    let s = overhanging(-0.5);
    let tr = run(&s);
    let (_, start, pv) = first_pivot(&tr);
    assert_eq!(start.w.dot(&pv.axis), 0.0, "the pivot starts from rest");
    let d = &tr.dynamics[0];
    let (m, g) = (d.mass, tr.gravity.norm());
    let rot = *start.q.to_rotation_matrix().matrix();
    let ic = rot * d.inertia * rot.transpose();
    let r = start.x - pv.point;
    let a = pv.axis;
    let i_a = a.dot(&((ic + (Matrix3::identity() * r.norm_squared() - r * r.transpose()) * m) * a));
    let height = |v: &Vec3, th: f64| {
        (Rotation3::from_axis_angle(&Unit::new_normalize(a), th) * v).z + pv.point.z
    };
    // The way the centre goes down.
    let sign = if height(&r, 1e-3) < height(&r, 0.0) {
        1.0
    } else {
        -1.0
    };
    let (_, v) = pv.landing.expect("it lands");
    let r_land = start.q * v + start.x - pv.point;
    let (mut lo, mut hi) = (0.0, 1.5);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if height(&r_land, sign * mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let th_land = 0.5 * (lo + hi);
    // θ = u²: the integrand 2u / θ̇(u²) is finite at u = 0 (θ̇ ∝ u there).
    let rate = |th: f64| (2.0 * m * g * (height(&r, 0.0) - height(&r, sign * th)) / i_a).sqrt();
    let n = 200_000;
    let du = th_land.sqrt() / n as f64;
    let t_land: f64 = (0..n)
        .map(|k| {
            let u = (k as f64 + 0.5) * du;
            2.0 * u / rate(u * u) * du
        })
        .sum();
    assert!(
        (pv.duration - t_land).abs() < 1e-10,
        "lands after {} s, the pendulum after {t_land} s",
        pv.duration
    );
}
