//! The touching features of a contact and how the contact point and
//! normal move with the owners, generic in the scalar (dual numbers).

use super::contact::{Contact, Corner, point_parabola};
use super::shapes::{Geometry, PartKind};
use crate::math::Vec3;
use nalgebra::{Isometry3, Matrix3, RealField, Vector3, convert};

/// A touching feature of one side, in its owner's frame.
#[derive(Debug, Clone, PartialEq)]
pub enum SideFeature {
    /// A material point (a vertex, a centroid of several vertices, or a ball
    /// centre with `radius > 0`). `vertices` lists the hull vertices it stands for.
    Point {
        p: Vec3,
        radius: f64,
        vertices: Vec<usize>,
    },
    /// A material plane (a face, or a half-space) with outward `normal` through `point`.
    Plane {
        normal: Vec3,
        point: Vec3,
        vertices: Vec<usize>,
    },
    /// A material line (an edge) through `point` along `dir`.
    Line {
        point: Vec3,
        dir: Vec3,
        vertices: [usize; 2],
    },
    /// A parabolic cylinder `z = −κ x²` placed at `frame` in the owner frame.
    Parabola {
        frame: Isometry3<f64>,
        curvature: f64,
        foot_hint: f64,
    },
}

/// How two owners touch: one feature on each side plus the parts involved.
/// It models how the contact point and normal move with the owners, which
/// the collision Jacobian needs (docs/design.md §5).
#[derive(Debug, Clone, PartialEq)]
pub struct FeaturePair {
    pub a: SideFeature,
    pub b: SideFeature,
    pub part_a: usize,
    pub part_b: usize,
    /// Orientation of the edge–edge normal relative to `d_a × d_b`.
    pub sign: f64,
    /// The contact patch when a flat face lies in the contact plane (see
    /// [`FeaturePair::at_patch`]): the impulse acts at the corners'
    /// centroid weighted by how close each is to the face; the distance and
    /// normal stay those of the touching features. Empty for a contact of
    /// single features.
    pub patch: Vec<PatchCorner>,
    /// Depth (m) over which a patch corner's weight falls from 1 (on the
    /// face) to 0.
    pub patch_depth: f64,
    /// The flat face whose normal a patch impulse takes: whether it is
    /// `a`'s, and its outward normal in its owner's frame.
    pub patch_face: Option<(bool, Vec3)>,
}

/// A pose with a generic scalar (so dual numbers can flow through it).
#[derive(Debug, Clone)]
pub struct PoseT<T: RealField> {
    /// Origin (centre of mass) in world space.
    pub x: Vector3<T>,
    /// Rotation matrix, owner frame to world.
    pub r: Matrix3<T>,
}

impl PoseT<f64> {
    /// From an isometry.
    pub fn from_isometry(iso: &Isometry3<f64>) -> Self {
        PoseT {
            x: iso.translation.vector,
            r: *iso.rotation.to_rotation_matrix().matrix(),
        }
    }
}

/// Contact geometry evaluated from a [`FeaturePair`].
#[derive(Debug, Clone)]
pub struct ContactGeometry<T: RealField> {
    /// Signed distance along the feature model.
    pub distance: T,
    /// Unit normal from b towards a.
    pub normal: Vector3<T>,
    /// Contact point on a, world.
    pub point_a: Vector3<T>,
    /// Contact point on b, world.
    pub point_b: Vector3<T>,
    /// Torsional friction radius of a contact patch (m): the root mean
    /// square distance of its weighted corners from the impulse point, in
    /// the contact plane. Coulomb friction at the corners resists a spin
    /// about the normal with a torque of at most `μ · spin_radius · P_n`
    /// (exact when every corner slides and carries the same load). 0 for a
    /// contact at one point, which resists no spin.
    pub spin_radius: T,
}

fn cv<T: RealField>(v: &Vec3) -> Vector3<T> {
    v.map(convert::<f64, T>)
}

fn world_point<T: RealField>(pose: &PoseT<T>, p: &Vec3) -> Vector3<T> {
    &pose.x + &pose.r * cv::<T>(p)
}

fn world_dir<T: RealField>(pose: &PoseT<T>, d: &Vec3) -> Vector3<T> {
    &pose.r * cv::<T>(d)
}

fn side(g: &Geometry, part: usize, pose: &Isometry3<f64>, towards: &Vec3) -> SideFeature {
    let p = &g.parts[part];
    match &p.kind {
        PartKind::Ball { radius } => SideFeature::Point {
            p: p.offset.translation.vector,
            radius: *radius,
            vertices: Vec::new(),
        },
        PartKind::HalfSpace { normal } => SideFeature::Plane {
            normal: p.offset.rotation * normal,
            point: p.offset.translation.vector,
            vertices: Vec::new(),
        },
        PartKind::Parabola { curvature, .. } => SideFeature::Parabola {
            frame: p.offset,
            curvature: *curvature,
            foot_hint: 0.0,
        },
        PartKind::Convex { .. } => {
            let d = pose.rotation.inverse() * towards;
            let verts = p.vertices();
            let reach = verts.iter().map(|v| v.norm()).fold(1.0, f64::max);
            let tol = 1e-9 * reach;
            let max = verts
                .iter()
                .map(|v| v.dot(&d))
                .fold(f64::NEG_INFINITY, f64::max);
            let support: Vec<usize> = (0..verts.len())
                .filter(|&i| verts[i].dot(&d) >= max - tol)
                .collect();
            let centroid =
                support.iter().map(|&i| verts[i]).sum::<Vec3>() / support.len().max(1) as f64;
            match support.len() {
                1 => SideFeature::Point {
                    p: verts[support[0]],
                    radius: 0.0,
                    vertices: support,
                },
                2 => SideFeature::Line {
                    point: verts[support[0]],
                    dir: verts[support[1]] - verts[support[0]],
                    vertices: [support[0], support[1]],
                },
                _ => SideFeature::Plane {
                    normal: d.normalize(),
                    point: centroid,
                    vertices: support,
                },
            }
        }
    }
}

/// A corner of a contact patch and the flat face it lies on.
#[derive(Debug, Clone, PartialEq)]
pub struct PatchCorner {
    pub corner: Corner,
    /// Whether the face is `a`'s (else `b`'s).
    pub face_on_a: bool,
    /// The face's outward unit normal and a point of it, in its owner's frame.
    pub face_normal: Vec3,
    pub face_point: Vec3,
}

impl PatchCorner {
    /// The corner's height over its face (m) and its position, world.
    fn height<T: RealField>(&self, pa: &PoseT<T>, pb: &PoseT<T>) -> (T, Vector3<T>) {
        let c = corner_point(&self.corner, pa, pb);
        let owner = if self.face_on_a { pa } else { pb };
        let m = world_dir(owner, &self.face_normal);
        let q = world_point(owner, &self.face_point);
        (m.dot(&(&c - q)), c)
    }
}

impl PatchCorner {
    /// The corner's gap (m): how far the party without the face stands
    /// off the face there, along the face's normal; zero when the corner
    /// touches, so it is this corner's own event function. It is
    /// [`PatchCorner::height`] except where `b`'s edge crosses `a`'s face:
    /// the corner point lies on `a`'s edge, in the face itself, so the gap
    /// is measured at `b`'s edge instead.
    pub fn gap<T: RealField>(&self, pa: &PoseT<T>, pb: &PoseT<T>) -> T {
        match (&self.corner, self.face_on_a) {
            (Corner::Crossing { a, b, .. }, true) => {
                let c = closest_on_first_line(pb, b, pa, a);
                let m = world_dir(pa, &self.face_normal);
                let q = world_point(pa, &self.face_point);
                m.dot(&(c - q))
            }
            _ => self.height(pa, pb).0,
        }
    }
}

/// A corner's weight in the patch centroid at height `h` over its face:
/// `(1 − h/D)²` below the depth `D`, 0 above. It falls smoothly to 0 at
/// `D`, so corners enter and leave the patch without a jump of the impulse
/// point (and without a change of the motion's signature). It is smooth
/// through `h = 0` too (a corner touching at the event, or sunk a skin
/// into the face, has weight about 1): a clamp there would differentiate
/// one-sided at the root.
fn corner_weight<T: RealField>(h: T, depth: f64) -> T {
    let d: T = convert(depth);
    if h >= d {
        T::zero()
    } else {
        let x = T::one() - h / d;
        x.clone() * x
    }
}

/// A patch corner's position (world) at the owners' poses.
fn corner_point<T: RealField>(corner: &Corner, pa: &PoseT<T>, pb: &PoseT<T>) -> Vector3<T> {
    match corner {
        Corner::A { p, .. } => world_point(pa, p),
        Corner::B { p, .. } => world_point(pb, p),
        // The point of a's edge line closest to b's edge line.
        Corner::Crossing { a, b, .. } => closest_on_first_line(pa, a, pb, b),
        // Balls never form patches (a ball touches in one point).
        Corner::Ball => world_point(pa, &Vec3::zeros()),
    }
}

/// The point of the first edge's line (end points `e` in the frame of
/// pose `pe`) closest to the second edge's line (`f` at `pf`), world.
fn closest_on_first_line<T: RealField>(
    pe: &PoseT<T>,
    e: &[Vec3; 2],
    pf: &PoseT<T>,
    f: &[Vec3; 2],
) -> Vector3<T> {
    let p = world_point(pe, &e[0]);
    let u = world_dir(pe, &(e[1] - e[0]));
    let q = world_point(pf, &f[0]);
    let v = world_dir(pf, &(f[1] - f[0]));
    let w = &p - &q;
    let (uu, uv, vv) = (u.dot(&u), u.dot(&v), v.dot(&v));
    let (uw, vw) = (u.dot(&w), v.dot(&w));
    let den = uu * vv.clone() - uv.clone() * uv.clone();
    let s = (uv * vw - vv * uw) / den;
    p + u * s
}

/// Reduce a feature to a material point (its centroid).
fn as_point(f: &SideFeature) -> SideFeature {
    match f {
        SideFeature::Line {
            point,
            dir,
            vertices,
        } => SideFeature::Point {
            p: point + dir * 0.5,
            radius: 0.0,
            vertices: vertices.to_vec(),
        },
        SideFeature::Plane {
            point, vertices, ..
        } => SideFeature::Point {
            p: *point,
            radius: 0.0,
            vertices: vertices.clone(),
        },
        other => other.clone(),
    }
}

impl FeaturePair {
    /// Name the touching features of a contact found by [`super::contact`].
    pub fn classify(
        a: &Geometry,
        pose_a: &Isometry3<f64>,
        b: &Geometry,
        pose_b: &Isometry3<f64>,
        c: &Contact,
    ) -> FeaturePair {
        let fa = side(a, c.part_a, pose_a, &-c.normal);
        let mut fb = side(b, c.part_b, pose_b, &c.normal);
        if let SideFeature::Parabola {
            frame,
            curvature,
            foot_hint,
        } = &mut fb
        {
            let local = (pose_b * *frame)
                .inverse_transform_point(&c.point_b.into())
                .coords;
            *foot_hint = point_parabola(*curvature, local.x, local.z);
        }
        let mut sign = 1.0;
        let (fa, fb) = match (&fa, &fb) {
            (SideFeature::Point { .. }, _) => (fa, fb),
            (_, SideFeature::Point { .. }) => (fa, fb),
            (SideFeature::Line { dir: da, .. }, SideFeature::Line { point, dir: db, .. }) => {
                let m = (pose_a.rotation * da).cross(&(pose_b.rotation * db));
                if m.norm() > 1e-6 * da.norm() * db.norm() {
                    sign = if m.dot(&c.normal) >= 0.0 { 1.0 } else { -1.0 };
                    (fa, fb)
                } else {
                    // Parallel edges touch along a segment: a plane through b's
                    // edge with the contact normal, against a's edge midpoint.
                    let n_local = pose_b.rotation.inverse() * c.normal;
                    (
                        as_point(&fa),
                        SideFeature::Plane {
                            normal: n_local,
                            point: *point,
                            vertices: Vec::new(),
                        },
                    )
                }
            }
            (SideFeature::Plane { vertices, .. }, SideFeature::Plane { .. })
                if vertices.is_empty() =>
            {
                (fa, as_point(&fb))
            }
            (_, SideFeature::Plane { .. }) | (_, SideFeature::Parabola { .. }) => {
                (as_point(&fa), fb)
            }
            (SideFeature::Plane { .. }, _) => (fa, as_point(&fb)),
            _ => (as_point(&fa), fb),
        };
        FeaturePair {
            a: fa,
            b: fb,
            part_a: c.part_a,
            part_b: c.part_b,
            sign,
            patch: Vec::new(),
            patch_depth: 0.0,
            patch_face: None,
        }
    }

    /// A short stable name of the touching features, part of the motion's
    /// signature: e.g. `0:v3/0:face`.
    pub fn key(&self) -> String {
        fn name(f: &SideFeature) -> String {
            match f {
                SideFeature::Point {
                    radius, vertices, ..
                } if *radius > 0.0 => {
                    let _ = vertices;
                    "ball".to_string()
                }
                SideFeature::Point { vertices, .. } => {
                    format!(
                        "v{}",
                        vertices
                            .iter()
                            .map(|v| v.to_string())
                            .collect::<Vec<_>>()
                            .join("+")
                    )
                }
                SideFeature::Plane { vertices, .. } if vertices.is_empty() => "plane".to_string(),
                SideFeature::Plane { vertices, .. } => {
                    format!(
                        "f{}",
                        vertices
                            .iter()
                            .map(|v| v.to_string())
                            .collect::<Vec<_>>()
                            .join("-")
                    )
                }
                SideFeature::Line { vertices, .. } => format!("e{}-{}", vertices[0], vertices[1]),
                SideFeature::Parabola { .. } => "parabola".to_string(),
            }
        }
        let key = format!(
            "{}:{}/{}:{}",
            self.part_a,
            name(&self.a),
            self.part_b,
            name(&self.b)
        );
        if self.patch.is_empty() {
            key
        } else {
            // Which corner touches first does not matter for a patch: the
            // impulse acts at the weighted centroid along the face normal,
            // both continuous as the touching corner changes.
            let side = match self.patch_face {
                Some((true, _)) => "a",
                _ => "b",
            };
            format!("{}:patch/{}:face-{side}", self.part_a, self.part_b)
        }
    }

    /// Number of hull vertices touching at once (more than one means a
    /// simultaneous contact resolved as one impulse at their centroid).
    pub fn simultaneous(&self) -> usize {
        if !self.patch.is_empty() {
            return self.patch.len().max(2);
        }
        match (&self.a, &self.b) {
            (SideFeature::Point { vertices, .. }, _) if vertices.len() > 1 => vertices.len(),
            (_, SideFeature::Point { vertices, .. }) if vertices.len() > 1 => vertices.len(),
            _ => 1,
        }
    }

    /// The hull vertices of `a` (index and position in `a`'s owner frame)
    /// that this contact stands for, when it is a simultaneous contact of
    /// several of them; empty otherwise.
    pub fn a_vertices(&self, a: &Geometry) -> Vec<(usize, Vec3)> {
        match &self.a {
            SideFeature::Point {
                vertices, radius, ..
            } if vertices.len() > 1 && *radius == 0.0 => {
                let verts = a
                    .parts
                    .get(self.part_a)
                    .map(|p| p.vertices())
                    .unwrap_or_default();
                vertices
                    .iter()
                    .filter_map(|&i| verts.get(i).map(|v| (i, *v)))
                    .collect()
            }
            _ => Vec::new(),
        }
    }

    /// The same contact reduced to one vertex of `a` (see
    /// [`FeaturePair::a_vertices`]): used when the centroid of a
    /// simultaneous contact does not approach but one of its vertices does
    /// (an edge rocking about its midpoint).
    pub fn with_a_vertex(&self, vertex: usize, p: Vec3) -> FeaturePair {
        FeaturePair {
            a: SideFeature::Point {
                p,
                radius: 0.0,
                vertices: vec![vertex],
            },
            patch: Vec::new(),
            ..self.clone()
        }
    }

    /// The contact modelled as `a`'s material point at the witness point
    /// `contact.point_a` against `b`'s tangent plane at `contact.point_b`
    /// (normal `contact.normal`). Its distance has the same first
    /// derivative as the true contact's; used when the classified features
    /// touch at an end of one of them, where their extrapolated model
    /// misplaces the point.
    pub fn on_tangent_plane(
        &self,
        pose_a: &Isometry3<f64>,
        pose_b: &Isometry3<f64>,
        contact: &Contact,
    ) -> FeaturePair {
        FeaturePair {
            a: SideFeature::Point {
                p: pose_a
                    .inverse_transform_point(&contact.point_a.into())
                    .coords,
                radius: 0.0,
                vertices: Vec::new(),
            },
            b: SideFeature::Plane {
                normal: pose_b.inverse_transform_vector(&contact.normal),
                point: pose_b
                    .inverse_transform_point(&contact.point_b.into())
                    .coords,
                vertices: Vec::new(),
            },
            patch: Vec::new(),
            ..self.clone()
        }
    }

    /// A contact where a flat face lies in the contact plane (an edge or a
    /// face landing on a face, a plank across a support): the same touching
    /// features — whose distance is the event function — with the impulse
    /// along the flat `face`'s normal (`(true, n)`: a face of `a`, `n` in
    /// its frame), at the centroid of the patch's `corners`, each weighted
    /// by its height over its face (full weight on it, none from `depth`
    /// up). One impulse there is the simultaneous
    /// impact of the corners; taking them one by one instead depends on
    /// their order and rocks and turns the body (friction at an off-centre
    /// corner). The weights and the centroid follow each corner's features
    /// as the owners move, so the collision Jacobian stays exact.
    pub fn at_patch(
        &self,
        corners: Vec<PatchCorner>,
        depth: f64,
        face: (bool, Vec3),
    ) -> FeaturePair {
        FeaturePair {
            patch: corners,
            patch_depth: depth,
            patch_face: Some(face),
            ..self.clone()
        }
    }

    /// Evaluate the contact geometry of this feature pair at the given poses.
    /// Generic in the scalar so that forward-mode dual numbers give exact
    /// derivatives of the distance, normal and contact points.
    pub fn evaluate<T: RealField>(&self, pa: &PoseT<T>, pb: &PoseT<T>) -> ContactGeometry<T> {
        let mut geo = self.evaluate_features(pa, pb);
        if !self.patch.is_empty() {
            let mut sum = Vector3::<T>::zeros();
            let mut total = T::zero();
            let mut weighted = Vec::with_capacity(self.patch.len());
            for corner in &self.patch {
                let (h, c) = corner.height(pa, pb);
                let w = corner_weight(h, self.patch_depth);
                sum += &c * w.clone();
                total += w.clone();
                weighted.push((w, c));
            }
            if let Some((on_a, normal)) = &self.patch_face {
                // The face's normal, pointing from b towards a.
                geo.normal = if *on_a {
                    -world_dir(pa, normal)
                } else {
                    world_dir(pb, normal)
                };
            }
            if total > T::zero() {
                let centroid = sum / total.clone();
                let mut spread = T::zero();
                for (w, c) in &weighted {
                    let d = c - &centroid;
                    let along = geo.normal.dot(&d);
                    spread += w.clone() * (d.norm_squared() - along.clone() * along);
                }
                let mean_square = spread / total;
                // Below (1 µm)² the patch is a point: no torsional lever, and
                // the square root's derivative would blow up at 0.
                if mean_square > convert(1e-12) {
                    geo.spin_radius = mean_square.sqrt();
                }
                geo.point_b = &centroid - &geo.normal * geo.distance.clone();
                geo.point_a = centroid;
            }
        }
        geo
    }

    /// [`FeaturePair::evaluate`] of the touching features alone.
    fn evaluate_features<T: RealField>(&self, pa: &PoseT<T>, pb: &PoseT<T>) -> ContactGeometry<T> {
        use SideFeature::*;
        match (&self.a, &self.b) {
            (Point { p, radius, .. }, Plane { normal, point, .. }) => {
                let c = world_point(pa, p);
                let n = world_dir(pb, normal);
                let q = world_point(pb, point);
                let rho: T = convert(*radius);
                let e = n.dot(&(&c - &q)) - rho.clone();
                let point_a = &c - &n * rho.clone();
                let point_b = &c - &n * (e.clone() + rho);
                ContactGeometry {
                    distance: e,
                    normal: n,
                    point_a,
                    point_b,
                    spin_radius: T::zero(),
                }
            }
            (Plane { normal, point, .. }, Point { p, radius, .. }) => {
                let c = world_point(pb, p);
                let m = world_dir(pa, normal);
                let q = world_point(pa, point);
                let rho: T = convert(*radius);
                let e = m.dot(&(&c - &q)) - rho.clone();
                let point_b = &c - &m * rho.clone();
                let point_a = &c - &m * (e.clone() + rho);
                ContactGeometry {
                    distance: e,
                    normal: -m,
                    point_a,
                    point_b,
                    spin_radius: T::zero(),
                }
            }
            (
                Point {
                    p: p1, radius: r1, ..
                },
                Point {
                    p: p2, radius: r2, ..
                },
            ) => {
                let ca = world_point(pa, p1);
                let cb = world_point(pb, p2);
                let d = &ca - &cb;
                let len = d.norm();
                let n = d / len.clone();
                let (ra, rb): (T, T) = (convert(*r1), convert(*r2));
                let point_a = &ca - &n * ra.clone();
                let point_b = &cb + &n * rb.clone();
                ContactGeometry {
                    distance: len - ra - rb,
                    normal: n,
                    point_a,
                    point_b,
                    spin_radius: T::zero(),
                }
            }
            (Point { p, radius, .. }, Line { point, dir, .. }) => {
                let c = world_point(pa, p);
                let q = world_point(pb, point);
                let d = world_dir(pb, dir);
                let foot = &q + &d * (d.dot(&(&c - &q)) / d.dot(&d));
                let w = &c - &foot;
                let len = w.norm();
                let n = w / len.clone();
                let rho: T = convert(*radius);
                let point_a = &c - &n * rho.clone();
                ContactGeometry {
                    distance: len - rho,
                    normal: n,
                    point_a,
                    point_b: foot,
                    spin_radius: T::zero(),
                }
            }
            (Line { point, dir, .. }, Point { p, radius, .. }) => {
                let c = world_point(pb, p);
                let q = world_point(pa, point);
                let d = world_dir(pa, dir);
                let foot = &q + &d * (d.dot(&(&c - &q)) / d.dot(&d));
                let w = &foot - &c;
                let len = w.norm();
                let n = w / len.clone();
                let rho: T = convert(*radius);
                let point_b = &c + &n * rho.clone();
                ContactGeometry {
                    distance: len - rho,
                    normal: n,
                    point_a: foot,
                    point_b,
                    spin_radius: T::zero(),
                }
            }
            (
                Line {
                    point: p1, dir: d1, ..
                },
                Line {
                    point: p2, dir: d2, ..
                },
            ) => {
                let qa = world_point(pa, p1);
                let da = world_dir(pa, d1);
                let qb = world_point(pb, p2);
                let db = world_dir(pb, d2);
                let m = da.cross(&db);
                let n = &m / (m.norm() * convert::<f64, T>(1.0 / self.sign));
                let r = &qa - &qb;
                let (a, b, c) = (da.dot(&da), da.dot(&db), db.dot(&db));
                let (d, e) = (da.dot(&r), db.dot(&r));
                let den = a.clone() * c.clone() - b.clone() * b.clone();
                let s = (b.clone() * e.clone() - c * d.clone()) / den.clone();
                let t = (a * e - b * d) / den;
                ContactGeometry {
                    distance: n.dot(&r),
                    normal: n,
                    point_a: &qa + &da * s,
                    point_b: &qb + &db * t,
                    spin_radius: T::zero(),
                }
            }
            (
                Point { p, radius, .. },
                Parabola {
                    frame,
                    curvature,
                    foot_hint,
                },
            ) => {
                // Parabola frame in world: pb ∘ frame.
                let fr = cv::<T>(&frame.translation.vector);
                let frot = frame
                    .rotation
                    .to_rotation_matrix()
                    .matrix()
                    .map(convert::<f64, T>);
                let origin = &pb.x + &pb.r * fr;
                let rot = &pb.r * frot;
                let c = world_point(pa, p);
                let local = rot.transpose() * (&c - &origin);
                let k: T = convert(*curvature);
                let two: T = convert(2.0);
                let one: T = convert(1.0);
                let (x, y, z) = (local.x.clone(), local.y.clone(), local.z.clone());
                let mut s: T = convert(*foot_hint);
                // Newton on the foot, from the hint (the converged foot at
                // classification). One step from a converged value already
                // carries the exact derivative (implicit function theorem),
                // so stop once the residual is at round-off.
                let tol: T =
                    convert(1e-15 * (1.0 + local.x.clone().abs().to_subset().unwrap_or(0.0)));
                for iteration in 0..8 {
                    let g = two.clone() * k.clone() * k.clone() * s.clone() * s.clone() * s.clone()
                        + (one.clone() + two.clone() * k.clone() * z.clone()) * s.clone()
                        - x.clone();
                    if iteration > 0 && g.clone().abs() <= tol {
                        break;
                    }
                    let dg = convert::<f64, T>(6.0) * k.clone() * k.clone() * s.clone() * s.clone()
                        + one.clone()
                        + two.clone() * k.clone() * z.clone();
                    s -= g / dg;
                }
                let foot = Vector3::new(s.clone(), y, -(k.clone() * s.clone() * s));
                let w = &local - &foot;
                let len = w.norm();
                let above = local.z.clone() + k * x.clone() * x >= T::zero();
                let sgn: T = convert(if above { 1.0 } else { -1.0 });
                let n_local = w / (len.clone() * sgn.clone());
                let n = &rot * n_local;
                let rho: T = convert(*radius);
                let foot_w = &origin + &rot * foot;
                ContactGeometry {
                    distance: len * sgn - rho.clone(),
                    point_a: &c - &n * rho,
                    normal: n,
                    point_b: foot_w,
                    spin_radius: T::zero(),
                }
            }
            // `classify` never produces the remaining combinations; fall back
            // to the points' separation so the result stays finite.
            (fa, fb) => {
                let ca = world_point(pa, &anchor(fa));
                let cb = world_point(pb, &anchor(fb));
                let d = &ca - &cb;
                let len = d.norm();
                let n = &d / len.clone();
                ContactGeometry {
                    distance: len,
                    normal: n,
                    point_a: ca,
                    point_b: cb,
                    spin_radius: T::zero(),
                }
            }
        }
    }
}

fn anchor(f: &SideFeature) -> Vec3 {
    match f {
        SideFeature::Point { p, .. } => *p,
        SideFeature::Plane { point, .. } | SideFeature::Line { point, .. } => *point,
        SideFeature::Parabola { frame, .. } => frame.translation.vector,
    }
}

#[cfg(test)]
mod tests;
