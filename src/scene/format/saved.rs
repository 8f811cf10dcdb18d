//! What saving writes: a [`Scene`] as an ordered list of TOML tables of
//! plain values ([`sections`]). Both writers take their content from here
//! and differ only in how they write it: [`super::write`] prints it as new
//! text, [`super::in_place`] edits the text the scene was loaded from.
//!
//! Every number is the model's own `f64`, so a writer that prints floats in
//! shortest round-trip form gives text that loads back bit for bit. Three
//! quantities are not stored the way the file gives them and need care:
//! - rotations (obstacle poses, inertia axes) are quaternions made from
//!   exp-map vectors: [`exp_map_of`] searches the few ulps around `log(q)`
//!   for a vector whose `exp` is exactly `q`;
//! - traced points are stored relative to the centre of mass but written in
//!   the shape's frame: the saved point is the shape-frame point whose
//!   difference with the centre of mass is exactly the stored one;
//! - the inertia is saved only when the file gave it or when it differs
//!   from what the shape and mass imply (an edited mass), so a saved scene
//!   keeps `inertia_given` as it was whenever it can. `mass` is always saved.
use super::constraint::CONSTRAINT_FIELDS;
use super::inertia::{implied, unit_props};
use super::shape::{Owner, build};
use super::source::Source;
use super::write::inline;
use crate::math::{Vec3, exp_so3, log_so3};
use crate::scene::model::{Body, Method, Obstacle, Scales, Scene};
use nalgebra::UnitQuaternion;
use toml::Value;
use toml::de::DeTable;

/// One table of the saved document.
#[derive(Debug, Clone)]
pub(super) struct Section {
    /// The table's name; `""` for the top level.
    pub name: &'static str,
    /// An element of an array of tables (`[[name]]`) rather than `[name]`.
    pub array: bool,
    /// The keys in writing order and their values.
    pub fields: Vec<(&'static str, Value)>,
}

impl Section {
    fn new(name: &'static str, array: bool) -> Section {
        Section {
            name,
            array,
            fields: Vec::new(),
        }
    }

    fn put(&mut self, key: &'static str, value: Value) {
        self.fields.push((key, value));
    }

    /// The value saved under `key`, if any.
    pub fn get(&self, key: &str) -> Option<&Value> {
        self.fields.iter().find(|(k, _)| *k == key).map(|(_, v)| v)
    }
}

/// The field that tells the elements of an array of tables apart (a body's
/// name, an event control's event), when there is one.
pub(super) fn identity(table: &str) -> Option<&'static str> {
    match table {
        "body" | "obstacle" => Some("name"),
        "event_control" => Some("event"),
        _ => None,
    }
}

/// Whether two saved values are the same, floats compared bit for bit.
pub(super) fn same_value(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Float(x), Value::Float(y)) => x.to_bits() == y.to_bits(),
        (Value::Array(x), Value::Array(y)) => {
            x.len() == y.len() && x.iter().zip(y).all(|(p, q)| same_value(p, q))
        }
        (Value::Table(x), Value::Table(y)) => {
            x.len() == y.len()
                && x.iter()
                    .zip(y)
                    .all(|((kx, vx), (ky, vy))| kx == ky && same_value(vx, vy))
        }
        _ => a == b,
    }
}

/// Whether two lists of fields are the same, in the same order.
pub(super) fn same_fields(a: &[(&str, Value)], b: &[(&str, Value)]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|((ka, va), (kb, vb))| ka == kb && same_value(va, vb))
}

/// Whether two saved documents are the same.
pub(super) fn same_sections(a: &[Section], b: &[Section]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| {
            x.name == y.name && x.array == y.array && same_fields(&x.fields, &y.fields)
        })
}

fn float(x: f64) -> Value {
    Value::Float(x)
}

fn vec3(v: &Vec3) -> Value {
    Value::Array(v.iter().copied().map(float).collect())
}

fn string(s: &str) -> Value {
    Value::String(s.to_string())
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
fn implied_inertia(shape_source: &Value, mass: f64) -> Option<(Vec3, UnitQuaternion<f64>)> {
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

/// Whether a shape (or a part of it, however deep) is a mesh file.
fn names_a_mesh(shape: &Value) -> bool {
    match shape {
        Value::Table(t) => {
            t.get("type").and_then(Value::as_str) == Some("mesh") || t.values().any(names_a_mesh)
        }
        Value::Array(a) => a.iter().any(names_a_mesh),
        _ => false,
    }
}

fn same_inertia(a: &(Vec3, UnitQuaternion<f64>), b: &Body) -> bool {
    a.0.iter().zip(b.inertia.iter()).all(|(x, y)| same(*x, *y))
        && a.1
            .coords
            .iter()
            .zip(b.inertia_axes.coords.iter())
            .all(|(x, y)| same(*x, *y))
}

fn body(b: &Body) -> Section {
    let mut s = Section::new("body", true);
    s.put("name", string(&b.name));
    s.put("shape", b.shape_source.clone());
    s.put("mass", float(b.mass));
    let derived = (!b.inertia_given)
        .then(|| {
            if names_a_mesh(&b.shape_source) {
                // A mesh file is named relative to the scene file, which
                // this text has no folder for: the body's geometry was
                // built from it (recentring keeps its unit inertia).
                unit_props(&b.geometry).ok().map(|u| implied(&u, b.mass))
            } else {
                implied_inertia(&b.shape_source, b.mass)
            }
        })
        .flatten();
    if !derived.is_some_and(|d| same_inertia(&d, b)) {
        s.put("inertia", vec3(&b.inertia));
        s.put("inertia_axes", vec3(&exp_map_of(&b.inertia_axes)));
    }
    s.put("position", vec3(&b.position));
    s.put("orientation", vec3(&b.orientation));
    s.put("velocity", vec3(&b.velocity));
    s.put("angular_velocity", vec3(&b.angular_velocity));
    s.put("restitution", float(b.restitution));
    s.put("friction", float(b.friction));
    s.put("drag", float(b.drag));
    let default_trace = b.traced.len() == 1 && b.traced[0].iter().all(|x| x.to_bits() == 0);
    if !default_trace {
        let points = b
            .traced
            .iter()
            .map(|p| {
                vec3(&Vec3::from_fn(|i, _| {
                    shape_coordinate(p[i], b.com_offset[i])
                }))
            })
            .collect();
        s.put("trace", Value::Array(points));
    }
    let free = b.free.iter().map(|f| string(f.name())).collect();
    s.put("free", Value::Array(free));
    s
}

fn obstacle(o: &Obstacle) -> Section {
    let mut s = Section::new("obstacle", true);
    s.put("name", string(&o.name));
    s.put("shape", o.shape_source.clone());
    s.put("position", vec3(&o.pose.translation.vector));
    s.put("orientation", vec3(&exp_map_of(&o.pose.rotation)));
    s.put("restitution", float(o.restitution));
    s.put("friction", float(o.friction));
    s
}

/// The scene as the tables saving writes, in writing order: the top level,
/// `[accuracy]`, `[scales]` (only when not the defaults), bodies,
/// obstacles, `[collisions]` (only with pairs), event controls (by event)
/// and constraints.
pub(super) fn sections(scene: &Scene) -> Vec<Section> {
    let mut top = Section::new("", false);
    top.put("name", string(&scene.name));
    if !scene.notes.is_empty() {
        top.put("notes", string(&scene.notes));
    }
    top.put("duration", float(scene.duration));
    top.put("gravity", vec3(&scene.gravity));
    let effects = scene
        .effects
        .listed()
        .iter()
        .map(|e| string(e.name()))
        .collect();
    top.put("effects", Value::Array(effects));
    top.put("rest_speed", float(scene.rest_speed));
    let mut out = vec![top];

    let mut accuracy = Section::new("accuracy", false);
    match scene.accuracy.method {
        Method::Rk4 { step } => {
            accuracy.put("method", string("rk4"));
            accuracy.put("step", float(step));
        }
        Method::Adaptive { tol, max_step } => {
            accuracy.put("method", string("adaptive"));
            accuracy.put("tol", float(tol));
            accuracy.put("max_step", float(max_step));
        }
    }
    accuracy.put("root_tol", float(scene.accuracy.root_tol));
    out.push(accuracy);

    if scene.scales != Scales::default() {
        let s = &scene.scales;
        let mut scales = Section::new("scales", false);
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
            scales.put(k, float(v));
        }
        out.push(scales);
    }

    out.extend(scene.bodies.iter().map(body));
    out.extend(scene.obstacles.iter().map(obstacle));

    let pairs: Vec<Value> = scene
        .pairs
        .iter()
        .filter_map(|&[i, j]| {
            Some(Value::Array(vec![
                string(&scene.bodies.get(i)?.name),
                string(&scene.bodies.get(j)?.name),
            ]))
        })
        .collect();
    if !pairs.is_empty() {
        let mut collisions = Section::new("collisions", false);
        collisions.put("pairs", Value::Array(pairs));
        out.push(collisions);
    }

    // By event, as loading orders them, so a saved scene's sections are
    // those of the scene it loads back to.
    let mut controls = scene.event_controls.clone();
    controls.sort_by_key(|c| c.event);
    for c in &controls {
        let mut s = Section::new("event_control", true);
        s.put(
            "event",
            Value::Integer(i64::try_from(c.event).unwrap_or(i64::MAX)),
        );
        if let Some([a, b]) = c.normal {
            s.put("normal", Value::Array(vec![float(a), float(b)]));
        }
        if let Some(e) = c.restitution {
            s.put("restitution", float(e));
        }
        if c.fixed {
            s.put("fixed", Value::Boolean(true));
        }
        out.push(s);
    }

    for c in &scene.constraints {
        let mut s = Section::new("constraint", true);
        if let Ok(Value::Table(t)) = Value::try_from(c) {
            for k in CONSTRAINT_FIELDS {
                if let Some(v) = t.get(k) {
                    s.put(k, v.clone());
                }
            }
        }
        out.push(s);
    }
    out
}
