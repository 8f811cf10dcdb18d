//! `[[constraint]]` tables: every field checked against the constraint's
//! kind when the scene loads, so a constraint that loads is one the editor
//! holds, and nothing the file says is dropped on the next save.
use super::SceneError;
use super::read::tables;
use super::source::{Table, as_table, number, plain, suggestion};
use crate::scene::model::{ConstraintKind, ConstraintSpec, MAX_EVENTS, Side};

/// The constraint fields (those of [`ConstraintSpec`]), in writing order.
pub(super) const CONSTRAINT_FIELDS: [&str; 8] = [
    "kind",
    "body",
    "other",
    "time",
    "collision",
    "side",
    "quantities",
    "target",
];

/// The scene's `[[constraint]]` tables, for a motion of `duration` seconds
/// with these `bodies`.
pub(super) fn constraints(
    top: &Table<'_, '_>,
    bodies: &[&str],
    duration: f64,
) -> Result<Vec<ConstraintSpec>, SceneError> {
    let mut out = Vec::new();
    let listing = if bodies.is_empty() {
        "the scene has no bodies".to_string()
    } else {
        format!("the bodies are {}", bodies.join(", "))
    };
    for (k, v) in tables(top, "constraint")?.iter().enumerate() {
        let owner = format!("constraint #{}", k + 1);
        let map = as_table(v).ok_or_else(|| {
            top.bad(
                "constraint",
                "must be an array of tables",
                "write each as a [[constraint]] table",
            )
        })?;
        let t = Table {
            src: top.src,
            map,
            span: v.span(),
            owner: &owner,
            path: "",
        };
        t.allow_only(&CONSTRAINT_FIELDS)?;
        let kind = kind(&t)?;
        side(&t)?;
        if let Some(list) = t.array("target", "give the target values as an array of numbers")? {
            for (i, x) in list.iter().enumerate() {
                number(
                    t.src,
                    x,
                    &t.field(&format!("target[{i}]")),
                    "give the target values as an array of finite numbers",
                )?;
            }
        }
        let spec: ConstraintSpec =
            plain(v.get_ref())
                .try_into()
                .map_err(|e: toml::de::Error| {
                    t.src.error_bare(
                        &t.span,
                        &format!("{owner} cannot be read: {}", e.message()),
                        "see docs/scene-format.md for the constraint fields",
                    )
                })?;
        for key in ["body", "other"] {
            let name = if key == "body" {
                Some(spec.body.as_str())
            } else {
                spec.other.as_deref()
            };
            if let Some(name) = name
                && !bodies.contains(&name)
            {
                return Err(t.bad(
                    key,
                    "names an unknown body",
                    &format!("{}{listing}", suggestion(name, bodies)),
                ));
            }
        }
        anchor(&t, &spec, duration)?;
        fields_of_kind(&t, kind, &spec)?;
        out.push(spec);
    }
    Ok(out)
}

/// The `kind` field, required, one of [`ConstraintKind::ALL`].
fn kind(t: &Table<'_, '_>) -> Result<ConstraintKind, SceneError> {
    let names: Vec<&str> = ConstraintKind::ALL.iter().map(|k| k.name()).collect();
    let hint = format!("give the kind, one of {}", names.join(", "));
    let word = t
        .string("kind", &hint)?
        .ok_or_else(|| t.missing("kind", &hint))?;
    ConstraintKind::ALL
        .into_iter()
        .find(|k| k.name() == word)
        .ok_or_else(|| {
            t.bad(
                "kind",
                "is not a constraint kind",
                &format!(
                    "{}use one of {}",
                    suggestion(word, &names),
                    names.join(", ")
                ),
            )
        })
}

/// The `side` field, if given: `pre` or `post`.
fn side(t: &Table<'_, '_>) -> Result<Option<Side>, SceneError> {
    let hint = "write side = \"pre\" (just before the impulse) or side = \"post\" (just after)";
    match t.string("side", hint)? {
        None => Ok(None),
        Some("pre") => Ok(Some(Side::Pre)),
        Some("post") => Ok(Some(Side::Post)),
        Some(_) => Err(t.bad("side", "must be \"pre\" or \"post\"", hint)),
    }
}

/// When the constraint holds: a time within the motion (a nail), the
/// body's k-th collision (a floating constraint), or either (an
/// expression).
fn anchor(t: &Table<'_, '_>, spec: &ConstraintSpec, duration: f64) -> Result<(), SceneError> {
    let kind = spec.kind.name();
    let time_hint = format!("give the time in s, from 0 to the duration {duration} s");
    let collision_hint = "give the 0-based index of the body's collision, e.g. collision = 0";
    let at_collision = match (spec.kind, spec.time, spec.collision) {
        (ConstraintKind::Nail, None, _) => return Err(t.missing("time", &time_hint)),
        (ConstraintKind::Nail, Some(_), _) => false,
        (ConstraintKind::Floating, _, None) => {
            return Err(t.missing("collision", collision_hint));
        }
        (ConstraintKind::Floating, _, Some(_)) => true,
        (_, Some(_), Some(_)) => {
            return Err(t.bad(
                "collision",
                &format!("is given with time: a {kind} constraint holds at one or the other"),
                "remove time to hold it at the collision, or collision to hold it at the time",
            ));
        }
        (_, None, None) => {
            return Err(t.missing(
                "time",
                &format!("{time_hint}, or collision = k to hold it at the body's k-th collision"),
            ));
        }
        (_, _, collision) => collision.is_some(),
    };
    let unused = |key: &str, holds: &str, fix: &str| {
        t.bad(
            key,
            &format!("is not used by a {kind} constraint (it holds at {holds})"),
            fix,
        )
    };
    if at_collision {
        if spec.collision.is_some_and(|k| k >= MAX_EVENTS) {
            return Err(t.bad(
                "collision",
                &format!("is beyond the {MAX_EVENTS} collisions a motion may have"),
                collision_hint,
            ));
        }
        if t.get("time").is_some() {
            return Err(unused(
                "time",
                "a collision",
                "remove time, or make it a nail",
            ));
        }
        return Ok(());
    }
    let time = spec.time.unwrap_or_default();
    if !(0.0..=duration).contains(&time) {
        return Err(t.bad("time", "is outside the motion", &time_hint));
    }
    for key in ["collision", "side"] {
        if t.get(key).is_some() {
            return Err(unused(key, "a time", &format!("remove {key}")));
        }
    }
    Ok(())
}

/// The quantities, the other body and the targets the kind needs.
fn fields_of_kind(
    t: &Table<'_, '_>,
    kind: ConstraintKind,
    spec: &ConstraintSpec,
) -> Result<(), SceneError> {
    let name = kind.name();
    let state = matches!(kind, ConstraintKind::Nail | ConstraintKind::Floating);
    if state {
        let hint = "list what it holds, e.g. quantities = [\"position\"]";
        if t.get("quantities").is_none() {
            return Err(t.missing("quantities", hint));
        }
        if spec.quantities.is_empty() {
            return Err(t.bad("quantities", "is empty", hint));
        }
    } else if t.get("quantities").is_some() {
        return Err(t.bad(
            "quantities",
            &format!("is not used by a {name} constraint"),
            "remove quantities: only nail and floating constraints hold quantities",
        ));
    }
    if kind.has_other() {
        if spec.other.is_none() {
            return Err(t.missing("other", "name the second body, e.g. other = \"egg2\""));
        }
    } else if t.get("other").is_some() {
        return Err(t.bad(
            "other",
            &format!("is not used by a {name} constraint"),
            "remove other: only equal_speed and distance constraints name a second body",
        ));
    }
    let (want, what) = kind.target_len(spec.quantities.len());
    let plural = if want == 1 { "" } else { "s" };
    let hint = format!("give {want} number{plural}: {what}");
    if want > 0 && t.get("target").is_none() {
        return Err(t.missing("target", &hint));
    }
    if spec.target.len() != want {
        let got = spec.target.len();
        return Err(t.bad(
            "target",
            &format!(
                "has {got} number{} where a {name} constraint needs {want}",
                if got == 1 { "" } else { "s" }
            ),
            &hint,
        ));
    }
    let nonnegative = match kind {
        ConstraintKind::AngularSpeed => spec.target.first().copied(),
        ConstraintKind::Distance => spec.target.get(6).copied(),
        _ => None,
    };
    if nonnegative.is_some_and(|v| v < 0.0) {
        return Err(t.bad("target", "gives a negative magnitude", &hint));
    }
    Ok(())
}
