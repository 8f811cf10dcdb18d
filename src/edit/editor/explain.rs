//! Words for what the editor did and why it could not: the name of an edit
//! (for undo and redo), the constraints that block a drag, and the release
//! of some quantities of a constraint (the way past a blocker).

use super::*;

impl Editor {
    /// What `edit` is, in a few words: "nudge of egg1's position".
    pub(super) fn describe(&self, edit: &Edit) -> String {
        let body = self
            .scene
            .bodies
            .get(self.selected)
            .map_or("—", |b| b.name.as_str());
        let t = |t: f64| format!("t={}", (t * 1e4).round() / 1e4);
        match edit {
            Edit::Nudge { quantity, .. } => format!("nudge of {body}'s {}", quantity.name()),
            Edit::Nail { .. } => format!("nail of {body} at {}", t(self.time)),
            Edit::Float { .. } => format!("floating constraint of {body}"),
            Edit::Expression(_) => format!("expression constraint on {body}"),
            Edit::Vertical { goal, .. } => format!("{} constraint on {body}", goal.word()),
            Edit::RemoveConstraint(i) => format!("deletion of constraint row {i}"),
            Edit::Release { row, quantities } => {
                let names: Vec<&str> = quantities.iter().map(|q| q.name()).collect();
                format!("release of {} from row {row}", names.join(", "))
            }
            Edit::SetBlock { body, block, free } => {
                let name = self
                    .scene
                    .bodies
                    .get(*body)
                    .map_or("—", |b| b.name.as_str());
                let how = if *free { "freeing" } else { "fixing" };
                format!("{how} of {name}.{}", block.name())
            }
            Edit::AddEventControls { .. } => "event controls".into(),
            Edit::SetEventControls { .. } => "fixing or freeing of event controls".into(),
            Edit::SetScale { kind, .. } => format!("scale of {}", kind.name()),
            Edit::SetAccuracy(a) => format!("accuracy {}", a.label()),
            Edit::Settle { .. } => "settle".into(),
            Edit::SetControls(_) => "choice of an explored alternative".into(),
            Edit::SelectBody(_) | Edit::SelectTime(_) | Edit::SelectEvent(_) => "selection".into(),
            Edit::Undo | Edit::Redo => String::new(),
        }
    }

    /// The persistent constraints that keep the drag `all.last()` from
    /// being followed on the current motion.
    pub(super) fn blocked_by(&self, all: &[Constraint]) -> Vec<BlockedBy> {
        let rows = self.constraint_rows();
        solve::blockers(&self.traj, all, &self.controls.scales(), self.opts.rank_tol)
            .into_iter()
            .filter_map(|b| {
                let row = rows.get(b.constraint)?;
                Some(BlockedBy {
                    row: b.constraint,
                    kind: self.constraints.get(b.constraint)?.label(),
                    body: row.body.clone(),
                    at: row.at.clone(),
                    quantities: b.quantities,
                })
            })
            .collect()
    }

    /// Stop holding `quantities` in constraint `row` (a nail or floating
    /// constraint); remove it when it holds nothing else.
    pub(super) fn release(
        &mut self,
        row: usize,
        quantities: &[StateQuantity],
    ) -> Result<(), EditError> {
        let n = self.constraints.len();
        let c = self
            .constraints
            .get_mut(row)
            .ok_or_else(|| invalid(format!("no constraint row {row}: there are {n}")))?;
        let Kind::State {
            quantities: held,
            target,
        } = &mut c.kind
        else {
            return Err(invalid(format!(
                "constraint row {row} is a {} constraint, which holds no quantities: :delete {row} removes it",
                c.label()
            )));
        };
        for q in quantities {
            let Some(k) = held.iter().position(|h| h == q) else {
                return Err(invalid(format!(
                    "constraint row {row} does not hold {}",
                    q.name()
                )));
            };
            held.remove(k);
            target.drain(3 * k..3 * k + 3);
        }
        if held.is_empty() {
            self.constraints.remove(row);
        }
        Ok(())
    }
}
