//! The meshes: a body's or obstacle's shape as triangles in its own frame,
//! turned y-up and rounded to `f32`.
//!
//! Bounded pieces are parry's triangulations (`Geometry::triangles`); a
//! plane is drawn as a square over the motion's extent, a parabola as a
//! strip of its drawn width (`half_width`) and the extent's length.

use super::keys::Extent;
use super::{ExportError, single, to_y_up};
use crate::geometry::{Geometry, PartKind};
use crate::math::Vec3;
use crate::scene::Obstacle;
use nalgebra::Point3;

/// Segments across a parabola's drawn width.
const PARABOLA_SEGMENTS: usize = 32;

/// A triangle mesh, y-up, in its node's frame.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    /// Triangles, counter-clockwise seen from outside.
    pub indices: Vec<u32>,
}

impl Mesh {
    /// Append z-up vertices and triangles (indices into `vertices`).
    fn push(
        &mut self,
        vertices: &[Vec3],
        triangles: &[[u32; 3]],
        owner: &str,
    ) -> Result<(), ExportError> {
        let base = self.positions.len() as u32;
        for v in vertices {
            let y = to_y_up(v);
            let what = || format!("{owner}: a vertex coordinate");
            self.positions
                .push([single(y.x, what)?, single(y.y, what)?, single(y.z, what)?]);
        }
        self.indices
            .extend(triangles.iter().flat_map(|t| t.map(|i| i + base)));
        Ok(())
    }

    /// The smallest and largest coordinate per axis (glTF's accessor bounds).
    pub fn bounds(&self) -> ([f32; 3], [f32; 3]) {
        let mut lo = [f32::MAX; 3];
        let mut hi = [f32::MIN; 3];
        for p in &self.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }
}

/// A body's mesh in its centre-of-mass frame.
///
/// # Errors
/// A vertex beyond `f32`'s range.
pub fn body(name: &str, geometry: &Geometry) -> Result<Mesh, ExportError> {
    let (vertices, triangles) = geometry.triangles();
    let mut mesh = Mesh::default();
    mesh.push(&vertices, &triangles, name)?;
    Ok(mesh)
}

/// Two unit vectors completing `n` to a right-handed frame `(t1, t2, n)`.
fn tangents(n: &Vec3) -> (Vec3, Vec3) {
    let t1 = n
        .cross(&Vec3::x())
        .try_normalize(1e-9)
        .unwrap_or_else(|| n.cross(&Vec3::y()).normalize());
    (t1, n.cross(&t1))
}

/// An obstacle's mesh in its own frame; planes and parabolas over `extent`.
///
/// # Errors
/// A vertex beyond `f32`'s range.
pub fn obstacle(o: &Obstacle, extent: &Extent) -> Result<Mesh, ExportError> {
    let mut mesh = Mesh::default();
    // The motion's centre in the obstacle's frame.
    let centre = o.pose.inverse() * Point3::from(extent.centre);
    let e = extent.half;
    for part in &o.geometry.parts {
        if let Some((vertices, triangles)) = part.triangles() {
            mesh.push(&vertices, &triangles, &o.name)?;
            continue;
        }
        let local = part.offset.inverse() * centre;
        let place = |v: Vec3| (part.offset * Point3::from(v)).coords;
        match &part.kind {
            PartKind::HalfSpace { normal } => {
                let (t1, t2) = tangents(normal);
                // The square on the plane, centred under the motion.
                let c = local.coords - normal * normal.dot(&local.coords);
                let corners = [-t1 - t2, t1 - t2, t1 + t2, -t1 + t2].map(|d| place(c + d * e));
                mesh.push(&corners, &[[0, 1, 2], [0, 2, 3]], &o.name)?;
            }
            PartKind::Parabola {
                curvature,
                half_width,
            } => {
                let n = PARABOLA_SEGMENTS;
                let mut vertices = Vec::with_capacity(2 * (n + 1));
                for k in 0..=n {
                    let x = -half_width + 2.0 * half_width * k as f64 / n as f64;
                    let z = -curvature * x * x;
                    vertices.push(place(Vec3::new(x, local.y - e, z)));
                    vertices.push(place(Vec3::new(x, local.y + e, z)));
                }
                // Facing up, out of the solid below the surface.
                let triangles: Vec<[u32; 3]> = (0..n as u32)
                    .flat_map(|k| {
                        let (a, b, c, d) = (2 * k, 2 * k + 1, 2 * k + 2, 2 * k + 3);
                        [[a, c, d], [a, d, b]]
                    })
                    .collect();
                mesh.push(&vertices, &triangles, &o.name)?;
            }
            PartKind::Ball { .. } | PartKind::Convex { .. } => {}
        }
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Isometry3;

    fn normal(mesh: &Mesh, t: usize) -> Vec3 {
        let p = |i: usize| {
            let v = mesh.positions[mesh.indices[3 * t + i] as usize];
            Vec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
        };
        (p(1) - p(0)).cross(&(p(2) - p(0)))
    }

    fn obstacle_of(geometry: Geometry) -> Obstacle {
        Obstacle {
            name: "floor".into(),
            geometry,
            shape_source: toml::Value::Table(Default::default()),
            pose: Isometry3::identity(),
            restitution: 1.0,
            friction: 0.5,
        }
    }

    #[test]
    fn a_floor_is_a_square_under_the_motion_facing_up() {
        let floor = obstacle_of(Geometry::half_space(Vec3::z()).expect("a plane"));
        let extent = Extent {
            centre: Vec3::new(3.0, 1.0, 2.0),
            half: 5.0,
        };
        let mesh = obstacle(&floor, &extent).expect("finite");
        assert_eq!(mesh.indices.len(), 6);
        // glTF's up is y.
        for t in 0..2 {
            let n = normal(&mesh, t);
            assert!(n.y > 0.0 && n.x.abs() < 1e-6 && n.z.abs() < 1e-6, "{n}");
        }
        let (lo, hi) = mesh.bounds();
        assert_eq!((lo[0], hi[0]), (-2.0, 8.0));
        // nudge's y = 1 is glTF's z = −1.
        assert_eq!((lo[2], hi[2]), (-6.0, 4.0));
        assert_eq!((lo[1], hi[1]), (0.0, 0.0));
    }

    #[test]
    fn a_parabola_is_a_strip_facing_up() {
        let hill = obstacle_of(Geometry::parabola(0.5, 2.0).expect("a parabola"));
        let extent = Extent {
            centre: Vec3::zeros(),
            half: 3.0,
        };
        let mesh = obstacle(&hill, &extent).expect("finite");
        assert_eq!(mesh.indices.len(), 3 * 2 * PARABOLA_SEGMENTS);
        for t in 0..2 * PARABOLA_SEGMENTS {
            assert!(normal(&mesh, t).y > 0.0);
        }
        let (lo, hi) = mesh.bounds();
        assert_eq!((lo[1], hi[1]), (-2.0, 0.0));
    }
}
