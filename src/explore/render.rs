//! An exploration as text (a table, then each alternative's collisions and
//! controls) and as JSON. No NaN or infinity is ever printed: a number that
//! is not finite prints as `—` in text and `null` in JSON.

use super::{Alternative, Contact, Exploration};
use crate::report::num;
use crate::scene::Scene;
use crate::solve::{Anchor, Constraint, Kind};
use serde_json::{Value, json};
use std::fmt::Write;

/// A number in a table cell.
fn cell(v: f64) -> String {
    if !v.is_finite() {
        "—".into()
    } else if v == 0.0 {
        "0".into()
    } else if (1e-3..1e4).contains(&v.abs()) {
        format!("{v:.4}")
    } else {
        format!("{v:.2e}")
    }
}

/// A control value: six decimals, or scientific beyond that.
fn value(v: f64) -> String {
    if !v.is_finite() {
        "—".into()
    } else if v == 0.0 || (1e-4..1e6).contains(&v.abs()) {
        format!("{v:.6}")
    } else {
        format!("{v:.4e}")
    }
}

fn words(contacts: &[Contact]) -> Vec<String> {
    contacts.iter().map(Contact::words).collect()
}

fn collisions_line(contacts: &[Contact]) -> String {
    if contacts.is_empty() {
        "none before the constrained times".into()
    } else {
        words(contacts).join("; ")
    }
}

/// The goal in words: `drag of ball (position) at t = 1.000 s`.
fn goal_words(scene: &Scene, c: &Constraint) -> String {
    let body = scene.bodies.get(c.body).map_or("?", |b| b.name.as_str());
    let what = match &c.kind {
        Kind::State { quantities, .. } => {
            let q: Vec<&str> = quantities.iter().map(|q| q.name()).collect();
            format!(" ({})", q.join(", "))
        }
        _ => String::new(),
    };
    let at = match c.anchor {
        Anchor::Time(t) => format!("t = {} s", cell(t)),
        Anchor::Event { collision, side } => format!("collision {collision} ({})", side.word()),
    };
    format!("{} of {body}{what} at {at}", c.label())
}

/// The exploration as text.
pub fn text(scene: &Scene, x: &Exploration) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "explore {}: {} worlds sampled ({} failed, {} not finite, skipped; {} not simulated, too far to be kept), {} collision sequences, {} polishing updates{}",
        scene.name,
        x.worlds,
        x.failed,
        x.non_finite,
        x.pruned,
        x.groups,
        x.polish_updates,
        if x.cancelled { "; cancelled" } else { "" }
    );
    if let Some(g) = &x.goal {
        let _ = writeln!(s, "goal: {}", goal_words(scene, g));
    }
    let _ = writeln!(
        s,
        "current: residual {}, collisions: {}",
        cell(x.current.residual),
        collisions_line(&x.current.contacts)
    );
    if x.alternatives.is_empty() {
        let _ = writeln!(s, "no alternatives: no sampled world could be scored");
        return s;
    }
    let _ = writeln!(s);
    let head = ["#", "score", "residual", "‖Δu‖_M", "events", "polished"];
    let rows: Vec<[String; 6]> = x
        .alternatives
        .iter()
        .enumerate()
        .map(|(k, a)| {
            [
                (k + 1).to_string(),
                cell(a.score),
                cell(a.residual),
                cell(a.distance),
                a.events.to_string(),
                a.polished.to_string(),
            ]
        })
        .collect();
    let width: Vec<usize> = (0..head.len())
        .map(|c| {
            rows.iter()
                .map(|r| r[c].chars().count())
                .chain([head[c].chars().count()])
                .max()
                .unwrap_or(0)
        })
        .collect();
    let line = |cells: &[String]| {
        let mut l = String::from(" ");
        for (c, v) in cells.iter().enumerate() {
            let _ = write!(l, " {v:>w$}", w = width[c]);
        }
        l
    };
    let head: Vec<String> = head.iter().map(|h| h.to_string()).collect();
    let _ = writeln!(s, "{}  what differs", line(&head));
    for (r, a) in rows.iter().zip(&x.alternatives) {
        let _ = writeln!(s, "{}  {}", line(r), a.description);
    }
    for (k, a) in x.alternatives.iter().enumerate() {
        let _ = writeln!(s);
        let _ = writeln!(s, "#{} collisions: {}", k + 1, collisions_line(&a.contacts));
        let _ = writeln!(s, "   controls:");
        for (name, (v, v0)) in x
            .names
            .iter()
            .zip(a.controls.iter().zip(&x.current.controls))
        {
            let _ = writeln!(s, "     {name:<28} {:>14}  Δ {}", value(*v), cell(v - v0));
        }
    }
    s
}

fn alternative_json(x: &Exploration, rank: usize, a: &Alternative) -> Value {
    let controls: Vec<Value> = x
        .names
        .iter()
        .zip(a.controls.iter().zip(&x.current.controls))
        .map(|(name, (v, v0))| json!({"name": name, "value": num(*v), "delta": num(v - v0)}))
        .collect();
    json!({
        "rank": rank,
        "score": num(a.score),
        "residual": num(a.residual),
        "distance": num(a.distance),
        "events": a.events,
        "polished": a.polished,
        "sample": a.sample,
        "from": if a.sample.is_some() { "sample" } else { "current" },
        "same_as_current": a.same_as_current,
        "description": a.description,
        "signature": a.signature,
        "collisions": words(&a.contacts),
        "controls": controls,
    })
}

/// The exploration as one JSON object.
pub fn json(scene: &Scene, x: &Exploration) -> Value {
    let goal = x.goal.as_ref().map(|g| {
        let target = match &g.kind {
            Kind::State { target, .. } => target.iter().map(|v| num(*v)).collect(),
            _ => Vec::new(),
        };
        json!({"what": goal_words(scene, g), "target": target})
    });
    json!({
        "scene": scene.name,
        "worlds": x.worlds,
        "failed": x.failed,
        "non_finite": x.non_finite,
        "pruned": x.pruned,
        "groups": x.groups,
        "polish_updates": x.polish_updates,
        "cancelled": x.cancelled,
        "goal": goal,
        "current": {
            "residual": num(x.current.residual),
            "events": x.current.events,
            "signature": x.current.signature,
            "collisions": words(&x.current.contacts),
            "controls": x.names.iter().zip(&x.current.controls)
                .map(|(n, v)| json!({"name": n, "value": num(*v)}))
                .collect::<Vec<_>>(),
        },
        "alternatives": x.alternatives.iter().enumerate()
            .map(|(k, a)| alternative_json(x, k + 1, a))
            .collect::<Vec<_>>(),
    })
}
