//! Contact queries between two geometries: the closest approach of every
//! part pair, with the bounds that prune far pairs.

use super::shapes::{Geometry, Part, PartKind};
use crate::math::{Mat3, Vec3};
use nalgebra::{Isometry3, Point3};
use parry3d_f64::query;
use smallvec::SmallVec;

/// The closest approach of two geometries.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    /// Signed distance, m: `> 0` apart, `< 0` penetrating.
    pub distance: f64,
    /// Unit normal in world space pointing from `b` towards `a`.
    pub normal: Vec3,
    /// Witness point on `a`'s surface, world space.
    pub point_a: Vec3,
    /// Witness point on `b`'s surface, world space.
    pub point_b: Vec3,
    /// Index of the touching part of `a`.
    pub part_a: usize,
    /// Index of the touching part of `b`.
    pub part_b: usize,
}

impl Contact {
    fn flipped(self) -> Contact {
        Contact {
            distance: self.distance,
            normal: -self.normal,
            point_a: self.point_b,
            point_b: self.point_a,
            part_a: self.part_b,
            part_b: self.part_a,
        }
    }
}

mod parabola;
pub(super) mod polytope;

pub use parabola::point_parabola;
use parabola::{against_parabola, parabola_point};
use polytope::Decided;

fn to_point(v: &Vec3) -> Point3<f64> {
    Point3::from(*v)
}

/// Contact of one part pair; `None` if farther apart than `max_distance`
/// or if the pair is unsupported (two unbounded parts).
fn part_contact(
    pa: &Part,
    pose_a: &Isometry3<f64>,
    pb: &Part,
    pose_b: &Isometry3<f64>,
    max_distance: f64,
) -> Option<Contact> {
    // Bounds farther apart than `max_distance`: no contact to report, and
    // no need to ask parry (a bucket's far walls, most of a compound's
    // parts).
    let (x, y) = (Placed::new(0, pa, pose_a), Placed::new(0, pb, pose_b));
    if x.beyond(&y, max_distance) {
        return None;
    }
    placed_part_contact(pa, &x.world, pb, &y.world, max_distance)
}

/// [`part_contact`] without the bounds' test.
#[cfg(test)]
fn unculled_part_contact(
    pa: &Part,
    pose_a: &Isometry3<f64>,
    pb: &Part,
    pose_b: &Isometry3<f64>,
    max_distance: f64,
) -> Option<Contact> {
    placed_part_contact(
        pa,
        &(pose_a * pa.offset),
        pb,
        &(pose_b * pb.offset),
        max_distance,
    )
}

/// The contact of two parts whose own frames are at `wa` and `wb` (world),
/// without the bounds' test (the caller has made it).
fn placed_part_contact(
    pa: &Part,
    wa: &Isometry3<f64>,
    pb: &Part,
    wb: &Isometry3<f64>,
    max_distance: f64,
) -> Option<Contact> {
    match (&pa.kind, &pb.kind) {
        (_, PartKind::Parabola { curvature, .. }) => {
            let (d, n, p_a, p_b) = against_parabola(pa, wa, wb, *curvature)?;
            (d <= max_distance).then_some(Contact {
                distance: d,
                normal: n,
                point_a: p_a,
                point_b: p_b,
                part_a: 0,
                part_b: 0,
            })
        }
        (PartKind::Parabola { .. }, _) => {
            placed_part_contact(pb, wb, pa, wa, max_distance).map(Contact::flipped)
        }
        (PartKind::HalfSpace { .. }, PartKind::HalfSpace { .. }) => None,
        // parry returns a wrong distance and witness points when a half-space
        // is the *second* shape (seen in 0.25 through 0.31): always pass it first.
        (_, PartKind::HalfSpace { .. }) => {
            let sa = pa.shape.as_ref()?;
            let sb = pb.shape.as_ref()?;
            let c = query::contact(wb, sb.as_ref(), wa, sa.as_ref(), max_distance).ok()??;
            // Shape 1 is b (the half-space): normal1 points from b towards a.
            Some(Contact {
                distance: c.dist,
                normal: c.normal1.into_inner(),
                point_a: c.point2.coords,
                point_b: c.point1.coords,
                part_a: 0,
                part_b: 0,
            })
        }
        (PartKind::HalfSpace { .. }, _) => {
            placed_part_contact(pb, wb, pa, wa, max_distance).map(Contact::flipped)
        }
        _ => {
            // Small polytopes: separating axes decide most pairs exactly
            // (`polytope`); parry the rest.
            match polytope::contact(pa, wa, pb, wb, max_distance) {
                Some(Decided::Beyond) => return None,
                Some(Decided::Contact(c)) => return Some(c),
                None => {}
            }
            let sa = pa.shape.as_ref()?;
            let sb = pb.shape.as_ref()?;
            let c = query::contact(wa, sa.as_ref(), wb, sb.as_ref(), max_distance).ok()??;
            Some(Contact {
                distance: c.dist,
                normal: -c.normal1.into_inner(),
                point_a: c.point1.coords,
                point_b: c.point2.coords,
                part_a: 0,
                part_b: 0,
            })
        }
    }
}

/// Every part pair's contact closer than `max_distance` (m), each with its
/// part indices: for a static convex obstacle part, the plane through
/// `point_b` with normal `normal` separates it from that part of `a`.
pub fn part_contacts(
    a: &Geometry,
    pose_a: &Isometry3<f64>,
    b: &Geometry,
    pose_b: &Isometry3<f64>,
    max_distance: f64,
) -> Vec<Contact> {
    Placement::new(a, pose_a)
        .part_contacts(&Placement::new(b, pose_b), max_distance)
        .into_vec()
}

/// A few part contacts, kept on the stack (a contact query returns one
/// per close part pair, rarely more than four).
pub type PartContacts = SmallVec<[Contact; 4]>;

/// A geometry placed in the world for contact queries: each part's world
/// frame and bounds, computed once. A static obstacle's is computed once
/// per simulation; a body's once per query.
pub struct Placement<'g> {
    /// On the stack for a few parts: a body is placed once per query.
    parts: SmallVec<[Placed<'g>; 4]>,
}

impl<'g> Placement<'g> {
    /// `g` placed at `pose`.
    pub fn new(g: &'g Geometry, pose: &Isometry3<f64>) -> Placement<'g> {
        Placement {
            parts: g
                .parts
                .iter()
                .enumerate()
                .map(|(k, p)| Placed::new(k, p, pose))
                .collect(),
        }
    }

    /// This placement without the parts `parts` (the others keep their
    /// indices): a body pivoting on them is not searched against them.
    pub fn without(&self, parts: &[usize]) -> Placement<'g> {
        Placement {
            parts: self
                .parts
                .iter()
                .filter(|p| !parts.contains(&p.index))
                .cloned()
                .collect(),
        }
    }

    /// As [`part_contacts`], between this placement (`a`) and `b`.
    pub fn part_contacts(&self, b: &Placement, max_distance: f64) -> PartContacts {
        let mut out = PartContacts::new();
        for x in &self.parts {
            for y in &b.parts {
                if !x.beyond(y, max_distance)
                    && let Some(c) = x.contact(y, max_distance)
                {
                    out.push(c);
                }
            }
        }
        out
    }

    /// As [`contact`], between this placement (`a`) and `b`.
    pub fn contact(&self, b: &Placement, max_distance: f64) -> Option<Contact> {
        let (pa, pb) = (&self.parts, &b.parts);
        if let ([x], [y]) = (pa.as_slice(), pb.as_slice()) {
            // One part pair: nothing to order.
            return (!x.beyond(y, max_distance))
                .then(|| x.contact(y, max_distance))
                .flatten();
        }
        // Ask the part pairs in the order of their distance bounds: the
        // closest distance found so far caps every later pair's (a pair
        // whose bound is larger cannot be closer), so the search stops at
        // the first pair bounded beyond it. Of equally close part pairs the
        // first in part order wins.
        let mut pairs: SmallVec<[(f64, (usize, usize)); 16]> = (0..pa.len())
            .flat_map(|ia| (0..pb.len()).map(move |ib| (ia, ib)))
            .map(|(ia, ib)| (pa[ia].bound(&pb[ib]), (ia, ib)))
            .collect();
        pairs.sort_by(|x, y| x.0.total_cmp(&y.0));
        let mut best: Option<Contact> = None;
        for (bound, (ia, ib)) in pairs {
            let cap = best.map_or(max_distance, |c| c.distance.min(max_distance));
            if bound > cap + BOUND_SLACK {
                break;
            }
            let Some(c) = pa[ia].contact(&pb[ib], cap) else {
                continue;
            };
            let closer = |b: &Contact| {
                c.distance
                    .total_cmp(&b.distance)
                    .then((c.part_a, c.part_b).cmp(&(b.part_a, b.part_b)))
                    .is_lt()
            };
            if best.as_ref().is_none_or(closer) {
                best = Some(c);
            }
        }
        best
    }
}

/// How much a part pair's bound may exceed a distance (m) before the pair
/// is culled: the bound is computed in floating point too, and a pair that
/// touches exactly as closely as the closest one must still be asked.
const BOUND_SLACK: f64 = 1e-9;

/// A part placed in the world for one query, with what its distance bounds
/// need, computed once per part rather than once per part pair.
#[derive(Clone)]
struct Placed<'g> {
    /// The part's index in its geometry.
    index: usize,
    part: &'g Part,
    /// The part's own frame, world (its origin is the bounding sphere's
    /// centre).
    world: Isometry3<f64>,
    /// The part's frame as a rotation matrix (columns: its axes, world)
    /// and its bounding box's centre (world) and half extents; `None`
    /// without a box.
    frame: Option<(Mat3, Vec3, Vec3)>,
    /// A half-space's outward normal and a point of its plane, world.
    plane: Option<(Vec3, Vec3)>,
}

impl<'g> Placed<'g> {
    fn new(index: usize, part: &'g Part, owner: &Isometry3<f64>) -> Placed<'g> {
        let w = owner * part.offset;
        let frame = part.local_box().map(|(c, h)| {
            (
                w.rotation.to_rotation_matrix().into_inner(),
                (w * Point3::from(c)).coords,
                h,
            )
        });
        let plane = match &part.kind {
            PartKind::HalfSpace { normal } => Some((w.rotation * normal, w.translation.vector)),
            _ => None,
        };
        Placed {
            index,
            part,
            world: w,
            frame,
            plane,
        }
    }

    /// Whether the two parts are certainly farther apart than `distance`
    /// (m), by the cheaper test first: bounding spheres, then boxes.
    fn beyond(&self, other: &Placed, distance: f64) -> bool {
        let limit = distance + BOUND_SLACK;
        self.sphere_gap(other) > limit || self.box_gap(other) > limit
    }

    /// A lower bound on the distance between the two parts (negative when
    /// they may overlap; −∞ when nothing bounds it).
    fn bound(&self, other: &Placed) -> f64 {
        self.sphere_gap(other).max(self.box_gap(other))
    }

    /// Distance between the bounding spheres (negative when they overlap;
    /// −∞ for an unbounded part).
    fn sphere_gap(&self, other: &Placed) -> f64 {
        (self.world.translation.vector - other.world.translation.vector).norm()
            - self.part.local_radius()
            - other.part.local_radius()
    }

    /// The separation of the two parts' bounding boxes along the boxes'
    /// face normals (a lower bound on their distance: along any unit
    /// direction, the gap between two convex sets' projections is at most
    /// their distance), or a box's height over a half-space; −∞ when
    /// neither applies.
    fn box_gap(&self, other: &Placed) -> f64 {
        match (&self.frame, &other.frame, &self.plane, &other.plane) {
            (Some((ma, ca, ha)), Some((mb, cb, hb)), _, _) => {
                // c[(i, j)] = aᵢ · bⱼ; `ta`, `tb`: the centres' offset along
                // a's and b's axes.
                let d = cb - ca;
                let c = ma.transpose() * mb;
                let ta = ma.transpose() * d;
                let tb = mb.transpose() * d;
                let mut gap = f64::NEG_INFINITY;
                for i in 0..3 {
                    let rb =
                        hb.x * c[(i, 0)].abs() + hb.y * c[(i, 1)].abs() + hb.z * c[(i, 2)].abs();
                    let ra =
                        ha.x * c[(0, i)].abs() + ha.y * c[(1, i)].abs() + ha.z * c[(2, i)].abs();
                    gap = gap
                        .max(ta[i].abs() - ha[i] - rb)
                        .max(tb[i].abs() - ra - hb[i]);
                }
                gap
            }
            (Some(bx), None, _, Some(pl)) | (None, Some(bx), Some(pl), _) => over_plane(bx, pl),
            _ => f64::NEG_INFINITY,
        }
    }

    /// The contact of the two parts closer than `max_distance`, if it is
    /// finite, labelled with their indices (the bounds' test is the
    /// caller's).
    fn contact(&self, other: &Placed, max_distance: f64) -> Option<Contact> {
        let mut c = placed_part_contact(
            self.part,
            &self.world,
            other.part,
            &other.world,
            max_distance,
        )?;
        if !(c.distance.is_finite() && c.normal.iter().all(|v| v.is_finite())) {
            return None;
        }
        c.part_a = self.index;
        c.part_b = other.index;
        Some(c)
    }
}

/// Height of the box `(frame, centre, half extents)` over the half-space
/// `(outward normal, point of the plane)`: their distance (negative when
/// the box dips into it).
fn over_plane((m, c, h): &(Mat3, Vec3, Vec3), (n, p0): &(Vec3, Vec3)) -> f64 {
    let along = m.transpose() * n;
    n.dot(&(c - p0)) - h.dot(&along.abs())
}

/// A point of one geometry close to another (see [`near_points`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NearPoint {
    /// The point on `a` (a hull vertex, or a ball's closest point), world.
    pub point: Vec3,
    /// Unit normal of `b`'s surface there, pointing from `b` towards `a`.
    pub normal: Vec3,
    /// Signed distance of the point from `b`, m (`< 0` inside).
    pub distance: f64,
    /// Which features make the point, so that it can be followed as the
    /// owners move.
    pub corner: Corner,
}

/// The features that make a corner of a contact patch, with their
/// geometry in the owners' frames (`a`'s for `a`'s features, `b`'s for
/// `b`'s), so the corner can be re-evaluated at other poses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Corner {
    /// Hull vertex `index` of `a`'s part, at `p`.
    A { index: usize, p: Vec3 },
    /// Hull vertex `index` of `b`'s part, at `p` (the corner is its
    /// projection on `a`).
    B { index: usize, p: Vec3 },
    /// Edge `ea` of `a`'s part (end points `a`) crossing edge `eb` of
    /// `b`'s (end points `b`); the corner is the closest point on `a`'s
    /// edge.
    Crossing {
        ea: usize,
        eb: usize,
        a: [Vec3; 2],
        b: [Vec3; 2],
    },
    /// The closest point of one of `a`'s balls.
    Ball,
}

impl Corner {
    /// A short stable name: `a3` (vertex of a), `b5` (vertex of b), `x2.7`
    /// (edge 2 of a across edge 7 of b).
    pub fn name(&self) -> String {
        match self {
            Corner::A { index, .. } => format!("a{index}"),
            Corner::B { index, .. } => format!("b{index}"),
            Corner::Crossing { ea, eb, .. } => format!("x{ea}.{eb}"),
            Corner::Ball => "ball".to_string(),
        }
    }
}

/// The corners of the contact patches of `a` on `b`: every point within
/// `band` (m) on which `a` can lean on `b`, which is what a support polygon
/// needs (a single closest-point query gives only one of them). A patch
/// between convex pieces is a convex polygon whose corners are of three
/// kinds, all listed: hull vertices of `a` (and the closest point of each
/// of `a`'s balls) near `b`; hull vertices of `b` near `a` (a plank lying
/// across the corner of a support); and crossings of an edge of `a` with an
/// edge of `b` (a plank lying across a support's top face touches it in a
/// rectangle whose corners are neither's vertices).
pub fn near_points(
    a: &Geometry,
    pose_a: &Isometry3<f64>,
    b: &Geometry,
    pose_b: &Isometry3<f64>,
    band: f64,
) -> Vec<NearPoint> {
    let mut out = Vec::new();
    for pa in &a.parts {
        for pb in &b.parts {
            out.extend(part_near_points(pa, pose_a, pb, pose_b, band));
        }
    }
    out
}

/// [`near_points`] of one part of `a` (placed by its owner's `pose_a`) on
/// one part of `b`.
pub fn part_near_points(
    pa: &Part,
    pose_a: &Isometry3<f64>,
    pb: &Part,
    pose_b: &Isometry3<f64>,
    band: f64,
) -> Vec<NearPoint> {
    let mut out = Vec::new();
    // Pieces farther apart than the band have no near points; for convex
    // pieces the closest approach also bounds where the points can be.
    let Some(pair) = part_contact(pa, pose_a, pb, pose_b, band) else {
        return out;
    };
    let wa = pose_a * pa.offset;
    let wb = pose_b * pb.offset;
    // b lies below the plane through its witness point with normal `pair.normal`
    // (b towards a), a above the one through a's: a point of a more than
    // `band` above b's plane is farther than `band` from b, and so on.
    let slab = matches!(pb.kind, PartKind::Convex { .. } | PartKind::Ball { .. });
    let above_b = |p: &Vec3| pair.normal.dot(&(p - pair.point_b));
    let below_a = |p: &Vec3| pair.normal.dot(&(pair.point_a - p));
    let margin = band + 1e-9 * (1.0 + pair.point_b.norm());
    // Candidate points of a with the radius to subtract (on the stack:
    // this runs for every near part pair of every stepped step).
    let points: SmallVec<[(Vec3, f64, Corner); 16]> = match &pa.kind {
        PartKind::Ball { radius } => {
            std::iter::once((wa.translation.vector, *radius, Corner::Ball)).collect()
        }
        PartKind::Convex { vertices, .. } => vertices
            .iter()
            .enumerate()
            .map(|(index, v)| {
                let p = (pa.offset * to_point(v)).coords;
                ((wa * to_point(v)).coords, 0.0, Corner::A { index, p })
            })
            .filter(|(w, _, _)| !slab || above_b(w) <= margin)
            .collect(),
        _ => return out,
    };
    for &(p, radius, corner) in &points {
        let found = match &pb.kind {
            PartKind::HalfSpace { normal } => {
                let n = wb.rotation * normal;
                Some((n.dot(&(p - wb.translation.vector)), n))
            }
            PartKind::Parabola { curvature, .. } => {
                let (d, n, _) = parabola_point(&wb, *curvature, &p);
                Some((d, n))
            }
            _ => pb.shape.as_ref().and_then(|shape| {
                let proj = shape.project_point(&wb, &to_point(&p), false);
                let d = p - proj.point.coords;
                let len = d.norm();
                let sign = if proj.is_inside { -1.0 } else { 1.0 };
                if len > 1e-12 {
                    Some((sign * len, d / len * sign))
                } else {
                    // On the surface: take the normal of the part pair's contact.
                    let probe = Part::new(
                        PartKind::Ball { radius: 1e-9 },
                        Some(parry3d_f64::shape::SharedShape::ball(1e-9)),
                    );
                    let at = Isometry3::translation(p.x, p.y, p.z);
                    part_contact(&probe, &at, pb, pose_b, f64::INFINITY).map(|c| (0.0, c.normal))
                }
            }),
        };
        if let Some((d, n)) = found {
            let d = d - radius;
            if d <= band && d.is_finite() && n.iter().all(|v| v.is_finite()) {
                out.push(NearPoint {
                    point: p - n * radius,
                    normal: n,
                    distance: d,
                    corner,
                });
            }
        }
    }
    let (
        PartKind::Convex {
            vertices: va,
            edges: ea,
            ..
        },
        PartKind::Convex {
            vertices: vb,
            edges: eb,
            ..
        },
        Some(sa),
    ) = (&pa.kind, &pb.kind, pa.shape.as_ref())
    else {
        return out;
    };
    // The corners that are not vertices of a: vertices of b near a, and
    // edge–edge crossings. Every one takes the normal of the pieces'
    // closest approach (two convex pieces touch in one plane).
    let n = pair.normal;
    if !n.iter().all(|v| v.is_finite()) {
        return out;
    }
    let wva: SmallVec<[Vec3; 16]> = va.iter().map(|v| (wa * to_point(v)).coords).collect();
    let wvb: SmallVec<[Vec3; 16]> = vb.iter().map(|v| (wb * to_point(v)).coords).collect();
    let owner_a = |i: usize| (pa.offset * to_point(&va[i])).coords;
    let owner_b = |i: usize| (pb.offset * to_point(&vb[i])).coords;
    let near_b: SmallVec<[bool; 16]> = wvb.iter().map(|q| below_a(q) <= margin).collect();
    let near_a: SmallVec<[bool; 16]> = wva.iter().map(|p| above_b(p) <= margin).collect();
    for (index, p) in wvb.iter().enumerate().filter(|(i, _)| near_b[*i]) {
        let proj = sa.project_point(&wa, &to_point(p), false);
        let gap = (proj.point.coords - p).norm();
        let d = if proj.is_inside { -gap } else { gap };
        if d <= band && d.is_finite() {
            out.push(NearPoint {
                point: proj.point.coords,
                normal: n,
                distance: d,
                corner: Corner::B {
                    index,
                    p: owner_b(index),
                },
            });
        }
    }
    // An edge can cross into the slab only from an end inside it.
    let edges_b: SmallVec<[(usize, &[usize; 2]); 32]> = eb
        .iter()
        .enumerate()
        .filter(|(_, f)| near_b[f[0]] || near_b[f[1]])
        .collect();
    for (i, e) in ea.iter().enumerate() {
        if !(near_a[e[0]] || near_a[e[1]]) {
            continue;
        }
        let (p0, p1) = (wva[e[0]], wva[e[1]]);
        for &(j, f) in &edges_b {
            let Some((s, t)) = segment_crossing(&p0, &p1, &wvb[f[0]], &wvb[f[1]]) else {
                continue;
            };
            let on_a = p0 + (p1 - p0) * s;
            let on_b = wvb[f[0]] + (wvb[f[1]] - wvb[f[0]]) * t;
            let d = n.dot(&(on_a - on_b));
            if d.abs() <= band && (on_a - on_b).norm() <= band {
                out.push(NearPoint {
                    point: on_a,
                    normal: n,
                    distance: d,
                    corner: Corner::Crossing {
                        ea: i,
                        eb: j,
                        a: [owner_a(e[0]), owner_a(e[1])],
                        b: [owner_b(f[0]), owner_b(f[1])],
                    },
                });
            }
        }
    }
    out
}

/// A flat face of a part, in world space (see [`flat_faces`]).
#[derive(Debug, Clone, PartialEq)]
pub struct FlatFace {
    /// Outward unit normal.
    pub normal: Vec3,
    /// The face's plane is `normal · p = offset`.
    pub offset: f64,
    /// The face polygon's corners in order (empty: unbounded, a half-space).
    pub polygon: Vec<Vec3>,
}

impl FlatFace {
    /// Whether `p` is within `tol` (m) of the face: of its plane, and of
    /// the polygon seen along the normal.
    pub fn holds(&self, p: &Vec3, tol: f64) -> bool {
        if (self.normal.dot(p) - self.offset).abs() > tol {
            return false;
        }
        let n = self.polygon.len();
        (0..n).all(|i| {
            let (a, b) = (self.polygon[i], self.polygon[(i + 1) % n]);
            let edge = b - a;
            // Outward in-plane direction of the edge (counter-clockwise
            // around the outward normal).
            let out = edge.cross(&self.normal);
            out.dot(&(p - a)) <= tol * out.norm()
        })
    }

    /// How far inside the polygon `p` lies, seen along the normal: the
    /// least distance to an edge's line (negative outside; infinite for a
    /// half-space's plane).
    pub fn depth(&self, p: &Vec3) -> f64 {
        self.nearest_edge(p).map_or(f64::INFINITY, |(d, _)| d)
    }

    /// The edge whose line `p` is nearest inside (see [`depth`]): the
    /// depth and the edge's outward unit normal in the face's plane.
    ///
    /// [`depth`]: FlatFace::depth
    pub fn nearest_edge(&self, p: &Vec3) -> Option<(f64, Vec3)> {
        let n = self.polygon.len();
        (0..n)
            .filter_map(|i| {
                let (a, b) = (self.polygon[i], self.polygon[(i + 1) % n]);
                let out = (b - a).cross(&self.normal).try_normalize(0.0)?;
                Some((-out.dot(&(p - a)), out))
            })
            .min_by(|x, y| x.0.total_cmp(&y.0))
    }
}

/// The flat faces of a part placed by its owner's `pose` that face `dir`
/// (unit, world) within the angle whose cosine is `cos_min`: a half-space's
/// plane, or hull faces. Balls and parabolas have none.
pub fn flat_faces(part: &Part, pose: &Isometry3<f64>, dir: &Vec3, cos_min: f64) -> Vec<FlatFace> {
    let w = pose * part.offset;
    match &part.kind {
        PartKind::HalfSpace { normal } => {
            let m = w.rotation * normal;
            if m.dot(dir) >= cos_min {
                vec![FlatFace {
                    normal: m,
                    offset: m.dot(&w.translation.vector),
                    polygon: Vec::new(),
                }]
            } else {
                Vec::new()
            }
        }
        PartKind::Convex {
            vertices, faces, ..
        } => faces
            .iter()
            .filter_map(|(f, ids)| {
                let m = w.rotation * f;
                (m.dot(dir) >= cos_min).then(|| {
                    let mut polygon: Vec<Vec3> = ids
                        .iter()
                        .filter_map(|&i| vertices.get(i))
                        .map(|v| (w * to_point(v)).coords)
                        .collect();
                    // Counter-clockwise around the outward normal.
                    let k = polygon.len();
                    let turn: Vec3 = (0..k)
                        .map(|i| polygon[i].cross(&polygon[(i + 1) % k]))
                        .sum();
                    if turn.dot(&m) < 0.0 {
                        polygon.reverse();
                    }
                    let offset = polygon
                        .iter()
                        .map(|p| m.dot(p))
                        .fold(f64::NEG_INFINITY, f64::max);
                    FlatFace {
                        normal: m,
                        offset,
                        polygon,
                    }
                })
            })
            .collect(),
        PartKind::Ball { .. } | PartKind::Parabola { .. } => Vec::new(),
    }
}

/// The parameters `(s, t)` of the closest points of two non-parallel
/// segments `p0 + s (p1 − p0)` and `q0 + t (q1 − q0)` when both lie strictly
/// inside their segments (else the closest approach is at an end point,
/// which the vertex cases cover).
fn segment_crossing(p0: &Vec3, p1: &Vec3, q0: &Vec3, q1: &Vec3) -> Option<(f64, f64)> {
    let (u, v, w) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, b, c, d, e) = (u.dot(&u), u.dot(&v), v.dot(&v), u.dot(&w), v.dot(&w));
    let den = a * c - b * b;
    if den <= 1e-12 * a * c {
        return None;
    }
    let s = (b * e - c * d) / den;
    let t = (a * e - b * d) / den;
    (s > 0.0 && s < 1.0 && t > 0.0 && t < 1.0).then_some((s, t))
}

/// The closest contact between two geometries placed at `pose_a` and
/// `pose_b`, or `None` when every part pair is farther apart than
/// `max_distance` (m). Compounds are searched part by part.
pub fn contact(
    a: &Geometry,
    pose_a: &Isometry3<f64>,
    b: &Geometry,
    pose_b: &Isometry3<f64>,
    max_distance: f64,
) -> Option<Contact> {
    Placement::new(a, pose_a).contact(&Placement::new(b, pose_b), max_distance)
}

#[cfg(test)]
mod tests;
