//! The machine-readable summary (`nudge check --json`, `nudge run --report`)
//! and its text form. The JSON shape is a contract: later features add keys,
//! never rename these.

use crate::controls::Controls;
use crate::scene::{Effect, Scene};
use crate::sim::{Party, Side, Trajectory};
use serde_json::{Value, json};

/// A finite number, or JSON `null` (NaN and infinity never reach a report).
pub fn num(v: f64) -> Value {
    if v.is_finite() { json!(v) } else { Value::Null }
}

fn vec3(v: &crate::math::Vec3) -> Value {
    Value::Array(v.iter().map(|x| num(*x)).collect())
}

/// Name of a collision party.
pub fn party_name(scene: &Scene, p: Party) -> String {
    match p {
        Party::Body(i) => scene
            .bodies
            .get(i)
            .map(|b| b.name.clone())
            .unwrap_or_default(),
        Party::Obstacle(i) => scene
            .obstacles
            .get(i)
            .map(|o| o.name.clone())
            .unwrap_or_default(),
    }
}

/// One constraint row of a report: the constraints panel's row.
pub use crate::view::ConstraintRow;

/// The summary object: `scene`, `duration`, `controls`, `constraints`,
/// `events`, `bodies`, `effects`, `diagnostics`.
pub fn summary(
    scene: &Scene,
    controls: &Controls,
    traj: &Trajectory,
    constraints: &[ConstraintRow],
    diagnostics: &[String],
) -> Value {
    let controls_json: Vec<Value> = controls
        .entries
        .iter()
        .enumerate()
        .map(|(i, e)| json!({"name": e.name, "value": num(controls.get(scene, i)), "free": e.free}))
        .collect();
    let events: Vec<Value> = traj
        .events
        .iter()
        .map(|e| {
            let mut v = json!({
                "t": num(e.t),
                "a": party_name(scene, Party::Body(e.a)),
                "b": party_name(scene, e.b),
                "feature": e.key,
                "grazing": e.grazing,
                "normal": vec3(&e.normal),
                "point": vec3(&e.point),
                "approach_speed": num(-e.approach),
                "restitution": num(e.restitution),
                "rest": e.rest,
            });
            // A ball's switch from slipping to rolling (no impulse).
            if e.roll {
                v["rolls"] = json!(true);
            }
            v
        })
        .collect();
    let bodies: Vec<Value> = scene
        .bodies
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let s = traj.state(i, traj.duration, Side::Post);
            json!({
                "name": b.name,
                "final": {
                    "position": vec3(&s.x),
                    "orientation": vec3(&s.orientation_vector()),
                    "velocity": vec3(&s.v),
                    "angular_velocity": vec3(&s.w),
                }
            })
        })
        .collect();
    let mut effects = serde_json::Map::new();
    for e in Effect::ALL {
        if scene.effects.has(e) || counter(traj, e) > 0 {
            effects.insert(e.name().to_string(), json!(counter(traj, e)));
        }
    }
    let constraints: Vec<Value> = constraints
        .iter()
        .map(|c| json!({"kind": c.kind, "body": c.body, "at": c.at, "residual": num(c.residual)}))
        .collect();
    let mut diags: Vec<String> = traj.diagnostics.clone();
    diags.extend(diagnostics.iter().cloned());
    json!({
        "scene": scene.name,
        "duration": num(scene.duration),
        "controls": controls_json,
        "constraints": constraints,
        "events": events,
        "bodies": bodies,
        "effects": Value::Object(effects),
        "diagnostics": diags,
    })
}

/// Evaluation count of an effect's term.
pub fn counter(traj: &Trajectory, e: Effect) -> u64 {
    let c = &traj.counters;
    match e {
        Effect::Gravity => c.gravity.get(),
        Effect::Drag => c.drag.get(),
        Effect::Gyroscopic => c.gyroscopic.get(),
        Effect::Collisions => c.collisions.get(),
        Effect::Friction => c.friction.get(),
    }
}

/// A fixed-precision number for text output (`—` when not finite).
pub fn fixed(v: f64, digits: usize) -> String {
    if v.is_finite() {
        format!("{v:.digits$}")
    } else {
        "—".to_string()
    }
}

/// The human-readable summary printed by `nudge check`.
pub fn text(scene: &Scene, controls: &Controls, traj: &Trajectory) -> String {
    use std::fmt::Write;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "scene {} — {} bodies, {} obstacles, {:.3} s, {}",
        scene.name,
        scene.bodies.len(),
        scene.obstacles.len(),
        scene.duration,
        scene.accuracy.label()
    );
    let _ = writeln!(s, "\neffects (evaluations):");
    for e in Effect::ALL {
        let listed = if scene.effects.has(e) { "on " } else { "off" };
        let _ = writeln!(s, "  {:<11} {listed} {:>10}", e.name(), counter(traj, e));
    }
    if scene.effects.collisions {
        let islands = traj.counters.islands.get();
        let _ = writeln!(
            s,
            "  {:<11}     {islands:>10}  (island statics solved)",
            "islands"
        );
    }
    let _ = writeln!(
        s,
        "\ncontrols ({} free of {}):",
        controls.m(),
        controls.entries.len()
    );
    for (i, e) in controls.entries.iter().enumerate() {
        let _ = writeln!(
            s,
            "  {} {:<32} {:>14}",
            if e.free { "●" } else { "○" },
            e.name,
            fixed(controls.get(scene, i), 6)
        );
    }
    let _ = writeln!(s, "\nevents ({}):", traj.events.len());
    for e in &traj.events {
        let _ = writeln!(
            s,
            "  #{:<3} t={:>9}  {:<10} × {:<10} {:<18} v_n={:>8}{}{}{}",
            e.index,
            fixed(e.t, 6),
            party_name(scene, Party::Body(e.a)),
            party_name(scene, e.b),
            e.key,
            fixed(-e.approach, 4),
            if e.grazing { "  GRAZING" } else { "" },
            if e.rest { "  rest" } else { "" },
            if e.roll { "  rolls" } else { "" }
        );
    }
    let _ = writeln!(s, "\nfinal states (t = {:.3} s):", traj.duration);
    for (i, b) in scene.bodies.iter().enumerate() {
        let st = traj.state(i, traj.duration, Side::Post);
        let f = |v: &crate::math::Vec3| {
            format!("[{}, {}, {}]", fixed(v.x, 4), fixed(v.y, 4), fixed(v.z, 4))
        };
        let _ = writeln!(
            s,
            "  {:<10} x={} r={} v={} ω={}",
            b.name,
            f(&st.x),
            f(&st.orientation_vector()),
            f(&st.v),
            f(&st.w)
        );
    }
    for d in &traj.diagnostics {
        let _ = writeln!(s, "diagnostic: {d}");
    }
    s
}
