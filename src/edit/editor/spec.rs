//! Constraints to and from their saved form (`scene::ConstraintSpec`).

use super::*;

pub(super) fn to_spec(scene: &Scene, c: &Constraint) -> ConstraintSpec {
    let name = |i: usize| {
        scene
            .bodies
            .get(i)
            .map(|b| b.name.clone())
            .unwrap_or_default()
    };
    let (time, collision, side) = match c.anchor {
        Anchor::Time(t) => (Some(t), None, None),
        Anchor::Event { collision, side } => (None, Some(collision), Some(side)),
    };
    let mut spec = ConstraintSpec {
        kind: c.kind(),
        body: name(c.body),
        other: None,
        time,
        collision,
        side,
        quantities: Vec::new(),
        target: Vec::new(),
    };
    match &c.kind {
        Kind::State { quantities, target } => {
            spec.quantities = quantities.clone();
            spec.target = target.clone();
        }
        Kind::EqualSpeed { other } => spec.other = Some(name(*other)),
        Kind::AngularSpeed { value } => spec.target = vec![*value],
        Kind::Upright { axis } | Kind::Steady { axis } => {
            spec.target = axis.iter().cloned().collect()
        }
        Kind::PointOnPlane {
            point,
            normal,
            offset,
        } => {
            spec.target = point
                .iter()
                .chain(normal.iter())
                .cloned()
                .chain([*offset])
                .collect()
        }
        Kind::Distance {
            other,
            point,
            other_point,
            value,
        } => {
            spec.other = Some(name(*other));
            spec.target = point
                .iter()
                .chain(other_point.iter())
                .cloned()
                .chain([*value])
                .collect();
        }
    }
    spec
}

/// The constraint a saved one describes. The scene loader has checked
/// every field against the kind, so this fails only for a spec built in
/// code that names an unknown body or gives too few targets.
pub(super) fn from_spec(scene: &Scene, s: &ConstraintSpec) -> Option<Constraint> {
    let body = scene.body_index(&s.body)?;
    let anchor = match (s.kind, s.time, s.collision) {
        (ConstraintKind::Floating, _, None) | (ConstraintKind::Nail, None, _) => return None,
        (ConstraintKind::Floating, _, Some(k)) | (_, None, Some(k)) => Anchor::Event {
            collision: k,
            side: s.side.unwrap_or(Side::Post),
        },
        (_, Some(t), _) => Anchor::Time(t),
        (_, None, None) => return None,
    };
    let other = || s.other.as_deref().and_then(|o| scene.body_index(o));
    let v3 = |i: usize| {
        Some(Vec3::new(
            *s.target.get(i)?,
            *s.target.get(i + 1)?,
            *s.target.get(i + 2)?,
        ))
    };
    let kind = match s.kind {
        ConstraintKind::Nail | ConstraintKind::Floating => {
            if s.quantities.is_empty() || s.target.len() != 3 * s.quantities.len() {
                return None;
            }
            Kind::State {
                quantities: s.quantities.clone(),
                target: s.target.clone(),
            }
        }
        ConstraintKind::EqualSpeed => Kind::EqualSpeed { other: other()? },
        ConstraintKind::AngularSpeed => Kind::AngularSpeed {
            value: *s.target.first()?,
        },
        ConstraintKind::Upright => Kind::Upright { axis: v3(0)? },
        ConstraintKind::Steady => Kind::Steady { axis: v3(0)? },
        ConstraintKind::PointOnPlane => Kind::PointOnPlane {
            point: v3(0)?,
            normal: v3(3)?,
            offset: *s.target.get(6)?,
        },
        ConstraintKind::Distance => Kind::Distance {
            other: other()?,
            point: v3(0)?,
            other_point: v3(3)?,
            value: *s.target.get(6)?,
        },
    };
    Some(Constraint {
        body,
        anchor,
        kind,
        drag: false,
    })
}
