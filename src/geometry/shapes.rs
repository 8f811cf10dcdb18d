//! Shapes as convex parts: building them from scene shapes, their mass
//! properties, outlines and surfaces.

use super::contact::polytope::Axes;
use crate::math::{Mat3, Vec3};
use nalgebra::{Isometry3, Point3, Translation3, Unit, UnitQuaternion};
use parry3d_f64::shape::SharedShape;
use std::f64::consts::PI;

/// Why a shape could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum GeometryError {
    /// A dimension (radius, half extent, curvature, ...) was not finite and positive.
    #[error("{what} must be a finite number > 0, got {value}")]
    NonPositive { what: &'static str, value: f64 },
    /// The convex hull of the given points is degenerate (fewer than 4 points
    /// not all on one plane).
    #[error(
        "the convex hull of {count} points is flat or degenerate: give at least 4 points that are not all on one plane"
    )]
    DegenerateHull { count: usize },
    /// An ellipsoid resolution outside the supported range.
    #[error("resolution must be between 3 and 64, got {0}")]
    Resolution(u32),
    /// A compound with no parts.
    #[error("a compound needs at least one part")]
    EmptyCompound,
    /// A shape that has no volume (a half-space or parabola) was given to a body.
    #[error("a {0} has no finite volume and can only be a static obstacle")]
    Unbounded(&'static str),
}

/// One convex piece of a [`Geometry`].
#[derive(Clone)]
pub struct Part {
    /// The piece's analytic description (fixed once built: the bounding
    /// radius is derived from it).
    pub kind: PartKind,
    /// Pose of the piece in the owner's frame.
    pub offset: Isometry3<f64>,
    pub(crate) shape: Option<SharedShape>,
    /// Radius of the piece's bounding sphere about its origin (see
    /// [`Part::local_radius`]), kept because the contact queries' culling
    /// asks for it for every part pair at every step.
    radius: f64,
    /// The piece's bounding box in its own frame (see [`Part::local_box`]),
    /// kept for the same reason.
    bounds: Option<(Vec3, Vec3)>,
    /// What the separating-axis contact query asks of a convex piece,
    /// kept for the same reason.
    pub(super) axes: Axes,
}

impl std::fmt::Debug for Part {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Part")
            .field("kind", &self.kind)
            .field("offset", &self.offset)
            .finish()
    }
}

/// The analytic description of a convex piece, in the piece's own frame.
#[derive(Debug, Clone, PartialEq)]
pub enum PartKind {
    /// A sphere centred at the piece origin.
    Ball { radius: f64 },
    /// A convex polyhedron: its vertices, hull edges (vertex index pairs)
    /// and its (merged, polygonal) faces: outward unit normal and vertex
    /// indices in order around the face.
    Convex {
        vertices: Vec<Vec3>,
        edges: Vec<[usize; 2]>,
        faces: Vec<(Vec3, Vec<usize>)>,
    },
    /// The half-space `n · p ≤ 0` (solid below the plane through the origin).
    HalfSpace { normal: Vec3 },
    /// The solid below the parabolic cylinder `z = −κ x²` (any `y`), drawn for `|x| ≤ half_width`.
    Parabola { curvature: f64, half_width: f64 },
}

/// Mass, centre of mass and inertia tensor about the centre of mass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProps {
    /// kg.
    pub mass: f64,
    /// Centre of mass in the geometry's frame, m.
    pub com: Vec3,
    /// Inertia tensor about `com`, axes of the geometry's frame, kg·m².
    pub inertia: Mat3,
}

/// A compound of convex parts in its owner's frame.
#[derive(Debug, Clone)]
pub struct Geometry {
    pub parts: Vec<Part>,
    /// Unit-density mass properties of a solid the parts only stand in
    /// for in collisions (a mesh, collided as its hull or decomposition;
    /// see `solid.rs`), in this frame. `None`: the parts are the solid.
    pub(super) solid: Option<parry3d_f64::mass_properties::MassProperties>,
}

fn positive(what: &'static str, value: f64) -> Result<f64, GeometryError> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(GeometryError::NonPositive { what, value })
    }
}

/// Whether the points span a volume (are not all on one plane or line).
fn spans_volume(points: &[Vec3]) -> bool {
    if points.len() < 4 {
        return false;
    }
    let centroid = points.iter().sum::<Vec3>() / points.len() as f64;
    let mut cov = Mat3::zeros();
    for p in points {
        let d = p - centroid;
        cov += d * d.transpose();
    }
    let eig = cov.symmetric_eigenvalues();
    let (min, max) = (eig.min(), eig.max());
    max > 0.0 && min > 1e-14 * max
}

fn to_point(v: &Vec3) -> Point3<f64> {
    Point3::from(*v)
}

impl Part {
    pub(super) fn convex(vertices: Vec<Vec3>) -> Result<Part, GeometryError> {
        let count = vertices.len();
        if !spans_volume(&vertices) {
            return Err(GeometryError::DegenerateHull { count });
        }
        let points: Vec<Point3<f64>> = vertices.iter().map(to_point).collect();
        let hull = parry3d_f64::shape::ConvexPolyhedron::from_convex_hull(&points)
            .ok_or(GeometryError::DegenerateHull { count })?;
        let verts: Vec<Vec3> = hull.points().iter().map(|p| p.coords).collect();
        if verts.len() < 4 {
            return Err(GeometryError::DegenerateHull { count });
        }
        // parry keeps the diagonals of the triangles it merged into flat
        // polygonal faces (both their sides then lie on one face): they are
        // not edges of the solid.
        let edges = hull
            .edges()
            .iter()
            .filter(|e| e.faces[0] != e.faces[1])
            .map(|e| [e.vertices[0] as usize, e.vertices[1] as usize])
            .collect();
        let around = hull.vertices_adj_to_face();
        let faces = hull
            .faces()
            .iter()
            .map(|f| {
                let first = f.first_vertex_or_edge as usize;
                let ids = around[first..first + f.num_vertices_or_edges as usize]
                    .iter()
                    .map(|&i| i as usize)
                    .collect();
                (f.normal.into_inner(), ids)
            })
            .collect();
        Ok(Part::new(
            PartKind::Convex {
                vertices: verts,
                edges,
                faces,
            },
            Some(SharedShape::new(hull)),
        ))
    }

    /// The piece's vertices in the owner's frame (empty for balls and unbounded pieces).
    pub fn vertices(&self) -> Vec<Vec3> {
        match &self.kind {
            PartKind::Convex { vertices, .. } => vertices
                .iter()
                .map(|v| self.offset * to_point(v))
                .map(|p| p.coords)
                .collect(),
            _ => Vec::new(),
        }
    }

    /// Radius of a sphere about the piece's own origin that contains it
    /// (infinite for unbounded pieces).
    pub fn local_radius(&self) -> f64 {
        self.radius
    }

    /// The box bounding the piece, aligned with the piece's own axes: its
    /// centre and half extents in the piece's frame (`None` for unbounded
    /// pieces). A long thin piece's bounding sphere is mostly empty; its box
    /// is not, so the box culls far more of a compound's part pairs.
    pub fn local_box(&self) -> Option<(Vec3, Vec3)> {
        self.bounds
    }

    /// A piece of the given kind and shape at the owner's origin.
    pub(crate) fn new(kind: PartKind, shape: Option<SharedShape>) -> Part {
        let radius = Part::bounding_radius(&kind);
        let bounds = Part::bounding_box(&kind);
        let axes = Axes::of(&kind, bounds);
        Part {
            kind,
            offset: Isometry3::identity(),
            shape,
            radius,
            bounds,
            axes,
        }
    }

    fn bounding_box(kind: &PartKind) -> Option<(Vec3, Vec3)> {
        match kind {
            PartKind::Ball { radius } => Some((Vec3::zeros(), Vec3::repeat(*radius))),
            PartKind::Convex { vertices, .. } => {
                let first = vertices.first()?;
                let (lo, hi) = vertices
                    .iter()
                    .fold((*first, *first), |(lo, hi), v| (lo.inf(v), hi.sup(v)));
                Some(((lo + hi) / 2.0, (hi - lo) / 2.0))
            }
            PartKind::HalfSpace { .. } | PartKind::Parabola { .. } => None,
        }
    }

    fn bounding_radius(kind: &PartKind) -> f64 {
        match kind {
            PartKind::Ball { radius } => *radius,
            PartKind::Convex { vertices, .. } => {
                vertices.iter().map(|v| v.norm()).fold(0.0, f64::max)
            }
            PartKind::HalfSpace { .. } | PartKind::Parabola { .. } => f64::INFINITY,
        }
    }

    /// Distance from the owner's origin to the farthest point of the piece
    /// (infinite for unbounded pieces).
    pub fn reach(&self) -> f64 {
        match &self.kind {
            PartKind::Ball { radius } => self.offset.translation.vector.norm() + radius,
            PartKind::Convex { .. } => self.vertices().iter().map(|v| v.norm()).fold(0.0, f64::max),
            PartKind::HalfSpace { .. } | PartKind::Parabola { .. } => f64::INFINITY,
        }
    }
}

impl Geometry {
    fn single(part: Part) -> Geometry {
        Geometry {
            parts: vec![part],
            solid: None,
        }
    }

    /// Unit-density mass properties in this frame: the solid's, or the
    /// parts' together.
    pub(super) fn unit_mass(&self) -> parry3d_f64::mass_properties::MassProperties {
        if let Some(solid) = self.solid {
            return solid;
        }
        let mut total = parry3d_f64::mass_properties::MassProperties::default();
        for p in &self.parts {
            if let Some(shape) = &p.shape {
                total += shape.mass_properties(1.0).transform_by(&p.offset);
            }
        }
        total
    }

    /// A sphere of the given radius, m.
    pub fn sphere(radius: f64) -> Result<Geometry, GeometryError> {
        let radius = positive("radius", radius)?;
        Ok(Geometry::single(Part::new(
            PartKind::Ball { radius },
            Some(SharedShape::ball(radius)),
        )))
    }

    /// A box with the given half extents, m.
    pub fn cuboid(half: Vec3) -> Result<Geometry, GeometryError> {
        for h in half.iter() {
            positive("half extent", *h)?;
        }
        let mut vertices = Vec::with_capacity(8);
        for i in 0..8 {
            let s = |bit: usize| if i & bit == 0 { -1.0 } else { 1.0 };
            vertices.push(Vec3::new(s(1) * half.x, s(2) * half.y, s(4) * half.z));
        }
        let mut part = Part::convex(vertices)?;
        // parry's cuboid is exact and faster than the generic polyhedron.
        part.shape = Some(SharedShape::cuboid(half.x, half.y, half.z));
        // Keep the hull's vertex list (same 8 points) for features and drawing.
        Ok(Geometry::single(part))
    }

    /// The convex hull of the given points, m.
    pub fn convex_hull(points: &[Vec3]) -> Result<Geometry, GeometryError> {
        if points.iter().any(|p| !p.iter().all(|c| c.is_finite())) {
            return Err(GeometryError::NonPositive {
                what: "point coordinate",
                value: f64::NAN,
            });
        }
        Ok(Geometry::single(Part::convex(points.to_vec())?))
    }

    /// A polyhedral ellipsoid: the hull of a latitude/longitude grid with
    /// `resolution` rings. With `bottom_scale != 1`, the lower half's vertical
    /// radius is scaled, which makes an egg (pointed when `< 1`... blunt when `> 1`).
    pub fn ellipsoid(
        radii: Vec3,
        resolution: u32,
        bottom_scale: f64,
    ) -> Result<Geometry, GeometryError> {
        for r in radii.iter() {
            positive("radius", *r)?;
        }
        positive("bottom scale", bottom_scale)?;
        if !(3..=64).contains(&resolution) {
            return Err(GeometryError::Resolution(resolution));
        }
        let rings = resolution as usize;
        let segments = 2 * rings;
        let mut points = vec![
            Vec3::new(0.0, 0.0, radii.z),
            Vec3::new(0.0, 0.0, -radii.z * bottom_scale),
        ];
        for i in 1..rings {
            let polar = PI * i as f64 / rings as f64;
            let (sp, cp) = polar.sin_cos();
            let zscale = if cp < 0.0 { bottom_scale } else { 1.0 };
            for j in 0..segments {
                // Offset alternate rings so the mesh has no long flat strips.
                let az = 2.0 * PI * (j as f64 + 0.5 * (i % 2) as f64) / segments as f64;
                let (sa, ca) = az.sin_cos();
                points.push(Vec3::new(
                    radii.x * sp * ca,
                    radii.y * sp * sa,
                    radii.z * cp * zscale,
                ));
            }
        }
        Geometry::convex_hull(&points)
    }

    /// A compound of already-built geometries, each placed by `offset`.
    pub fn compound(parts: Vec<(Isometry3<f64>, Geometry)>) -> Result<Geometry, GeometryError> {
        if parts.is_empty() {
            return Err(GeometryError::EmptyCompound);
        }
        // A part that stands for a solid keeps its solid's mass in the whole.
        let solid = parts.iter().any(|(_, g)| g.solid.is_some()).then(|| {
            parts
                .iter()
                .map(|(offset, g)| g.unit_mass().transform_by(offset))
                .fold(Default::default(), |a, b| a + b)
        });
        let mut out = Vec::new();
        for (offset, g) in parts {
            for mut p in g.parts {
                p.offset = offset * p.offset;
                out.push(p);
            }
        }
        Ok(Geometry { parts: out, solid })
    }

    /// The half-space below the plane through the origin with outward `normal`.
    pub fn half_space(normal: Vec3) -> Result<Geometry, GeometryError> {
        let len = normal.norm();
        if !(len.is_finite() && len > 1e-12) {
            return Err(GeometryError::NonPositive {
                what: "plane normal length",
                value: len,
            });
        }
        let n = normal / len;
        Ok(Geometry::single(Part::new(
            PartKind::HalfSpace { normal: n },
            Some(SharedShape::halfspace(Unit::new_normalize(n))),
        )))
    }

    /// The solid below `z = −κ x²`, drawn over `|x| ≤ half_width`.
    pub fn parabola(curvature: f64, half_width: f64) -> Result<Geometry, GeometryError> {
        Ok(Geometry::single(Part::new(
            PartKind::Parabola {
                curvature: positive("curvature", curvature)?,
                half_width: positive("half width", half_width)?,
            },
            None,
        )))
    }

    /// Whether every part is bounded (a body must be).
    pub fn bounded(&self) -> Result<(), GeometryError> {
        for p in &self.parts {
            match p.kind {
                PartKind::HalfSpace { .. } => return Err(GeometryError::Unbounded("plane")),
                PartKind::Parabola { .. } => return Err(GeometryError::Unbounded("parabola")),
                _ => {}
            }
        }
        Ok(())
    }

    /// Mass properties at uniform `density` (kg/m³). Requires a bounded geometry.
    pub fn mass_properties(&self, density: f64) -> Result<MassProps, GeometryError> {
        self.bounded()?;
        let total = match self.solid {
            Some(unit) => parry3d_f64::mass_properties::MassProperties::with_inertia_matrix(
                unit.local_com,
                unit.mass() * density,
                unit.reconstruct_inertia_matrix() * density,
            ),
            None => {
                let mut total = parry3d_f64::mass_properties::MassProperties::default();
                for p in &self.parts {
                    if let Some(shape) = &p.shape {
                        total += shape.mass_properties(density).transform_by(&p.offset);
                    }
                }
                total
            }
        };
        Ok(MassProps {
            mass: total.mass(),
            com: total.local_com.coords,
            inertia: total.reconstruct_inertia_matrix(),
        })
    }

    /// The same geometry with its frame origin moved to `origin` (given in
    /// the current frame): every part is translated by `−origin`.
    pub fn recentered(&self, origin: &Vec3) -> Geometry {
        let shift = Translation3::from(-origin);
        let solid = self
            .solid
            .map(|s| s.transform_by(&Isometry3::from_parts(shift, UnitQuaternion::identity())));
        let parts = self
            .parts
            .iter()
            .map(|p| Part {
                offset: Isometry3::from_parts(shift, UnitQuaternion::identity()) * p.offset,
                ..p.clone()
            })
            .collect();
        Geometry { parts, solid }
    }

    /// Distance from the frame origin to the farthest point (infinite if unbounded).
    pub fn reach(&self) -> f64 {
        self.parts.iter().map(Part::reach).fold(0.0, f64::max)
    }

    /// Line segments outlining the geometry in its own frame, for drawing.
    /// Balls are drawn as three great circles; unbounded parts over `extent`.
    pub fn outline(&self, extent: f64) -> Vec<(Vec3, Vec3)> {
        let mut out = Vec::new();
        for p in &self.parts {
            let tf = |v: Vec3| (p.offset * to_point(&v)).coords;
            match &p.kind {
                PartKind::Ball { radius } => {
                    let n = 24;
                    for axis in 0..3 {
                        for k in 0..n {
                            let a0 = 2.0 * PI * k as f64 / n as f64;
                            let a1 = 2.0 * PI * (k + 1) as f64 / n as f64;
                            let pt = |a: f64| {
                                let (s, c) = a.sin_cos();
                                let mut v = Vec3::zeros();
                                v[(axis + 1) % 3] = radius * c;
                                v[(axis + 2) % 3] = radius * s;
                                v
                            };
                            out.push((tf(pt(a0)), tf(pt(a1))));
                        }
                    }
                }
                PartKind::Convex {
                    vertices, edges, ..
                } => {
                    for e in edges {
                        out.push((tf(vertices[e[0]]), tf(vertices[e[1]])));
                    }
                }
                PartKind::HalfSpace { normal } => {
                    let t1 = normal
                        .cross(&Vec3::x())
                        .try_normalize(1e-9)
                        .unwrap_or_else(|| normal.cross(&Vec3::y()).normalize());
                    let t2 = normal.cross(&t1);
                    let c = [t1 + t2, t1 - t2, -t1 - t2, -t1 + t2].map(|v| tf(v * extent));
                    for k in 0..4 {
                        out.push((c[k], c[(k + 1) % 4]));
                    }
                }
                PartKind::Parabola {
                    curvature,
                    half_width,
                } => {
                    let n = 32;
                    for k in 0..n {
                        let x0 = -half_width + 2.0 * half_width * k as f64 / n as f64;
                        let x1 = -half_width + 2.0 * half_width * (k + 1) as f64 / n as f64;
                        out.push((
                            tf(Vec3::new(x0, 0.0, -curvature * x0 * x0)),
                            tf(Vec3::new(x1, 0.0, -curvature * x1 * x1)),
                        ));
                    }
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_mass_properties_match_the_closed_form() {
        let g = Geometry::cuboid(Vec3::new(1.0, 0.5, 0.25)).unwrap();
        let m = g.mass_properties(2.0).unwrap();
        let mass = 2.0 * 2.0 * 1.0 * 0.5;
        assert!((m.mass - mass).abs() < 1e-12);
        let ixx = mass / 12.0 * (1.0 + 0.25);
        assert!((m.inertia[(0, 0)] - ixx).abs() < 1e-12);
        assert!(m.com.norm() < 1e-12);
    }

    #[test]
    fn ellipsoid_mesh_volume_approaches_the_smooth_one() {
        let g = Geometry::ellipsoid(Vec3::new(0.3, 0.3, 0.4), 16, 1.0).unwrap();
        let m = g.mass_properties(1.0).unwrap();
        let smooth = 4.0 / 3.0 * PI * 0.3 * 0.3 * 0.4;
        assert!((m.mass / smooth - 1.0).abs() < 0.03, "{}", m.mass / smooth);
    }

    #[test]
    fn flat_hull_is_rejected() {
        let pts = [
            Vec3::zeros(),
            Vec3::x(),
            Vec3::y(),
            Vec3::new(1.0, 1.0, 0.0),
        ];
        assert!(matches!(
            Geometry::convex_hull(&pts),
            Err(GeometryError::DegenerateHull { .. })
        ));
    }
}
