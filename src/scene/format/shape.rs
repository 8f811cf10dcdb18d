//! `shape = { type = ... }` tables: reading, checking and building the
//! [`Geometry`] they describe.
use super::SceneError;
use super::source::{Bound, Source, Table, Value, as_table, suggestion, vec3};
use crate::geometry::Geometry;
use crate::math::{Vec3, exp_so3, reparameterize};
use nalgebra::{Isometry3, Translation3};

/// Largest curvature of a parabola obstacle, 1/m (a hill whose top has a
/// radius of curvature of 0.5 µm): the closest-point search on steeper
/// ones squares numbers beyond the finite range.
const MAX_CURVATURE: f64 = 1e6;

/// Deepest allowed nesting of `compound` shapes (a top-level compound is 1).
pub(super) const MAX_NESTING: usize = 8;

/// Shape types a body may have (bounded ones).
pub(super) const BODY_TYPES: [&str; 7] = [
    "sphere",
    "box",
    "ellipsoid",
    "egg",
    "hull",
    "mesh",
    "compound",
];
/// Shape types an obstacle may have.
pub(super) const OBSTACLE_TYPES: [&str; 9] = [
    "sphere",
    "box",
    "ellipsoid",
    "egg",
    "hull",
    "mesh",
    "compound",
    "plane",
    "parabola",
];

/// Default number of latitude rings of ellipsoids and eggs.
pub(super) const DEFAULT_RESOLUTION: u64 = 8;
/// Default vertical scale of an egg's lower half.
pub(super) const DEFAULT_EGG_BOTTOM: f64 = 1.3;

/// Who owns a shape: bodies need a finite volume.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Owner {
    Body,
    Obstacle,
}

/// Turn an exp-map vector into an equivalent one with `|r| ≤ π`
/// (Grassia's reparameterisation, repeated; very long vectors are first
/// reduced modulo 2π so this takes at most a few steps).
pub(super) fn short_rotation(r: Vec3) -> Vec3 {
    use std::f64::consts::{PI, TAU};
    let mut r = r;
    let angle = robust_norm(&r);
    if angle > 3.0 * PI {
        // Scale the unit direction, not `r`, so huge vectors do not overflow.
        let reduced = angle.rem_euclid(TAU);
        r = (r / angle) * reduced;
    }
    for _ in 0..4 {
        let (next, changed) = reparameterize(&r);
        r = next;
        if !changed {
            break;
        }
    }
    r
}

/// `|v|` without overflow for huge components (`Vector::norm` squares them).
pub(super) fn robust_norm(v: &Vec3) -> f64 {
    let m = v.amax();
    if m == 0.0 || !m.is_finite() {
        m
    } else {
        m * (v / m).norm()
    }
}

/// Longest exp-map vector accepted, rad (longer ones are surely mistakes,
/// and near `f64::MAX` their length overflows).
pub(super) const MAX_ROTATION: f64 = 1e6;

/// The exp-map vector `key` of table `t` (zero when absent), shortened to
/// `|r| ≤ π`.
pub(super) fn rotation(t: &Table<'_, '_>, key: &str, hint: &str) -> Result<Vec3, SceneError> {
    let r = t.vec3_or(key, Vec3::zeros(), hint)?;
    if robust_norm(&r) > MAX_ROTATION {
        return Err(t.bad(key, &format!("is longer than {MAX_ROTATION:e} rad"), hint));
    }
    Ok(short_rotation(r))
}

/// A pose from a position and an exp-map orientation (rad).
pub(super) fn pose(position: Vec3, orientation: Vec3) -> Isometry3<f64> {
    Isometry3::from_parts(Translation3::from(position), exp_so3(&orientation))
}

/// Build the shape described by the table `v`, which messages call
/// `{owner} field {path}` (`path` without a trailing dot, e.g. `shape`).
/// `depth` counts enclosing compounds plus one.
pub(super) fn build(
    src: &Source<'_>,
    v: &Value<'_>,
    owner: &str,
    path: &str,
    kind: Owner,
    depth: usize,
) -> Result<Geometry, SceneError> {
    let types: &[&str] = match kind {
        Owner::Body => &BODY_TYPES,
        Owner::Obstacle => &OBSTACLE_TYPES,
    };
    let Some(map) = as_table(v) else {
        return Err(src.error_at(
            &v.span(),
            &format!("{owner} field {path} must be a table"),
            "write it as { type = \"sphere\", radius = 0.1 } (see docs/scene-format.md)",
        ));
    };
    let prefix = format!("{path}.");
    let t = Table {
        src,
        map,
        span: v.span(),
        owner,
        path: &prefix,
    };
    let type_hint = format!("add type = \"<type>\" with one of {}", types.join(", "));
    let Some(ty) = t.string("type", &type_hint)? else {
        return Err(t.missing("type", &type_hint));
    };
    if kind == Owner::Body && (ty == "plane" || ty == "parabola") {
        return Err(t.bad(
            "type",
            "is a shape without a finite volume",
            &format!(
                "a body needs one of {}: make the {ty} an [[obstacle]]",
                BODY_TYPES.join(", ")
            ),
        ));
    }
    let positive3 = |key: &str, hint: &str| -> Result<Vec3, SceneError> {
        let v = t.vec3(key, hint)?.ok_or_else(|| t.missing(key, hint))?;
        if v.iter().all(|x| *x > 0.0) {
            Ok(v)
        } else {
            Err(t.bad(key, "must have all three entries greater than 0", hint))
        }
    };
    let resolution = || -> Result<u32, SceneError> {
        let hint = "give resolution as a whole number from 3 to 64 (default 8)";
        let r = t.index("resolution", hint)?.unwrap_or(DEFAULT_RESOLUTION);
        match u32::try_from(r) {
            Ok(r) if (3..=64).contains(&r) => Ok(r),
            _ => Err(t.bad("resolution", "must be from 3 to 64", hint)),
        }
    };
    let built = match ty {
        "sphere" => {
            t.allow_only(&["type", "radius"])?;
            let r = t.required(
                "radius",
                Bound::Positive,
                "give the radius in m, e.g. radius = 0.1",
            )?;
            Geometry::sphere(r)
        }
        "box" => {
            t.allow_only(&["type", "half_extents"])?;
            let h = positive3(
                "half_extents",
                "give the half extents in m as [x, y, z], e.g. half_extents = [0.3, 0.2, 0.1]",
            )?;
            Geometry::cuboid(h)
        }
        "ellipsoid" => {
            t.allow_only(&["type", "radii", "resolution"])?;
            let radii = positive3(
                "radii",
                "give the radii in m as [x, y, z], e.g. radii = [0.05, 0.05, 0.07]",
            )?;
            Geometry::ellipsoid(radii, resolution()?, 1.0)
        }
        "egg" => {
            t.allow_only(&["type", "radii", "bottom", "resolution"])?;
            let radii = positive3(
                "radii",
                "give the radii in m as [x, y, z], e.g. radii = [0.05, 0.05, 0.07]",
            )?;
            let bottom = t.number_or(
                "bottom",
                DEFAULT_EGG_BOTTOM,
                Bound::Positive,
                "give the vertical scale of the lower half, e.g. bottom = 1.3 (1 makes an ellipsoid)",
            )?;
            Geometry::ellipsoid(radii, resolution()?, bottom)
        }
        "hull" => {
            t.allow_only(&["type", "points"])?;
            let hint = "give at least 4 points [x, y, z] in m that are not all on one plane";
            let list = t
                .array("points", hint)?
                .ok_or_else(|| t.missing("points", hint))?;
            let mut points = Vec::with_capacity(list.len());
            for (k, p) in list.iter().enumerate() {
                points.push(vec3(src, p, &t.field(&format!("points[{k}]")), hint)?);
            }
            Ok(Geometry::convex_hull(&points)
                .map_err(|_| t.bad("points", "does not enclose a volume", hint))?)
        }
        "mesh" => return super::mesh::build(&t),
        "compound" => {
            if depth > MAX_NESTING {
                return Err(t.bad(
                    "type",
                    &format!("is a compound nested {depth} deep"),
                    &format!("compounds may nest at most {MAX_NESTING} deep: move the inner parts into an outer compound"),
                ));
            }
            t.allow_only(&["type", "parts"])?;
            let hint = "give parts = [{ shape = { ... }, position = [x, y, z], orientation = [rx, ry, rz] }, ...]";
            let list = t
                .array("parts", hint)?
                .ok_or_else(|| t.missing("parts", hint))?;
            if list.is_empty() {
                return Err(t.bad("parts", "is empty", hint));
            }
            let mut parts = Vec::with_capacity(list.len());
            for (k, part) in list.iter().enumerate() {
                let part_path = format!("{prefix}parts[{k}]");
                let Some(map) = as_table(part) else {
                    return Err(src.error_at(
                        &part.span(),
                        &format!("{owner} field {part_path} must be a table"),
                        hint,
                    ));
                };
                let part_prefix = format!("{part_path}.");
                let p = Table {
                    src,
                    map,
                    span: part.span(),
                    owner,
                    path: &part_prefix,
                };
                p.allow_only(&["shape", "position", "orientation"])?;
                let shape = p.get("shape").ok_or_else(|| p.missing("shape", hint))?;
                let g = build(
                    src,
                    shape,
                    owner,
                    &format!("{part_prefix}shape"),
                    kind,
                    depth + 1,
                )?;
                let position = p.vec3_or(
                    "position",
                    Vec3::zeros(),
                    "give the part's position in the compound's frame in m, e.g. [0, 0, 0.1]",
                )?;
                let orientation = rotation(
                    &p,
                    "orientation",
                    "give the part's orientation as an exp-map vector in rad, e.g. [0, 0, 0.5]",
                )?;
                parts.push((pose(position, orientation), g));
            }
            Geometry::compound(parts)
        }
        "plane" => {
            t.allow_only(&["type", "normal"])?;
            let hint = "give the outward normal as [x, y, z], e.g. normal = [0, 0, 1]";
            let n = t
                .vec3("normal", hint)?
                .ok_or_else(|| t.missing("normal", hint))?;
            if robust_norm(&n) <= 1e-12 {
                return Err(t.bad("normal", "must not be the zero vector", hint));
            }
            // Only the direction matters: scale it first so huge entries do not overflow.
            Geometry::half_space(n / n.amax())
        }
        "parabola" => {
            t.allow_only(&["type", "curvature", "half_width"])?;
            let k = t.required("curvature", Bound::PositiveAtMost(MAX_CURVATURE), "give the curvature in 1/m (the surface is z = -curvature x^2), e.g. curvature = 1.0")?;
            let w = t.required(
                "half_width",
                Bound::Positive,
                "give the drawn half width in m, e.g. half_width = 1.5",
            )?;
            if !(k * w * w).is_finite() {
                return Err(t.bad(
                    "half_width",
                    "makes the drawn hill deeper than the finite numbers",
                    "give a drawn half width in m such as 1.5",
                ));
            }
            Geometry::parabola(k, w)
        }
        other => {
            return Err(t.bad(
                "type",
                "is not a known shape type",
                &format!(
                    "{}use one of {}",
                    suggestion(other, types),
                    types.join(", ")
                ),
            ));
        }
    };
    built.map_err(|e| match ty {
        // Their only failure is a hull too thin for the volume test:
        // dimensions spanning many orders of magnitude, or overflowing.
        "box" | "ellipsoid" | "egg" => src.error_at(
            &v.span(),
            &format!("{owner} field {path} is too elongated, too large or too small to build"),
            "keep its dimensions in m within a factor of 1e6 of each other and below 1e100",
        ),
        _ => src.error_at(
            &v.span(),
            &format!("{owner} field {path} cannot be built"),
            &e.to_string(),
        ),
    })
}
