//! A shape from a closed triangle mesh: the mass properties of the solid
//! it encloses, and for collisions its convex hull or its convex
//! decomposition (parry's VHACD). The event search works on convex pieces
//! (docs/design.md §4), so a mesh collides as convex pieces; a concave
//! mesh's hull fills its hollows, its decomposition follows them.

use super::shapes::{Geometry, Part};
use crate::math::Vec3;
use nalgebra::Point3;
use parry3d_f64::mass_properties::MassProperties;
use parry3d_f64::transformation::vhacd::{VHACD, VHACDParameters};
use std::collections::HashMap;

/// Most convex pieces a decomposition may make: each is searched for
/// contacts at every step. (VHACD makes as many as its concavity needs.)
pub const MAX_PIECES: usize = 64;

/// How far a piece may depart from convex, relative to the mesh's size
/// (parry's default): a hollow is followed to within about 2 % of it; 10×
/// tighter triples the pieces of a hat (75) for little a toss can show.
const CONCAVITY: f64 = 0.01;

/// Voxels along the longest side when decomposing (parry's default).
const DECOMPOSITION_RESOLUTION: u32 = 64;

/// What a mesh collides as.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Decomposition {
    /// Its convex hull.
    Hull,
    /// Its approximate convex decomposition (at most [`MAX_PIECES`] hulls).
    Convex,
}

/// Why a mesh makes no solid.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeshError {
    #[error("has no triangles")]
    NoTriangles,
    #[error("has a triangle (#{triangle}) using vertex {index} of {count}")]
    BadIndex {
        triangle: usize,
        index: u32,
        count: usize,
    },
    #[error("has a vertex (#{index}) with a coordinate that is not a finite number")]
    NonFinite { index: usize },
    #[error(
        "is not a closed solid: {open} triangle edges have no matching edge facing the other way"
    )]
    NotClosed { open: usize },
    #[error("is flat: it encloses no volume")]
    Flat,
    #[error("is too large: its volume is beyond the finite numbers")]
    Overflow,
    #[error("decomposes into no convex piece with a volume")]
    NoPieces,
    #[error("decomposes into {count} convex pieces, more than {MAX_PIECES}")]
    TooManyPieces { count: usize },
}

/// Merge vertices at bit-identical positions (files repeat a vertex per
/// face, or per seam) and drop triangles that use one vertex twice.
fn weld(vertices: &[Vec3], triangles: &[[u32; 3]]) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut seen: HashMap<[u64; 3], u32> = HashMap::new();
    let mut out = Vec::new();
    let map: Vec<u32> = vertices
        .iter()
        .map(|v| {
            let key = [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
            *seen.entry(key).or_insert_with(|| {
                out.push(*v);
                (out.len() - 1) as u32
            })
        })
        .collect();
    let tris = triangles
        .iter()
        .map(|t| t.map(|i| map[i as usize]))
        .filter(|t| t[0] != t[1] && t[1] != t[2] && t[0] != t[2])
        .collect();
    (out, tris)
}

/// Directed edges without exactly one partner facing the other way.
fn open_edges(triangles: &[[u32; 3]]) -> usize {
    let mut count: HashMap<(u32, u32), i32> = HashMap::new();
    for t in triangles {
        for k in 0..3 {
            *count.entry((t[k], t[(k + 1) % 3])).or_default() += 1;
        }
    }
    count
        .iter()
        .filter(|&(&(a, b), &n)| n != 1 || count.get(&(b, a)) != Some(&1))
        .count()
}

/// The signed volume enclosed (positive when the triangles face outwards).
fn signed_volume(vertices: &[Vec3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum()
}

impl Geometry {
    /// The solid a closed triangle mesh encloses, colliding as its hull or
    /// its decomposition. Triangles index `vertices`; they may face in or
    /// out, consistently.
    ///
    /// # Errors
    /// A mesh without triangles, with a bad index or a non-finite
    /// coordinate, not closed, flat, or whose decomposition has no volume.
    pub fn from_mesh(
        vertices: &[Vec3],
        triangles: &[[u32; 3]],
        decomposition: Decomposition,
    ) -> Result<Geometry, MeshError> {
        if let Some(index) = vertices
            .iter()
            .position(|v| !v.iter().all(|c| c.is_finite()))
        {
            return Err(MeshError::NonFinite { index });
        }
        for (triangle, t) in triangles.iter().enumerate() {
            if let Some(&index) = t.iter().find(|&&i| i as usize >= vertices.len()) {
                return Err(MeshError::BadIndex {
                    triangle,
                    index,
                    count: vertices.len(),
                });
            }
        }
        let (vertices, mut triangles) = weld(vertices, triangles);
        if triangles.is_empty() {
            return Err(MeshError::NoTriangles);
        }
        let open = open_edges(&triangles);
        if open > 0 {
            return Err(MeshError::NotClosed { open });
        }
        let mut volume = signed_volume(&vertices, &triangles);
        if volume < 0.0 {
            for t in &mut triangles {
                t.swap(1, 2);
            }
            volume = -volume;
        }
        let (lo, hi) = vertices.iter().fold(
            (Vec3::repeat(f64::INFINITY), Vec3::repeat(f64::NEG_INFINITY)),
            |(lo, hi), v| (lo.inf(v), hi.sup(v)),
        );
        let size = (hi - lo).norm();
        if !(volume.is_finite() && size.is_finite()) {
            return Err(MeshError::Overflow);
        }
        if volume <= 1e-9 * size * size * size {
            return Err(MeshError::Flat);
        }
        let points: Vec<Point3<f64>> = vertices.iter().map(|v| Point3::from(*v)).collect();
        let solid = MassProperties::from_trimesh(1.0, &points, &triangles);
        let parts = match decomposition {
            Decomposition::Hull => vec![Part::convex(vertices).map_err(|_| MeshError::Flat)?],
            Decomposition::Convex => {
                let params = VHACDParameters {
                    resolution: DECOMPOSITION_RESOLUTION,
                    concavity: CONCAVITY,
                    ..Default::default()
                };
                let pieces = VHACD::decompose(&params, &points, &triangles, true)
                    .compute_exact_convex_hulls(&points, &triangles);
                // A sliver of a piece (flat, or a few voxels) has no volume
                // to collide with; the solid's mass keeps its share.
                let parts: Vec<Part> = pieces
                    .into_iter()
                    .filter_map(|(p, _)| Part::convex(p.iter().map(|p| p.coords).collect()).ok())
                    .collect();
                if parts.is_empty() {
                    return Err(MeshError::NoPieces);
                }
                if parts.len() > MAX_PIECES {
                    return Err(MeshError::TooManyPieces { count: parts.len() });
                }
                parts
            }
        };
        Ok(Geometry {
            parts,
            solid: Some(solid),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed box mesh of half extents `h` at `c`, with its vertices
    /// repeated per face (as files often write them).
    fn box_mesh(h: Vec3, c: Vec3) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let g = Geometry::cuboid(h).expect("a box");
        let (v, t) = g.triangles();
        let mut vertices = Vec::new();
        let mut triangles = Vec::new();
        for tri in t {
            let base = vertices.len() as u32;
            vertices.extend(tri.iter().map(|&i| v[i as usize] + c));
            triangles.push([base, base + 1, base + 2]);
        }
        (vertices, triangles)
    }

    #[test]
    fn a_box_mesh_has_the_box_mass_properties_either_way_round() {
        let h = Vec3::new(0.3, 0.2, 0.1);
        let (v, t) = box_mesh(h, Vec3::new(1.0, 2.0, 3.0));
        let reference = Geometry::cuboid(h).expect("a box").mass_properties(7.0);
        let reference = reference.expect("bounded");
        let inside_out: Vec<[u32; 3]> = t.iter().map(|t| [t[0], t[2], t[1]]).collect();
        for tris in [t, inside_out] {
            let g = Geometry::from_mesh(&v, &tris, Decomposition::Hull).expect("closed");
            let m = g.mass_properties(7.0).expect("bounded");
            assert!((m.mass - reference.mass).abs() < 1e-12);
            assert!((m.com - Vec3::new(1.0, 2.0, 3.0)).norm() < 1e-12);
            assert!((m.inertia - reference.inertia).norm() < 1e-12);
            // Recentred, as a body is, it keeps the solid's inertia.
            let r = g.recentered(&m.com).mass_properties(7.0).expect("bounded");
            assert!(r.com.norm() < 1e-12 && (r.inertia - reference.inertia).norm() < 1e-12);
        }
    }

    /// Two boxes 0.1 m apart, one lying, one standing on its end (an L
    /// with a gap at the corner): the hull fills the space between them,
    /// the decomposition does not; both weigh what the boxes weigh.
    #[test]
    fn a_concave_mesh_weighs_its_solid_and_decomposes_into_pieces() {
        let (mut v, mut t) = box_mesh(Vec3::new(0.5, 0.1, 0.1), Vec3::new(0.5, 0.0, 0.1));
        let (v2, t2) = box_mesh(Vec3::new(0.1, 0.1, 0.4), Vec3::new(0.1, 0.0, 0.6));
        let shift = Vec3::new(0.0, 0.0, 0.1);
        let base = v.len() as u32;
        v.extend(v2.iter().map(|p| p + shift));
        t.extend(t2.iter().map(|t| t.map(|i| i + base)));
        let volume = 1.0 * 0.2 * 0.2 + 0.2 * 0.2 * 0.8;
        let hull = Geometry::from_mesh(&v, &t, Decomposition::Hull).expect("closed");
        let pieces = Geometry::from_mesh(&v, &t, Decomposition::Convex).expect("closed");
        for g in [&hull, &pieces] {
            let m = g.mass_properties(1.0).expect("bounded").mass;
            assert!((m - volume).abs() < 1e-12, "{m}");
        }
        assert_eq!(hull.parts.len(), 1);
        assert!(pieces.parts.len() >= 2, "{} pieces", pieces.parts.len());
        assert!(pieces.parts.len() <= MAX_PIECES);
    }

    #[test]
    fn open_flat_and_broken_meshes_are_refused() {
        let (v, t) = box_mesh(Vec3::repeat(0.1), Vec3::zeros());
        assert_eq!(
            Geometry::from_mesh(&v, &t[1..], Decomposition::Hull).map(|_| ()),
            Err(MeshError::NotClosed { open: 3 })
        );
        assert_eq!(
            Geometry::from_mesh(&v, &[], Decomposition::Hull).map(|_| ()),
            Err(MeshError::NoTriangles)
        );
        // Two triangles back to back: closed, and no volume.
        assert_eq!(
            Geometry::from_mesh(&v, &[[0, 1, 2], [0, 2, 1]], Decomposition::Hull).map(|_| ()),
            Err(MeshError::Flat)
        );
        let mut nan = v.clone();
        nan[5].y = f64::NAN;
        assert_eq!(
            Geometry::from_mesh(&nan, &t, Decomposition::Hull).map(|_| ()),
            Err(MeshError::NonFinite { index: 5 })
        );
        assert!(matches!(
            Geometry::from_mesh(&v, &[[0, 1, 99]], Decomposition::Hull),
            Err(MeshError::BadIndex { index: 99, .. })
        ));
    }
}
