//! Triangle meshes of the bounded parts, for export: parry's `to_trimesh`
//! of each convex piece, every triangle turned to face outwards.

use super::shapes::{Geometry, Part};
use crate::math::Vec3;

/// Segments around a ball's equator and from pole to pole.
const BALL_SUBDIVISIONS: (u32, u32) = (32, 16);

/// Vertices and triangles (indices into the vertices, counter-clockwise
/// seen from outside).
pub type Triangles = (Vec<Vec3>, Vec<[u32; 3]>);

impl Part {
    /// The piece's surface as triangles in the owner's frame; `None` for
    /// unbounded pieces (a plane, a parabola), which have no surface to
    /// close.
    pub fn triangles(&self) -> Option<Triangles> {
        let shape = self.shape.as_ref()?;
        let (points, mut triangles) = if let Some(ball) = shape.as_ball() {
            ball.to_trimesh(BALL_SUBDIVISIONS.0, BALL_SUBDIVISIONS.1)
        } else if let Some(cuboid) = shape.as_cuboid() {
            cuboid.to_trimesh()
        } else if let Some(hull) = shape.as_convex_polyhedron() {
            hull.to_trimesh()
        } else {
            return None;
        };
        let vertices: Vec<Vec3> = points.iter().map(|p| (self.offset * p).coords).collect();
        if vertices.is_empty() {
            return None;
        }
        // The piece is convex: its vertices' centroid is inside, so a
        // triangle faces outwards when its normal points away from it.
        let centre = vertices.iter().sum::<Vec3>() / vertices.len() as f64;
        for t in &mut triangles {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            if (b - a).cross(&(c - a)).dot(&(a - centre)) < 0.0 {
                t.swap(1, 2);
            }
        }
        Some((vertices, triangles))
    }
}

impl Geometry {
    /// Every bounded piece's triangles, merged into one mesh in the
    /// geometry's frame (a compound's pieces overlap where they touch; a
    /// viewer draws them as they are).
    pub fn triangles(&self) -> Triangles {
        let (mut vertices, mut triangles) = (Vec::new(), Vec::new());
        for (v, t) in self.parts.iter().filter_map(Part::triangles) {
            let base = vertices.len() as u32;
            vertices.extend(v);
            triangles.extend(t.iter().map(|t| t.map(|i| i + base)));
        }
        (vertices, triangles)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Isometry3, Translation3, UnitQuaternion};

    /// The signed volume of a closed mesh (the divergence theorem):
    /// positive when every triangle faces outwards.
    fn volume((v, t): &Triangles) -> f64 {
        t.iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| v[i as usize]);
                a.dot(&b.cross(&c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn a_box_mesh_is_closed_outward_and_has_its_volume() {
        let g = Geometry::cuboid(Vec3::new(0.5, 0.25, 0.1)).expect("a box");
        assert!((volume(&g.triangles()) - 0.1).abs() < 1e-12);
    }

    #[test]
    fn a_ball_and_a_hull_in_a_compound_are_placed_and_face_outwards() {
        let ball = Geometry::sphere(0.5).expect("a ball");
        let egg = Geometry::ellipsoid(Vec3::new(0.1, 0.1, 0.2), 8, 1.3).expect("an egg");
        let far = Isometry3::from_parts(
            Translation3::new(3.0, 0.0, 0.0),
            UnitQuaternion::from_euler_angles(0.3, 0.2, 0.1),
        );
        let both = Geometry::compound(vec![
            (Isometry3::identity(), ball.clone()),
            (far, egg.clone()),
        ])
        .expect("a compound");
        let mesh = both.triangles();
        let sum = volume(&ball.triangles()) + volume(&egg.triangles());
        assert!((volume(&mesh) - sum).abs() < 1e-12 * sum);
        let egg_mass = egg.mass_properties(1.0).expect("bounded").mass;
        assert!((volume(&egg.triangles()) - egg_mass).abs() < 1e-12);
        // A 32 × 16 ball is within 3 % of the sphere's volume.
        let sphere = 4.0 / 3.0 * std::f64::consts::PI * 0.125;
        assert!((volume(&ball.triangles()) / sphere - 1.0).abs() < 0.03);
        assert!(mesh.0.iter().any(|v| v.x > 2.8), "the egg sits at x = 3");
    }

    #[test]
    fn unbounded_parts_have_no_triangles() {
        let plane = Geometry::half_space(Vec3::z()).expect("a plane");
        assert!(plane.triangles().1.is_empty());
    }
}
