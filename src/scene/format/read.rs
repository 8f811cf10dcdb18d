//! The whole scene: top-level fields, `[accuracy]`, `[scales]`, bodies and
//! obstacles, `[collisions]`, event controls, constraints, and the checks
//! that need all of them (unique names, nothing overlapping at t = 0).
use super::SceneError;
use super::body::{Spans, body, obstacle};
use super::constraint::constraints;
use super::shape::pose;
use super::source::{Bound, Source, Table, Value, as_table, numbers, suggestion};
use crate::geometry::contact;
use crate::math::Vec3;
use crate::scene::model::{
    Accuracy, Effect, Effects, EventControl, MAX_EVENTS, Method, ScaleKind, Scales, Scene,
};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;
use std::sync::Arc;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

/// The fields allowed at the top level.
pub(super) const SCENE_FIELDS: [&str; 13] = [
    "name",
    "notes",
    "duration",
    "gravity",
    "effects",
    "rest_speed",
    "accuracy",
    "scales",
    "body",
    "obstacle",
    "collisions",
    "event_control",
    "constraint",
];

/// Longest simulated time span a scene may ask for, s.
pub(super) const MAX_DURATION: f64 = 1e5;
/// Default gravity, m/s².
pub(super) const DEFAULT_GRAVITY: [f64; 3] = [0.0, 0.0, -9.81];
/// Default rest speed, m/s.
pub(super) const DEFAULT_REST_SPEED: f64 = 1e-3;
/// Default RK4 step, s.
pub(super) const DEFAULT_STEP: f64 = 1e-3;
/// Default adaptive tolerance.
pub(super) const DEFAULT_TOL: f64 = 1e-9;
/// Default largest adaptive step, s.
pub(super) const DEFAULT_MAX_STEP: f64 = 0.01;
/// Default collision root tolerance, m.
pub(super) const DEFAULT_ROOT_TOL: f64 = 1e-12;
/// Bodies penetrating deeper than this at t = 0 are rejected, m.
pub(super) const OVERLAP_TOLERANCE: f64 = 1e-9;

/// Read and validate a parsed document.
pub(super) fn scene(src: &Source<'_>, doc: &Spanned<DeTable<'_>>) -> Result<Scene, SceneError> {
    let t = Table {
        src,
        map: doc.get_ref(),
        span: doc.span(),
        owner: "scene",
        path: "",
    };
    t.allow_only(&SCENE_FIELDS)?;

    let default_name = Path::new(src.origin).file_stem().map_or_else(
        || src.origin.to_string(),
        |s| s.to_string_lossy().into_owned(),
    );
    let name = t
        .string("name", "give the scene a short name, e.g. name = \"eggs\"")?
        .map_or(default_name, str::to_string);
    let notes = t
        .string(
            "notes",
            "describe the scene and its intended edit as a string",
        )?
        .unwrap_or("")
        // A multi-line string in a CRLF file keeps its CRs: the notes are
        // the same text whatever the file's line endings.
        .replace("\r\n", "\n");
    let duration_hint = "give the simulated time span in s, e.g. duration = 3.0";
    let duration = t.required(
        "duration",
        Bound::PositiveAtMost(MAX_DURATION),
        duration_hint,
    )?;
    let gravity = t.vec3_or(
        "gravity",
        Vec3::from(DEFAULT_GRAVITY),
        "give gravity as [gx, gy, gz] in m/s^2, e.g. [0, 0, -9.81]",
    )?;
    let effects = effects(&t)?;
    let rest_speed = t.number_or(
        "rest_speed",
        DEFAULT_REST_SPEED,
        Bound::NonNegative,
        "give the speed in m/s below which a bounce ends at rest, 0 or greater, e.g. rest_speed = 0.001",
    )?;
    let accuracy = accuracy(&t)?;
    if let Some((problem, fix)) = accuracy.problem(duration) {
        return Err(t.src.error_at(&t.span_of("accuracy"), &problem, &fix));
    }
    let scales = scales(&t)?;

    let mut bodies = Vec::new();
    let mut body_spans = Vec::new();
    for (k, v) in tables(&t, "body")?.iter().enumerate() {
        let (b, s) = body(src, v, k)?;
        bodies.push(b);
        body_spans.push(s);
    }
    let mut obstacles = Vec::new();
    let mut obstacle_spans = Vec::new();
    for (k, v) in tables(&t, "obstacle")?.iter().enumerate() {
        let (o, s) = obstacle(src, v, k)?;
        obstacles.push(o);
        obstacle_spans.push(s);
    }
    unique_names(
        src,
        &bodies.iter().map(|b| b.name.as_str()).collect::<Vec<_>>(),
        &body_spans,
        &obstacles
            .iter()
            .map(|o| o.name.as_str())
            .collect::<Vec<_>>(),
        &obstacle_spans,
    )?;

    let body_names: Vec<&str> = bodies.iter().map(|b| b.name.as_str()).collect();
    let obstacle_names: Vec<&str> = obstacles.iter().map(|o| o.name.as_str()).collect();
    let pairs = collisions(&t, &body_names, &obstacle_names)?;
    let event_controls = event_controls(&t)?;
    let constraints = constraints(&t, &body_names, duration)?;

    let scene = Scene {
        name,
        notes,
        duration,
        gravity,
        effects,
        accuracy,
        rest_speed,
        bodies,
        obstacles,
        pairs,
        scales,
        event_controls,
        constraints,
        source_text: Some(Arc::from(src.text)),
    };
    no_overlaps(src, &scene, &body_spans)?;
    Ok(scene)
}

/// The elements of an array of tables (`[[key]]`), or none when absent.
pub(super) fn tables<'a, 'i>(t: &Table<'a, 'i>, key: &str) -> Result<&'a [Value<'i>], SceneError> {
    let hint = format!("write each {key} as a [[{key}]] table (double brackets)");
    let Some(v) = t.get(key) else { return Ok(&[]) };
    match v.get_ref() {
        DeValue::Array(a) => Ok(a),
        _ => Err(t.bad(key, "must be an array of tables", &hint)),
    }
}

fn effects(t: &Table<'_, '_>) -> Result<Effects, SceneError> {
    let names: Vec<&str> = Effect::ALL.iter().map(|e| e.name()).collect();
    let hint = format!(
        "list the effects to simulate from {}, e.g. effects = [\"gravity\", \"collisions\"]",
        names.join(", ")
    );
    let list = t
        .strings("effects", &hint)?
        .ok_or_else(|| t.missing("effects", &hint))?;
    let mut effects = Effects::default();
    for (name, span) in list {
        let Some(e) = Effect::ALL.into_iter().find(|e| e.name() == name) else {
            return Err(t.src.error_at(
                &span,
                &format!("{} lists an unknown effect", t.field("effects")),
                &format!(
                    "{}the effects are {}",
                    suggestion(name, &names),
                    names.join(", ")
                ),
            ));
        };
        effects.set(e, true);
    }
    Ok(effects)
}

/// A sub-table of the top level, read with its own owner name.
fn section<'a, 'i>(t: &Table<'a, 'i>, key: &'a str) -> Result<Option<Table<'a, 'i>>, SceneError> {
    let hint = format!("write it as a [{key}] table");
    Ok(t.table(key, &hint)?.and_then(|v| {
        as_table(v).map(|map| Table {
            src: t.src,
            map,
            span: v.span(),
            owner: key,
            path: "",
        })
    }))
}

fn accuracy(top: &Table<'_, '_>) -> Result<Accuracy, SceneError> {
    let Some(t) = section(top, "accuracy")? else {
        return Ok(Accuracy::default());
    };
    t.allow_only(&["method", "step", "tol", "max_step", "root_tol"])?;
    let method_hint = "write method = \"rk4\" (fixed step) or method = \"adaptive\" (Dormand-Prince with a tolerance)";
    let method = t.string("method", method_hint)?.unwrap_or("rk4");
    let method = match method {
        "rk4" => {
            for key in ["tol", "max_step"] {
                if t.get(key).is_some() {
                    return Err(t.bad(
                        key,
                        "applies only to method = \"adaptive\"",
                        "remove it, or set method = \"adaptive\"",
                    ));
                }
            }
            let step = t.number_or(
                "step",
                DEFAULT_STEP,
                Bound::Positive,
                "give the RK4 step in s, e.g. step = 0.001",
            )?;
            Method::Rk4 { step }
        }
        "adaptive" => {
            if t.get("step").is_some() {
                return Err(t.bad(
                    "step",
                    "applies only to method = \"rk4\"",
                    "remove it (use max_step to bound the adaptive step), or set method = \"rk4\"",
                ));
            }
            let tol = t.number_or(
                "tol",
                DEFAULT_TOL,
                Bound::Positive,
                "give the relative/absolute tolerance, e.g. tol = 1e-9",
            )?;
            let max_step = t.number_or(
                "max_step",
                DEFAULT_MAX_STEP,
                Bound::Positive,
                "give the largest step in s, e.g. max_step = 0.01",
            )?;
            Method::Adaptive { tol, max_step }
        }
        other => {
            return Err(t.bad(
                "method",
                "is not a known method",
                &format!("{}{method_hint}", suggestion(other, &["rk4", "adaptive"])),
            ));
        }
    };
    let root_tol = t.number_or(
        "root_tol",
        DEFAULT_ROOT_TOL,
        Bound::Positive,
        "give the collision-time tolerance on the signed distance in m, e.g. root_tol = 1e-12",
    )?;
    Ok(Accuracy { method, root_tol })
}

fn scales(top: &Table<'_, '_>) -> Result<Scales, SceneError> {
    let Some(t) = section(top, "scales")? else {
        return Ok(Scales::default());
    };
    let keys = ScaleKind::ALL.map(ScaleKind::name);
    t.allow_only(&keys)?;
    let hint = "give a scale greater than 0 (larger means change this less; default 1)";
    let mut scales = Scales::default();
    for kind in ScaleKind::ALL {
        scales.set(kind, t.number_or(kind.name(), 1.0, Bound::Positive, hint)?);
    }
    Ok(scales)
}

fn unique_names(
    src: &Source<'_>,
    bodies: &[&str],
    body_spans: &[Spans],
    obstacles: &[&str],
    obstacle_spans: &[Spans],
) -> Result<(), SceneError> {
    let mut seen: BTreeMap<&str, String> = BTreeMap::new();
    let all = bodies
        .iter()
        .zip(body_spans)
        .enumerate()
        .map(|(k, (n, s))| (*n, s, format!("body #{}", k + 1)))
        .chain(
            obstacles
                .iter()
                .zip(obstacle_spans)
                .enumerate()
                .map(|(k, (n, s))| (*n, s, format!("obstacle #{}", k + 1))),
        );
    for (name, spans, who) in all {
        if let Some(first) = seen.get(name) {
            return Err(src.error_at(
                &spans.name,
                &format!("{who} field name repeats the name of {first}"),
                "give every body and obstacle a different name",
            ));
        }
        seen.insert(name, who);
    }
    Ok(())
}

fn collisions(
    top: &Table<'_, '_>,
    bodies: &[&str],
    obstacles: &[&str],
) -> Result<Vec<[usize; 2]>, SceneError> {
    let Some(t) = section(top, "collisions")? else {
        return Ok(Vec::new());
    };
    t.allow_only(&["pairs", "groups"])?;
    let src = t.src;
    let listing = if bodies.is_empty() {
        "the scene has no bodies".to_string()
    } else {
        format!("the bodies are {}", bodies.join(", "))
    };
    let mut pairs = BTreeSet::new();
    for (key, hint) in [
        (
            "pairs",
            "write pairs = [[\"egg1\", \"egg2\"], ...] with two different body names each",
        ),
        (
            "groups",
            "write groups = [[\"a\", \"b\", \"c\"], ...]: every pair of bodies within a group collides",
        ),
    ] {
        let Some(list) = t.array(key, hint)? else {
            continue;
        };
        for (k, entry) in list.iter().enumerate() {
            let field = t.field(&format!("{key}[{k}]"));
            let names = match entry.get_ref() {
                DeValue::Array(a) if a.iter().all(|n| n.get_ref().is_str()) => a,
                _ => {
                    return Err(src.error_at(
                        &entry.span(),
                        &format!("{field} must be an array of body names"),
                        hint,
                    ));
                }
            };
            let right_count = if key == "pairs" {
                names.len() == 2
            } else {
                names.len() >= 2
            };
            if !right_count {
                let what = if key == "pairs" {
                    "must name exactly two bodies"
                } else {
                    "must name at least two bodies"
                };
                return Err(src.error_at(&entry.span(), &format!("{field} {what}"), hint));
            }
            let mut indices = Vec::with_capacity(names.len());
            for n in names {
                let name = n.get_ref().as_str().unwrap_or("");
                let index = match bodies.iter().position(|b| *b == name) {
                    Some(i) => i,
                    None if obstacles.contains(&name) => {
                        return Err(src.error_at(
                            &n.span(),
                            &format!("{field} names an obstacle, not a body"),
                            &format!("bodies always collide with obstacles when the collisions effect is on: list only bodies here ({listing})"),
                        ));
                    }
                    None => {
                        return Err(src.error_at(
                            &n.span(),
                            &format!("{field} names an unknown body"),
                            &format!("{}{listing}", suggestion(name, bodies)),
                        ));
                    }
                };
                if indices.contains(&index) {
                    let what = if key == "pairs" {
                        format!("{field} pairs body {name:?} with itself")
                    } else {
                        format!("{field} names body {name:?} twice")
                    };
                    return Err(src.error_at(
                        &entry.span(),
                        &what,
                        "name different bodies: a body never collides with itself",
                    ));
                }
                indices.push(index);
            }
            for (a, &i) in indices.iter().enumerate() {
                for &j in &indices[a + 1..] {
                    pairs.insert([i.min(j), i.max(j)]);
                }
            }
        }
    }
    Ok(pairs.into_iter().collect())
}

fn event_controls(top: &Table<'_, '_>) -> Result<Vec<EventControl>, SceneError> {
    let mut out: Vec<EventControl> = Vec::new();
    let mut owners: Vec<String> = Vec::new();
    for (k, v) in tables(top, "event_control")?.iter().enumerate() {
        let owner = format!("event_control #{}", k + 1);
        let map = as_table(v).ok_or_else(|| {
            top.bad(
                "event_control",
                "must be an array of tables",
                "write each as an [[event_control]] table",
            )
        })?;
        let t = Table {
            src: top.src,
            map,
            span: v.span(),
            owner: &owner,
            path: "",
        };
        t.allow_only(&["event", "normal", "restitution", "fixed"])?;
        let hint = "give the 0-based index of the collision event in time order, e.g. event = 2";
        let event = t
            .index("event", hint)?
            .ok_or_else(|| t.missing("event", hint))?;
        let event = usize::try_from(event)
            .ok()
            .filter(|&e| e < MAX_EVENTS)
            .ok_or_else(|| {
                t.bad(
                    "event",
                    &format!("is beyond the {MAX_EVENTS} events a motion may have"),
                    hint,
                )
            })?;
        if let Some(first) = out.iter().position(|c| c.event == event) {
            return Err(t.bad(
                "event",
                &format!("repeats the event of {}", owners[first]),
                "give each event a single [[event_control]] table",
            ));
        }
        let normal_hint =
            "give the normal deviation [a, b] in the tangent plane, e.g. normal = [0, 0]";
        let normal = match t.get("normal") {
            Some(n) => Some(numbers::<2>(t.src, n, &t.field("normal"), normal_hint)?),
            None => None,
        };
        let restitution = t.bounded(
            "restitution",
            Bound::Unit,
            "give the restitution used at this event, from 0 to 1",
        )?;
        let fixed = t
            .boolean(
                "fixed",
                "write fixed = true to keep these controls' values, or leave it out",
            )?
            .unwrap_or(false);
        out.push(EventControl {
            event,
            normal,
            restitution,
            fixed,
        });
        owners.push(owner);
    }
    out.sort_by_key(|c| c.event);
    Ok(out)
}

/// A penetration depth for messages.
fn depth(d: f64) -> String {
    if d >= 1e-4 {
        format!("{d:.4} m")
    } else {
        format!("{d:.1e} m")
    }
}

fn no_overlaps(src: &Source<'_>, scene: &Scene, spans: &[Spans]) -> Result<(), SceneError> {
    let poses: Vec<_> = scene
        .bodies
        .iter()
        .map(|b| pose(b.position, b.orientation))
        .collect();
    let hint = "move the bodies apart: bodies that can collide must not overlap at t = 0";
    for (i, b) in scene.bodies.iter().enumerate() {
        for o in &scene.obstacles {
            if let Some(c) = contact(&b.geometry, &poses[i], &o.geometry, &o.pose, 0.0)
                && c.distance < -OVERLAP_TOLERANCE
            {
                return Err(src.error_at(
                    &spans[i].position,
                    &format!(
                        "body {:?} starts inside obstacle {:?} (penetration {})",
                        b.name,
                        o.name,
                        depth(-c.distance)
                    ),
                    "move the body out of the obstacle: bodies must not overlap obstacles at t = 0",
                ));
            }
        }
    }
    for &[i, j] in &scene.pairs {
        let (a, b) = (&scene.bodies[i], &scene.bodies[j]);
        if let Some(c) = contact(&a.geometry, &poses[i], &b.geometry, &poses[j], 0.0)
            && c.distance < -OVERLAP_TOLERANCE
        {
            return Err(src.error_at(
                &spans[j].position,
                &format!(
                    "body {:?} starts inside body {:?} (penetration {})",
                    b.name,
                    a.name,
                    depth(-c.distance)
                ),
                hint,
            ));
        }
    }
    Ok(())
}
