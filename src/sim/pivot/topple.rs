//! Toppling over an edge of the support polygon.
//!
//! A body lying on three or more support points of one face, with its
//! centre of mass beyond their hull (scissors come down flat on a handle
//! and a blade's tip, hanging over the blade), cannot rest there and does
//! not slide: gravity turns it about the hull's edge that the centre
//! hangs over, lifting the supports on the other side. As impacts only,
//! that is a train of micro-collisions (each a hop of at least `2 v_r / g`)
//! until the body has tipped over; as a pivot it is one hinge on that
//! edge ([`super::Pivot::enter`]), which ends when the body lands, lifts
//! off or slips. The hinge's line is not the body's own edge (the
//! supports are corners within the support band of the face, at different
//! heights), so it is a hinge only, never a skid, whose ends are body
//! corners.

use crate::geometry::NearPoint;
use crate::math::{Vec3, plane_basis};
use crate::sim::rest::{convex_hull, cross2};

/// The supports on the edge of their hull (seen along their common normal)
/// that the centre of mass `com` lies farthest beyond, when it lies beyond
/// it by more than `1e-6 · reach`: the line a body lying on them topples
/// over. `None` for fewer than three supports, more than one normal, a hull
/// of fewer than three corners, or the centre over the hull.
pub(crate) fn edge(supports: &[NearPoint], com: &Vec3, reach: f64) -> Option<Vec<NearPoint>> {
    let n = supports.first()?.normal;
    if supports.len() < 3 || supports.iter().any(|q| q.normal.dot(&n) < 1.0 - 1e-6) {
        return None;
    }
    let tol = 1e-6 * reach;
    let (t1, t2) = plane_basis(&n);
    let flat = |p: &Vec3| [t1.dot(&(p - com)), t2.dot(&(p - com))];
    let hull = convex_hull(supports.iter().map(|q| flat(&q.point)).collect());
    if hull.len() < 3 {
        return None;
    }
    let origin = [0.0, 0.0];
    // How far the centre (the origin) lies beyond each edge of the
    // counter-clockwise hull, along the edge's outward normal.
    let (a, b, len, beyond) = (0..hull.len())
        .filter_map(|i| {
            let (a, b) = (hull[i], hull[(i + 1) % hull.len()]);
            let len = (b[0] - a[0]).hypot(b[1] - a[1]);
            (len > tol).then(|| (a, b, len, -cross2(&a, &b, &origin) / len))
        })
        .max_by(|x, y| x.3.total_cmp(&y.3))?;
    if beyond.is_nan() || beyond <= tol {
        return None;
    }
    // The supports lie within the support band of the face, not on it: the
    // body touches at its lowest and is tilted by up to the band over its
    // size. The hinge is the edge let down onto the plane of the lowest
    // support, level with the face, so that no point of the body starts
    // below the plane the pivot lands on.
    let low = supports
        .iter()
        .map(|q| n.dot(&q.point))
        .fold(f64::INFINITY, f64::min);
    Some(
        supports
            .iter()
            .filter(|q| cross2(&a, &b, &flat(&q.point)).abs() <= tol * len)
            .map(|q| NearPoint {
                point: q.point - n * (n.dot(&q.point) - low),
                ..*q
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Corner;

    /// Supports at `(x, y, z)` on a level face (normal +z).
    fn supports(pts: &[[f64; 3]]) -> Vec<NearPoint> {
        pts.iter()
            .enumerate()
            .map(|(index, p)| {
                let p = Vec3::new(p[0], p[1], p[2]);
                NearPoint {
                    point: p,
                    normal: Vec3::z(),
                    distance: p.z,
                    corner: Corner::A { index, p },
                }
            })
            .collect()
    }

    /// A 10 cm square foot, its +x side 2 µm higher than the rest.
    fn foot() -> Vec<NearPoint> {
        supports(&[
            [-0.05, -0.05, 0.0],
            [0.05, -0.05, 2e-6],
            [0.05, 0.05, 2e-6],
            [-0.05, 0.05, 0.0],
        ])
    }

    #[test]
    fn the_centre_beyond_one_side_picks_that_side_let_down_level() {
        let com = Vec3::new(0.08, 0.01, 0.03);
        let edge = edge(&foot(), &com, 0.2).expect("the centre hangs over +x");
        let mut xs: Vec<[f64; 3]> = edge
            .iter()
            .map(|q| [q.point.x, q.point.y, q.point.z])
            .collect();
        xs.sort_by(|a, b| a[1].total_cmp(&b[1]));
        assert_eq!(xs, vec![[0.05, -0.05, 0.0], [0.05, 0.05, 0.0]]);
    }

    #[test]
    fn beyond_a_corner_the_side_it_overhangs_most_is_the_edge() {
        // 3 cm beyond x = 0.05 and 1 cm beyond y = 0.05.
        let com = Vec3::new(0.08, 0.06, 0.03);
        let edge = edge(&foot(), &com, 0.2).expect("the centre hangs over");
        assert!(edge.iter().all(|q| q.point.x == 0.05), "{edge:?}");
        let com = Vec3::new(0.06, 0.08, 0.03);
        let edge = self::edge(&foot(), &com, 0.2).expect("the centre hangs over");
        assert!(edge.iter().all(|q| q.point.y == 0.05), "{edge:?}");
    }

    #[test]
    fn no_edge_over_the_hull_on_a_line_or_with_two_normals() {
        // Over the foot (within it, and on its edge).
        assert!(edge(&foot(), &Vec3::new(0.01, 0.02, 0.03), 0.2).is_none());
        assert!(edge(&foot(), &Vec3::new(0.05, 0.0, 0.03), 0.2).is_none());
        let far = Vec3::new(0.3, 0.0, 0.03);
        // Two supports, or three on one line: no polygon to topple off.
        assert!(edge(&foot()[..2], &far, 0.2).is_none());
        let line = supports(&[[0.0, 0.0, 0.0], [0.1, 0.0, 0.0], [0.2, 0.0, 0.0]]);
        assert!(edge(&line, &far, 0.2).is_none());
        // A support on another face.
        let mut bent = foot();
        bent[3].normal = Vec3::x();
        assert!(edge(&bent, &far, 0.2).is_none());
    }
}
