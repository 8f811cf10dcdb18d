//! The contact of two small convex polytopes by separating axes, exact
//! where one pair of features certifies it, without GJK or EPA.
//!
//! For convex polytopes `A` and `B` the separation along a unit axis `n`
//! (pointing from `B` towards `A`) is `sep(n) = min_a n·a − max_b n·b`,
//! a lower bound on their signed distance. Every face of the Minkowski
//! difference `A − B` has the normal of a face of `A`, of a face of `B`
//! or the cross product of an edge of each, so over those candidate axes
//! `s = max sep(n)`:
//!
//! - equals the signed distance when the two overlap or touch (`s ≤ 0`:
//!   the penetration depth is the least support of the difference over
//!   its face normals);
//! - bounds it from below when they are apart, and equals it when two
//!   features realise it: a vertex over a face whose foot lies on the
//!   face, or two edges whose closest points lie inside both. Then
//!   `d ≤ |p_a − p_b| = s ≤ d`. Apart, with a vertex over a face at the
//!   faces' separation, the edges' axes need not be asked at all.
//!
//! A contact is returned when one such pair of features is the only
//! support on each side, or the pair is known to be farther apart than
//! asked (`s > max_distance`); otherwise the caller asks parry. That
//! includes every flush contact (a face or an edge lying on a face, two
//! vertices within `1e-7` of the parts' size of the same height): its
//! witness may be anywhere on the overlap, and the patch, rest and
//! sinking rules were built on parry's. Near contact, where the event
//! search's queries cluster, GJK iterates to a tetrahedron and EPA
//! follows; the axes cost a few hundred dot products, and the normal of a
//! vertex on a face is the face's own.

use super::Contact;
use crate::geometry::shapes::{Part, PartKind};
use crate::math::Vec3;
use nalgebra::Isometry3;
use smallvec::SmallVec;

/// Parts with more vertices than this, or more pairs of edge directions,
/// are left to GJK (a mesh's hull: the axes grow as their product).
const MAX_VERTICES: usize = 16;
const MAX_EDGE_PAIRS: usize = 64;

/// What the separating axes decide about a part pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Decided {
    /// Farther apart than the distance asked about.
    Beyond,
    /// Their exact contact.
    Contact(Contact),
}

/// What the axes need of a convex part, found once when it is built: the
/// directions of its edges, one unit vector per class of parallel edges
/// (a box has three; they are crossed pairwise), and whether it is a box
/// aligned with its own axes (its extent along an axis is then closed
/// form).
#[derive(Debug, Clone, Default)]
pub(in crate::geometry) struct Axes {
    directions: Vec<Vec3>,
    boxed: bool,
}

impl Axes {
    /// Of a part of kind `kind` with bounding box `bounds` (centre and
    /// half extents, its own frame).
    pub(in crate::geometry) fn of(kind: &PartKind, bounds: Option<(Vec3, Vec3)>) -> Axes {
        let PartKind::Convex {
            vertices, edges, ..
        } = kind
        else {
            return Axes::default();
        };
        let mut directions: Vec<Vec3> = Vec::new();
        for [i, j] in edges {
            let d = (vertices[*j] - vertices[*i]).normalize();
            if directions.iter().all(|e| e.cross(&d).norm() >= 1e-9) {
                directions.push(d);
            }
        }
        let boxed = bounds.is_some_and(|(c, h)| {
            let tol = 1e-12 * h.norm();
            vertices.len() == 8
                && vertices.iter().all(|v| {
                    let d = v - c;
                    (0..3).all(|k| (d[k].abs() - h[k]).abs() <= tol)
                })
        });
        Axes { directions, boxed }
    }
}

/// A candidate axis: its separation and what realises it.
#[derive(Debug, Clone, Copy)]
enum Axis {
    /// Face `f` of `B` (its outward normal is the axis).
    FaceB(usize),
    /// Face `f` of `A` (the axis is its inward normal).
    FaceA(usize),
    /// Edge directions `i` of `A` and `j` of `B`, the axis `n` from `B`
    /// towards `A`.
    Edges(usize, usize, Vec3),
}

/// The contact of convex parts `pa` (at `wa`, world) and `pb` (at `wb`),
/// its normal from `b` towards `a`; `None` when the axes do not decide it.
pub(super) fn contact(
    pa: &Part,
    wa: &Isometry3<f64>,
    pb: &Part,
    wb: &Isometry3<f64>,
    max_distance: f64,
) -> Option<Decided> {
    let (
        PartKind::Convex {
            vertices: va,
            edges: ea,
            faces: fa,
        },
        PartKind::Convex {
            vertices: vb,
            edges: eb,
            faces: fb,
        },
    ) = (&pa.kind, &pb.kind)
    else {
        return None;
    };
    let (da, db) = (&pa.axes.directions, &pb.axes.directions);
    if va.len() > MAX_VERTICES || vb.len() > MAX_VERTICES || da.len() * db.len() > MAX_EDGE_PAIRS {
        return None;
    }
    // Everything in b's frame.
    let rel = wb.inv_mul(wa);
    let rot = rel.rotation.to_rotation_matrix();
    let shift = rel.translation.vector;
    // Filled in place: collected into a vector, the 16 points were copied
    // once more on every query.
    let mut placed = [Vec3::zeros(); MAX_VERTICES];
    for (p, v) in placed.iter_mut().zip(va) {
        *p = rot * v + shift;
    }
    let a = &placed[..va.len()];
    let shape_a = Extents::of(pa, a, &rot, &shift);
    let shape_b = Extents::of(pb, vb, &nalgebra::Rotation3::identity(), &Vec3::zeros());
    let scale = pa.local_radius() + pb.local_radius() + shift.norm();
    let eps = 1e-12 * scale;
    // Heights closer than this make a support ambiguous (see `over_face`).
    let tie = 1e-7 * scale;
    let mut axes: SmallVec<[(f64, Axis); 32]> = SmallVec::new();
    for (f, (n, ids)) in fb.iter().enumerate() {
        axes.push((shape_a.extent(n).0 - n.dot(&vb[ids[0]]), Axis::FaceB(f)));
    }
    for (f, (m, ids)) in fa.iter().enumerate() {
        let m = rot * m;
        axes.push((shape_b.extent(&m).0 - m.dot(&a[ids[0]]), Axis::FaceA(f)));
    }
    let faces = best(&axes);
    if faces > max_distance {
        return Some(Decided::Beyond);
    }
    let witness = |axes: &[(f64, Axis)], s: f64| {
        // Every axis within round-off of the best may carry the witnesses.
        axes.iter()
            .filter(|x| x.0 >= s - eps)
            .find_map(|&(sep, axis)| match axis {
                Axis::FaceB(f) => {
                    let (n, ids) = &fb[f];
                    over_face(a, vb, n, ids, sep, eps, tie).map(|(p_a, p_b)| (p_a, p_b, *n))
                }
                Axis::FaceA(f) => {
                    let (m, ids) = &fa[f];
                    let m = rot * m;
                    over_face(vb, a, &m, ids, sep, eps, tie).map(|(p_b, p_a)| (p_a, p_b, -m))
                }
                Axis::Edges(i, j, n) => {
                    let d = rot * da[i];
                    crossing([a, vb], [ea, eb], [&d, &db[j]], &n, tie)
                        .map(|(p_a, p_b)| (p_a, p_b, n))
                }
            })
    };
    // Apart, with a vertex over a face at the faces' separation: that is
    // the distance (every axis's separation is at most it), and the edges'
    // axes need not be asked.
    let found = match (faces > 0.0).then(|| witness(&axes, faces)).flatten() {
        Some(w) => Some((faces, w)),
        None => {
            for (i, d) in da.iter().enumerate() {
                let d = rot * d;
                for (j, e) in db.iter().enumerate() {
                    let c = d.cross(e);
                    let len = c.norm();
                    // Parallel edges: their faces' axes cover them.
                    if len < 1e-9 {
                        continue;
                    }
                    let n = c / len;
                    let (lo_a, hi_a) = shape_a.extent(&n);
                    let (lo_b, hi_b) = shape_b.extent(&n);
                    let (up, down) = (lo_a - hi_b, lo_b - hi_a);
                    axes.push(if up >= down {
                        (up, Axis::Edges(i, j, n))
                    } else {
                        (down, Axis::Edges(i, j, -n))
                    });
                }
            }
            let s = best(&axes);
            if s > max_distance {
                return Some(Decided::Beyond);
            }
            witness(&axes, s).map(|w| (s, w))
        }
    };
    let (s, found) = found?;
    if !s.is_finite() {
        return None;
    }
    let (p_a, p_b, n) = found;
    Some(Decided::Contact(Contact {
        distance: s,
        normal: wb.rotation * n,
        point_a: (wb * nalgebra::Point3::from(p_a)).coords,
        point_b: (wb * nalgebra::Point3::from(p_b)).coords,
        part_a: 0,
        part_b: 0,
    }))
}

/// The extent of a polytope along an axis: of its box in closed form
/// (the centre's height plus or minus the half extents' reach), else
/// over its vertices.
enum Extents<'p> {
    /// A box: its frame (rotation into `b`'s frame, its centre there) and
    /// half extents.
    Box {
        rot: nalgebra::Rotation3<f64>,
        centre: Vec3,
        half: Vec3,
    },
    Points(&'p [Vec3]),
}

impl<'p> Extents<'p> {
    /// Part `p` with vertices `pts` in `b`'s frame, its own frame turned
    /// by `rot` and shifted by `shift` into it.
    fn of(p: &Part, pts: &'p [Vec3], rot: &nalgebra::Rotation3<f64>, shift: &Vec3) -> Extents<'p> {
        match p.local_box().filter(|_| p.axes.boxed) {
            Some((c, half)) => Extents::Box {
                rot: *rot,
                centre: rot * c + shift,
                half,
            },
            None => Extents::Points(pts),
        }
    }

    /// The least and greatest height along `n` (unit, `b`'s frame).
    fn extent(&self, n: &Vec3) -> (f64, f64) {
        match self {
            Extents::Box { rot, centre, half } => {
                let l = rot.inverse_transform_vector(n);
                let r = half.x * l.x.abs() + half.y * l.y.abs() + half.z * l.z.abs();
                let mid = n.dot(centre);
                (mid - r, mid + r)
            }
            Extents::Points(pts) => {
                let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
                for p in pts.iter() {
                    let h = n.x * p.x + n.y * p.y + n.z * p.z;
                    if h < lo {
                        lo = h;
                    }
                    if h > hi {
                        hi = h;
                    }
                }
                (lo, hi)
            }
        }
    }
}

/// The greatest separation of `axes` (−∞ without any).
fn best(axes: &[(f64, Axis)]) -> f64 {
    axes.iter().map(|x| x.0).fold(f64::NEG_INFINITY, f64::max)
}

/// The one point of `over` at the least height `sep` over the face
/// `(n, ids)` of the polytope with vertices `face_pts`, when its foot on
/// the face's plane lies on the face: the point and its foot. `None` when
/// another point lies within `tie` of that height (a face or an edge
/// lying flush: its contact is a patch, left to parry, whose witness the
/// patch and rest rules were built on).
fn over_face(
    over: &[Vec3],
    face_pts: &[Vec3],
    n: &Vec3,
    ids: &[usize],
    sep: f64,
    eps: f64,
    tie: f64,
) -> Option<(Vec3, Vec3)> {
    let level = n.dot(&face_pts[ids[0]]);
    let mut low = over.iter().filter(|p| n.dot(p) - level <= sep + tie);
    let (p, None) = (low.next()?, low.next()) else {
        return None;
    };
    let h = n.dot(p) - level;
    let foot = p - n * h;
    on_polygon(&foot, n, ids.iter().map(|&k| &face_pts[k]), eps).then_some((*p, foot))
}

/// Whether `p`, on the plane of a convex polygon with normal `n` and
/// corners `corners` in order around it, lies on the polygon (within
/// `eps`, either winding). `FlatFace::holds` asks the same of a face it
/// owns; this one reads the part's own corners, without building one.
fn on_polygon<'p>(
    p: &Vec3,
    n: &Vec3,
    corners: impl Iterator<Item = &'p Vec3> + Clone,
    eps: f64,
) -> bool {
    let next = corners.clone().cycle().skip(1);
    let (mut left, mut right) = (false, false);
    for (u, w) in corners.zip(next) {
        let edge = w - u;
        let side = edge.cross(&(p - u)).dot(n);
        let slack = eps * edge.norm();
        left |= side > slack;
        right |= side < -slack;
        if left && right {
            return false;
        }
    }
    true
}

/// The one edge of `a` along direction `dirs[0]` at `a`'s least height
/// along `n` and the one edge of `b` along `dirs[1]` at `b`'s greatest,
/// when each is its polytope's only support (no third vertex within `tie`
/// of it) and their closest points lie inside both: those points.
fn crossing(
    pts: [&[Vec3]; 2],
    edges: [&[[usize; 2]]; 2],
    dirs: [&Vec3; 2],
    n: &Vec3,
    tie: f64,
) -> Option<(Vec3, Vec3)> {
    // The supporting edge of polytope `k` towards the other (`sign`: −1
    // for a's least height, +1 for b's greatest).
    let supporting = |k: usize, sign: f64| {
        let heights = pts[k].iter().map(|p| sign * n.dot(p));
        let top = heights.clone().fold(f64::NEG_INFINITY, f64::max);
        if heights.filter(|h| *h >= top - tie).count() != 2 {
            return None;
        }
        // Heights first: only the supporting edge passes them.
        edges[k].iter().find(|[i, j]| {
            let (p, q) = (&pts[k][*i], &pts[k][*j]);
            sign * n.dot(p) >= top - tie
                && sign * n.dot(q) >= top - tie
                && (q - p).normalize().cross(dirs[k]).norm() < 1e-9
        })
    };
    let [i, j] = supporting(0, -1.0)?;
    let [k, l] = supporting(1, 1.0)?;
    let (p0, p1, q0, q1) = (pts[0][*i], pts[0][*j], pts[1][*k], pts[1][*l]);
    let (d, e, r) = (p1 - p0, q1 - q0, p0 - q0);
    // Closest points of the two lines: `p0 + s d`, `q0 + t e`.
    let (dd, ee, de, dr, er) = (d.dot(&d), e.dot(&e), d.dot(&e), d.dot(&r), e.dot(&r));
    let den = dd * ee - de * de;
    if den <= 0.0 {
        return None;
    }
    let s = (de * er - ee * dr) / den;
    let t = (dd * er - de * dr) / den;
    // Strictly inside both: a crossing at an end is a vertex on an edge.
    let (ms, mt) = (tie / dd.sqrt(), tie / ee.sqrt());
    ((ms..=1.0 - ms).contains(&s) && (mt..=1.0 - mt).contains(&t)).then(|| (p0 + d * s, q0 + e * t))
}

#[cfg(test)]
mod tests;
