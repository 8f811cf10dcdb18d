//! `[[body]]` and `[[obstacle]]` tables.
use super::SceneError;
use super::inertia::{implied, triangle_ok, unit_props};
use super::shape::{Owner, build, pose, rotation};
use super::source::{Bound, Source, Table, Value, as_table, plain, vec3};
use crate::math::{Vec3, exp_so3};
use crate::scene::model::{Body, Obstacle};
use std::ops::Range;

/// The fields a `[[body]]` table may have.
pub(super) const BODY_FIELDS: [&str; 15] = [
    "name",
    "shape",
    "density",
    "mass",
    "inertia",
    "inertia_axes",
    "position",
    "orientation",
    "velocity",
    "angular_velocity",
    "restitution",
    "friction",
    "drag",
    "trace",
    "free",
];

/// The fields an `[[obstacle]]` table may have.
pub(super) const OBSTACLE_FIELDS: [&str; 6] = [
    "name",
    "shape",
    "position",
    "orientation",
    "restitution",
    "friction",
];

/// Default restitution of bodies and obstacles.
pub(super) const DEFAULT_RESTITUTION: f64 = 1.0;
/// Default Coulomb friction coefficient of bodies and obstacles.
pub(super) const DEFAULT_FRICTION: f64 = 0.5;

const SHAPE_HINT: &str = "add shape = { type = \"sphere\", radius = 0.1 } (see docs/scene-format.md for the shape types)";
const RESTITUTION_HINT: &str =
    "give the coefficient of restitution from 0 (no bounce) to 1 (elastic), e.g. restitution = 0.8";
const FRICTION_HINT: &str =
    "give the Coulomb friction coefficient, 0 or greater, e.g. friction = 0.5";
const ORIENTATION_HINT: &str =
    "give the orientation as an exp-map vector [rx, ry, rz] in rad, e.g. [0, 0, 0.5]";

/// Where a body or obstacle was written, for the cross-checks made later.
pub(super) struct Spans {
    /// The `name` value.
    pub name: Range<usize>,
    /// The `position` value (the table when absent).
    pub position: Range<usize>,
}

/// Read the `name` of the `index`-th (0-based) table of `kind` (`body`, `obstacle`).
fn name<'a>(t: &Table<'a, '_>, kind: &str) -> Result<&'a str, SceneError> {
    let hint =
        format!("give the {kind} a unique name without dots or spaces, e.g. name = \"{kind}1\"");
    let name = t
        .string("name", &hint)?
        .ok_or_else(|| t.missing("name", &hint))?;
    if name.is_empty() {
        return Err(t.bad("name", "is empty", &hint));
    }
    if name.contains(|c: char| c == '.' || c.is_whitespace() || c.is_control()) {
        let fixed: String = name
            .chars()
            .map(|c| {
                if c == '.' || c.is_whitespace() || c.is_control() {
                    '_'
                } else {
                    c
                }
            })
            .collect();
        return Err(t.bad(
            "name",
            "contains a dot or a space",
            &format!("names are used in control names like {fixed}.position: write \"{fixed}\""),
        ));
    }
    Ok(name)
}

/// The located table of the `index`-th element of `[[kind]]`.
fn table_of<'a, 'i>(
    src: &'a Source<'a>,
    v: &'a Value<'i>,
    owner: &'a str,
    kind: &str,
) -> Result<Table<'a, 'i>, SceneError> {
    let map = as_table(v).ok_or_else(|| {
        src.error_at(
            &v.span(),
            &format!("{owner} must be a table"),
            &format!("write each {kind} as a [[{kind}]] table"),
        )
    })?;
    Ok(Table {
        src,
        map,
        span: v.span(),
        owner,
        path: "",
    })
}

/// Read and validate the `index`-th (0-based) `[[body]]` table.
pub(super) fn body(
    src: &Source<'_>,
    v: &Value<'_>,
    index: usize,
) -> Result<(Body, Spans), SceneError> {
    let numbered = format!("body #{}", index + 1);
    let t = table_of(src, v, &numbered, "body")?;
    let name = name(&t, "body")?;
    let owner = format!("body {name:?}");
    let t = Table { owner: &owner, ..t };
    t.allow_only(&BODY_FIELDS)?;

    let shape = t
        .get("shape")
        .ok_or_else(|| t.missing("shape", SHAPE_HINT))?;
    let shape_geometry = build(src, shape, &owner, "shape", Owner::Body, 1)?;
    let size_hint = "give the shape a size in m that is neither tiny nor astronomically large";
    let unit = unit_props(&shape_geometry)
        .ok()
        .filter(|u| u.mass > 0.0 && u.mass.is_finite())
        .ok_or_else(|| {
            t.bad(
                "shape",
                "has a volume of zero or too large to compute",
                size_hint,
            )
        })?;
    if !(unit
        .com
        .iter()
        .chain(unit.inertia.iter())
        .all(|x| x.is_finite()))
    {
        return Err(t.bad("shape", "has an inertia too large to compute", size_hint));
    }

    let density_hint =
        "give the density in kg/m^3, e.g. density = 1000.0 (water), or give mass instead";
    let mass_hint = "give the mass in kg, e.g. mass = 0.5, or give density instead";
    let density = t.bounded("density", Bound::Positive, density_hint)?;
    let given_mass = t.bounded("mass", Bound::Positive, mass_hint)?;
    let mass = match (density, given_mass) {
        (Some(_), Some(_)) => {
            return Err(t.bad(
                "mass",
                "is given together with density",
                "give only one of density (kg/m^3) or mass (kg)",
            ));
        }
        (None, None) => {
            return Err(src.error_bare(
                &t.span,
                &format!("{owner} has neither density nor mass"),
                "add density = 1000.0 (kg/m^3) or mass = 0.5 (kg)",
            ));
        }
        (Some(d), None) => d * unit.mass,
        (None, Some(m)) => m,
    };
    if !(mass.is_finite() && mass > 0.0) {
        return Err(t.bad(
            "density",
            "gives a mass that is not a positive finite number",
            density_hint,
        ));
    }

    let inertia_hint = "give the principal moments [I1, I2, I3] in kg m^2, or leave inertia out to compute it from the shape";
    let axes_hint = "give the principal axes as an exp-map vector [rx, ry, rz] in rad, or leave it out for the body axes";
    let (inertia, inertia_axes, inertia_given) = match t.vec3("inertia", inertia_hint)? {
        Some(m) => {
            if !m.iter().all(|x| *x > 0.0) {
                return Err(t.bad(
                    "inertia",
                    "must have all three moments greater than 0",
                    inertia_hint,
                ));
            }
            if !triangle_ok(&m) {
                return Err(t.bad(
                    "inertia",
                    "violates the triangle inequality (each moment must be at most the sum of the other two)",
                    "no rigid body has these moments: fix them, or leave inertia out to compute it from the shape",
                ));
            }
            let axes = rotation(&t, "inertia_axes", axes_hint)?;
            (m, exp_so3(&axes), true)
        }
        None => {
            if t.get("inertia_axes").is_some() {
                return Err(t.bad(
                    "inertia_axes",
                    "is given without inertia",
                    "add inertia = [I1, I2, I3] or remove inertia_axes",
                ));
            }
            let (m, axes) = implied(&unit, mass);
            (m, axes, false)
        }
    };
    if !inertia.iter().all(|x| x.is_finite()) {
        let key = if given_mass.is_some() {
            "mass"
        } else {
            "density"
        };
        return Err(t.bad(
            key,
            "makes the inertia too large to compute",
            "give a realistic mass or density for the shape's size",
        ));
    }
    let com = unit.com;

    let position = t.vec3_or(
        "position",
        Vec3::zeros(),
        "give the initial centre-of-mass position [x, y, z] in m",
    )?;
    let orientation = rotation(&t, "orientation", ORIENTATION_HINT)?;
    let velocity = t.vec3_or(
        "velocity",
        Vec3::zeros(),
        "give the initial velocity [vx, vy, vz] in m/s",
    )?;
    let angular_velocity = t.vec3_or(
        "angular_velocity",
        Vec3::zeros(),
        "give the initial angular velocity [wx, wy, wz] in rad/s (world frame)",
    )?;
    let restitution = t.number_or(
        "restitution",
        DEFAULT_RESTITUTION,
        Bound::Unit,
        RESTITUTION_HINT,
    )?;
    let friction = t.number_or(
        "friction",
        DEFAULT_FRICTION,
        Bound::NonNegative,
        FRICTION_HINT,
    )?;
    let drag = t.number_or(
        "drag",
        0.0,
        Bound::NonNegative,
        "give the linear drag coefficient in kg/s, 0 or greater, e.g. drag = 0.1",
    )?;

    let trace_hint =
        "give body points [x, y, z] in m in the shape's frame, e.g. trace = [[0, 0, 0.07]]";
    let traced = match t.array("trace", trace_hint)? {
        None => vec![Vec3::zeros()],
        Some(list) => {
            let mut pts = Vec::with_capacity(list.len());
            for (k, p) in list.iter().enumerate() {
                pts.push(vec3(src, p, &t.field(&format!("trace[{k}]")), trace_hint)? - com);
            }
            pts
        }
    };
    let free = t.blocks("free")?;

    let spans = Spans {
        name: t.span_of("name"),
        position: t.span_of("position"),
    };
    let body = Body {
        name: name.to_string(),
        geometry: shape_geometry.recentered(&com),
        shape_source: plain(shape.get_ref()),
        com_offset: com,
        mass,
        inertia,
        inertia_axes,
        inertia_given,
        position,
        orientation,
        velocity,
        angular_velocity,
        restitution,
        friction,
        drag,
        traced,
        free,
    };
    Ok((body, spans))
}

/// Read and validate the `index`-th (0-based) `[[obstacle]]` table.
pub(super) fn obstacle(
    src: &Source<'_>,
    v: &Value<'_>,
    index: usize,
) -> Result<(Obstacle, Spans), SceneError> {
    let numbered = format!("obstacle #{}", index + 1);
    let t = table_of(src, v, &numbered, "obstacle")?;
    let name = name(&t, "obstacle")?;
    let owner = format!("obstacle {name:?}");
    let t = Table { owner: &owner, ..t };
    t.allow_only(&OBSTACLE_FIELDS)?;
    let shape = t
        .get("shape")
        .ok_or_else(|| t.missing("shape", SHAPE_HINT))?;
    let geometry = build(src, shape, &owner, "shape", Owner::Obstacle, 1)?;
    let position = t.vec3_or(
        "position",
        Vec3::zeros(),
        "give the obstacle frame's position [x, y, z] in m",
    )?;
    let orientation = rotation(&t, "orientation", ORIENTATION_HINT)?;
    let restitution = t.number_or(
        "restitution",
        DEFAULT_RESTITUTION,
        Bound::Unit,
        RESTITUTION_HINT,
    )?;
    let friction = t.number_or(
        "friction",
        DEFAULT_FRICTION,
        Bound::NonNegative,
        FRICTION_HINT,
    )?;
    let spans = Spans {
        name: t.span_of("name"),
        position: t.span_of("position"),
    };
    let obstacle = Obstacle {
        name: name.to_string(),
        geometry,
        shape_source: plain(shape.get_ref()),
        pose: pose(position, orientation),
        restitution,
        friction,
    };
    Ok((obstacle, spans))
}
