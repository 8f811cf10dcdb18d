//! What the readout and the plot show about the selected body and the
//! constraints: its pose now, its neighbouring collisions, where each
//! constraint holds a position, and each event in words.

use super::*;

impl Editor {
    /// The selected body's state at the current time.
    pub(super) fn pose(&self) -> Option<view::Pose> {
        if self.selected >= self.scene.bodies.len() {
            return None;
        }
        let s = self.traj.state(self.selected, self.time, Side::Post);
        if !s.is_finite() {
            return None;
        }
        let r = s.orientation_vector();
        let angle = r.norm();
        let axis = if angle > 1e-12 { r / angle } else { Vec3::z() };
        let up = s.q * Vec3::z();
        let tilt = up.z.clamp(-1.0, 1.0).acos();
        let events = self.traj.body_events(self.selected);
        // The other party: `b`, or `a` when the selected body was hit.
        let neighbour = |e: &&crate::sim::Event| view::Neighbour {
            index: e.index,
            t: e.t,
            other: if e.a == self.selected {
                report::party_name(&self.scene, e.b)
            } else {
                report::party_name(&self.scene, Party::Body(e.a))
            },
        };
        Some(view::Pose {
            position: s.x,
            angle_deg: angle.to_degrees(),
            axis,
            tilt_deg: tilt.to_degrees(),
            velocity: s.v,
            angular_velocity: s.w,
            previous: events
                .iter()
                .rev()
                .find(|e| e.t <= self.time)
                .map(neighbour),
            next: events.iter().find(|e| e.t > self.time).map(neighbour),
        })
    }

    /// Where each constraint that holds a position holds it, with the
    /// distance from the body's position there (the constraint's time).
    pub(super) fn position_targets(&self) -> Vec<(view::Target, Option<f64>)> {
        self.constraints
            .iter()
            .enumerate()
            .filter_map(|(row, c)| {
                let Kind::State { quantities, target } = &c.kind else {
                    return None;
                };
                let k = quantities
                    .iter()
                    .position(|q| *q == StateQuantity::Position)?;
                let point = Vec3::new(target[3 * k], target[3 * k + 1], target[3 * k + 2]);
                let side = match c.anchor {
                    Anchor::Event { side, .. } => side,
                    Anchor::Time(_) => Side::Post,
                };
                let gap = c
                    .time(&self.traj)
                    .map(|t| (self.traj.state(c.body, t, side).x - point).norm())
                    .filter(|g| g.is_finite());
                Some((
                    view::Target {
                        row,
                        body: c.body,
                        point,
                    },
                    gap,
                ))
            })
            .collect()
    }

    /// An event as drawn and described.
    pub(super) fn event_mark(&self, e: &crate::sim::Event) -> view::EventMark {
        view::EventMark {
            index: e.index,
            t: e.t,
            point: e.point,
            a: report::party_name(&self.scene, Party::Body(e.a)),
            b: report::party_name(&self.scene, e.b),
            grazing: e.grazing,
            features: feature_words(&e.key),
            approach: e.approach.abs(),
            separation: e.separation.abs(),
            micro: e.micro || e.rest,
        }
    }
}

/// `0:v3/0:plane` → `vertex 3 on plane`.
fn feature_words(key: &str) -> String {
    let word = |part: &str| {
        let f = part.split_once(':').map_or(part, |(_, f)| f);
        let rest = |p: &str| f.strip_prefix(p).map(|r| r.replace('+', ", "));
        if let Some(v) = rest("v") {
            format!("vertex {v}")
        } else if let Some(e) = rest("e") {
            format!("edge {e}")
        } else if let Some(fc) =
            rest("f").filter(|r| r.chars().next().is_some_and(|c| c.is_ascii_digit()))
        {
            format!("face {fc}")
        } else {
            f.to_string()
        }
    };
    match key.split_once('/') {
        Some((a, b)) => format!("{} on {}", word(a), word(b)),
        None => word(key),
    }
}

#[cfg(test)]
mod tests {
    use super::feature_words;

    #[test]
    fn features_read_as_words() {
        assert_eq!(feature_words("0:v3/0:plane"), "vertex 3 on plane");
        assert_eq!(feature_words("0:v1+2/0:face"), "vertex 1, 2 on face");
        assert_eq!(feature_words("1:e0-1/0:f2-3-4"), "edge 0-1 on face 2-3-4");
        assert_eq!(feature_words("0:ball/0:parabola"), "ball on parabola");
    }
}
