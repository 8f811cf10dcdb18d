//! Saving: a [`Scene`] as TOML text that loads back to the same scene bit
//! for bit.
//!
//! Floats are printed with Rust's shortest round-trip formatting (`{:?}`),
//! so every number parses back to the same `f64`. Three quantities are not
//! stored the way the file gives them and need care:
//! - rotations (obstacle poses, inertia axes) are quaternions made from
//!   exp-map vectors: the writer searches the few ulps around `log(q)` for a
//!   vector whose `exp` is exactly `q`;
//! - traced points are stored relative to the centre of mass but written in
//!   the shape's frame: the writer picks the shape-frame point whose
//!   difference with the centre of mass is exactly the stored one;
//! - the inertia is written only when the file gave it or when it differs
//!   from what the shape and mass imply (an edited mass), so a saved scene
//!   keeps `inertia_given` as it was whenever it can.
use super::inertia::{implied, unit_props};
use super::shape::{Owner, build};
use super::source::Source;
use crate::math::{Vec3, exp_so3, log_so3};
use crate::scene::model::{Body, Method, Obstacle, Scales, Scene};
use nalgebra::UnitQuaternion;
use std::fmt::Write as _;
use toml::de::DeTable;

/// Shapes whose inline form is longer than this are written as a sub-table.
const MAX_INLINE_SHAPE: usize = 100;

/// A float as TOML: shortest round-trip digits (`nan`/`inf` for non-finite
/// values, which then fail to load with a located message rather than
/// making the file unreadable).
pub(super) fn float(x: f64) -> String {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf".into() } else { "-inf".into() }
    } else {
        format!("{x:?}")
    }
}

fn vec3(v: &Vec3) -> String {
    format!("[{}, {}, {}]", float(v.x), float(v.y), float(v.z))
}

fn quoted(s: &str) -> String {
    toml::Value::String(s.to_string()).to_string()
}

fn key(k: &str) -> String {
    if !k.is_empty()
        && k.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
    {
        k.to_string()
    } else {
        quoted(k)
    }
}

/// The order shape keys are written in; other keys follow, sorted.
const KEY_ORDER: [&str; 14] = [
    "type",
    "shape",
    "position",
    "orientation",
    "radius",
    "half_extents",
    "radii",
    "bottom",
    "resolution",
    "points",
    "normal",
    "curvature",
    "half_width",
    "parts",
];

/// Keys of a table in writing order (see [`KEY_ORDER`]).
fn ordered(t: &toml::Table) -> Vec<&String> {
    let rank = |k: &str| {
        KEY_ORDER
            .iter()
            .position(|x| *x == k)
            .unwrap_or(KEY_ORDER.len())
    };
    let mut keys: Vec<&String> = t.keys().collect();
    keys.sort_by(|a, b| rank(a).cmp(&rank(b)).then_with(|| a.cmp(b)));
    keys
}

/// A value on one line.
pub(super) fn inline(v: &toml::Value) -> String {
    match v {
        toml::Value::String(s) => quoted(s),
        toml::Value::Integer(i) => i.to_string(),
        toml::Value::Float(f) => float(*f),
        toml::Value::Boolean(b) => b.to_string(),
        toml::Value::Datetime(d) => d.to_string(),
        toml::Value::Array(a) => {
            format!("[{}]", a.iter().map(inline).collect::<Vec<_>>().join(", "))
        }
        toml::Value::Table(t) if t.is_empty() => "{}".into(),
        toml::Value::Table(t) => {
            let fields: Vec<String> = ordered(t)
                .into_iter()
                .map(|k| format!("{} = {}", key(k), inline(&t[k.as_str()])))
                .collect();
            format!("{{ {} }}", fields.join(", "))
        }
    }
}

/// Whether two floats are the same bits.
fn same(a: f64, b: f64) -> bool {
    a.to_bits() == b.to_bits()
}

/// `x` moved by `k` ulps.
fn ulps(x: f64, k: i32) -> f64 {
    let mut y = x;
    for _ in 0..k.unsigned_abs() {
        y = if k > 0 { y.next_up() } else { y.next_down() };
    }
    y
}

/// An exp-map vector whose `exp_so3` is exactly `q` when one lies within a
/// few ulps of `log_so3(q)` (always the case for rotations that were loaded
/// from an exp-map vector); otherwise `log_so3(q)`, which is within an ulp.
pub(super) fn exp_map_of(q: &UnitQuaternion<f64>) -> Vec3 {
    const K: i32 = 3;
    let r0 = log_so3(q);
    let exact = |r: &Vec3| {
        exp_so3(r)
            .coords
            .iter()
            .zip(q.coords.iter())
            .all(|(a, b)| same(*a, *b))
    };
    if exact(&r0) {
        return r0;
    }
    let mut offsets = Vec::new();
    for a in -K..=K {
        for b in -K..=K {
            for c in -K..=K {
                offsets.push((a, b, c));
            }
        }
    }
    offsets.sort_by_key(|(a, b, c)| a.abs() + b.abs() + c.abs());
    offsets
        .into_iter()
        .map(|(a, b, c)| Vec3::new(ulps(r0.x, a), ulps(r0.y, b), ulps(r0.z, c)))
        .find(exact)
        .unwrap_or(r0)
}

/// A shape-frame coordinate `p` with `p - com == x` exactly, when one is
/// within a few ulps of `x + com`.
fn shape_coordinate(x: f64, com: f64) -> f64 {
    let p0 = x + com;
    (0..=8)
        .flat_map(|k| [k, -k])
        .map(|k| ulps(p0, k))
        .find(|p| same(p - com, x))
        .unwrap_or(p0)
}

/// What loading `shape_source` with this mass would give for the inertia.
fn implied_inertia(shape_source: &toml::Value, mass: f64) -> Option<(Vec3, UnitQuaternion<f64>)> {
    let text = format!("shape = {}", inline(shape_source));
    let doc = DeTable::parse(&text).ok()?;
    let src = Source {
        text: &text,
        origin: "<saved shape>",
    };
    let v = doc.get_ref().get("shape")?;
    let g = build(&src, v, "body", "shape", Owner::Body, 1).ok()?;
    let unit = unit_props(&g).ok()?;
    Some(implied(&unit, mass))
}

fn same_inertia(a: &(Vec3, UnitQuaternion<f64>), b: &Body) -> bool {
    a.0.iter().zip(b.inertia.iter()).all(|(x, y)| same(*x, *y))
        && a.1
            .coords
            .iter()
            .zip(b.inertia_axes.coords.iter())
            .all(|(x, y)| same(*x, *y))
}

/// Write `shape` inline when short, else return the lines of a sub-table.
fn shape_lines(out: &mut String, shape: &toml::Value) -> Option<String> {
    let one_line = inline(shape);
    if one_line.len() <= MAX_INLINE_SHAPE || !shape.is_table() {
        let _ = writeln!(out, "shape = {one_line}");
        return None;
    }
    let mut sub = String::new();
    if let toml::Value::Table(t) = shape {
        for k in ordered(t) {
            match &t[k.as_str()] {
                toml::Value::Array(items)
                    if items.iter().all(toml::Value::is_table) && !items.is_empty() =>
                {
                    let _ = writeln!(sub, "{} = [", key(k));
                    for item in items {
                        let _ = writeln!(sub, "    {},", inline(item));
                    }
                    let _ = writeln!(sub, "]");
                }
                v => {
                    let _ = writeln!(sub, "{} = {}", key(k), inline(v));
                }
            }
        }
    }
    Some(sub)
}

fn write_body(out: &mut String, b: &Body) {
    let _ = writeln!(out, "\n[[body]]");
    let _ = writeln!(out, "name = {}", quoted(&b.name));
    let sub = shape_lines(out, &b.shape_source);
    let _ = writeln!(out, "mass = {}", float(b.mass));
    let derived = (!b.inertia_given)
        .then(|| implied_inertia(&b.shape_source, b.mass))
        .flatten();
    if !derived.is_some_and(|d| same_inertia(&d, b)) {
        let _ = writeln!(out, "inertia = {}", vec3(&b.inertia));
        let _ = writeln!(out, "inertia_axes = {}", vec3(&exp_map_of(&b.inertia_axes)));
    }
    let _ = writeln!(out, "position = {}", vec3(&b.position));
    let _ = writeln!(out, "orientation = {}", vec3(&b.orientation));
    let _ = writeln!(out, "velocity = {}", vec3(&b.velocity));
    let _ = writeln!(out, "angular_velocity = {}", vec3(&b.angular_velocity));
    let _ = writeln!(out, "restitution = {}", float(b.restitution));
    let _ = writeln!(out, "friction = {}", float(b.friction));
    let _ = writeln!(out, "drag = {}", float(b.drag));
    let default_trace = b.traced.len() == 1 && b.traced[0].iter().all(|x| x.to_bits() == 0);
    if !default_trace {
        let points: Vec<String> = b
            .traced
            .iter()
            .map(|p| {
                vec3(&Vec3::from_fn(|i, _| {
                    shape_coordinate(p[i], b.com_offset[i])
                }))
            })
            .collect();
        let _ = writeln!(out, "trace = [{}]", points.join(", "));
    }
    let free: Vec<String> = b.free.iter().map(|f| quoted(f.name())).collect();
    let _ = writeln!(out, "free = [{}]", free.join(", "));
    if let Some(sub) = sub {
        let _ = write!(out, "\n[body.shape]\n{sub}");
    }
}

fn write_obstacle(out: &mut String, o: &Obstacle) {
    let _ = writeln!(out, "\n[[obstacle]]");
    let _ = writeln!(out, "name = {}", quoted(&o.name));
    let sub = shape_lines(out, &o.shape_source);
    let _ = writeln!(out, "position = {}", vec3(&o.pose.translation.vector));
    let _ = writeln!(out, "orientation = {}", vec3(&exp_map_of(&o.pose.rotation)));
    let _ = writeln!(out, "restitution = {}", float(o.restitution));
    let _ = writeln!(out, "friction = {}", float(o.friction));
    if let Some(sub) = sub {
        let _ = write!(out, "\n[obstacle.shape]\n{sub}");
    }
}

/// The scene as TOML text.
pub(super) fn to_toml(scene: &Scene) -> String {
    let mut out = String::new();
    let _ = writeln!(out, "# nudge scene (format: docs/scene-format.md)");
    let _ = writeln!(out, "name = {}", quoted(&scene.name));
    if !scene.notes.is_empty() {
        let _ = writeln!(out, "notes = {}", quoted(&scene.notes));
    }
    let _ = writeln!(out, "duration = {}", float(scene.duration));
    let _ = writeln!(out, "gravity = {}", vec3(&scene.gravity));
    let effects: Vec<String> = scene
        .effects
        .listed()
        .iter()
        .map(|e| quoted(e.name()))
        .collect();
    let _ = writeln!(out, "effects = [{}]", effects.join(", "));
    let _ = writeln!(out, "rest_speed = {}", float(scene.rest_speed));

    let _ = writeln!(out, "\n[accuracy]");
    match scene.accuracy.method {
        Method::Rk4 { step } => {
            let _ = writeln!(out, "method = \"rk4\"\nstep = {}", float(step));
        }
        Method::Adaptive { tol, max_step } => {
            let _ = writeln!(
                out,
                "method = \"adaptive\"\ntol = {}\nmax_step = {}",
                float(tol),
                float(max_step)
            );
        }
    }
    let _ = writeln!(out, "root_tol = {}", float(scene.accuracy.root_tol));

    if scene.scales != Scales::default() {
        let s = &scene.scales;
        let _ = writeln!(out, "\n[scales]");
        for (k, v) in [
            ("position", s.position),
            ("orientation", s.orientation),
            ("velocity", s.velocity),
            ("angular_velocity", s.angular_velocity),
            ("mass", s.mass),
            ("inertia", s.inertia),
            ("normal", s.normal),
            ("restitution", s.restitution),
        ] {
            let _ = writeln!(out, "{k} = {}", float(v));
        }
    }

    for b in &scene.bodies {
        write_body(&mut out, b);
    }
    for o in &scene.obstacles {
        write_obstacle(&mut out, o);
    }

    let pairs: Vec<String> = scene
        .pairs
        .iter()
        .filter_map(|&[i, j]| {
            Some(format!(
                "[{}, {}]",
                quoted(&scene.bodies.get(i)?.name),
                quoted(&scene.bodies.get(j)?.name)
            ))
        })
        .collect();
    if !pairs.is_empty() {
        let _ = writeln!(out, "\n[collisions]\npairs = [{}]", pairs.join(", "));
    }

    for c in &scene.event_controls {
        let _ = writeln!(out, "\n[[event_control]]\nevent = {}", c.event);
        if let Some([a, b]) = c.normal {
            let _ = writeln!(out, "normal = [{}, {}]", float(a), float(b));
        }
        if let Some(e) = c.restitution {
            let _ = writeln!(out, "restitution = {}", float(e));
        }
        if c.fixed {
            let _ = writeln!(out, "fixed = true");
        }
    }

    for c in &scene.constraints {
        let _ = writeln!(out, "\n[[constraint]]");
        if let Ok(toml::Value::Table(t)) = toml::Value::try_from(c) {
            for k in [
                "kind",
                "body",
                "other",
                "time",
                "collision",
                "side",
                "quantities",
                "target",
            ] {
                if let Some(v) = t.get(k) {
                    let _ = writeln!(out, "{k} = {}", inline(v));
                }
            }
        }
    }
    out
}
