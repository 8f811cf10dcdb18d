//! When the motion is simulated whole.
//!
//! A nudge's accepted trial is simulated only a little past the last
//! constrained time (the solver's horizon, `solve::update`), with tangents:
//! that prefix is all the next nudge of the same drag needs. Simulating
//! the rest at once is most of a nudge's cost (the eggs rattling in their
//! buckets after the edited flight), so when [`Editor::set_defer_motion`]
//! is on the editor keeps the prefix, draws the traces up to its horizon,
//! and simulates the whole motion when the user pauses ([`Core::idle`]) or
//! before any edit other than another nudge of the same drag. A held key's
//! frames then wait only for the trials.
//!
//! The whole motion is simulated afresh from the scene (never spliced onto
//! the prefix), so what is saved, drawn and exported after a pause is
//! exactly what opening the saved scene gives. Should it fail (a collision
//! after the horizon the simulator refuses), the nudges made since the
//! motion was last whole are taken back and the error says why.
//!
//! [`Core::idle`]: super::Core::idle

use super::*;

impl Editor {
    /// Keep a nudge's simulated prefix and simulate the rest in pauses
    /// (`true`: the terminal editor and key replays, which pause after
    /// every key), or simulate every accepted motion whole at once
    /// (`false`, the default: every edit leaves the whole motion).
    pub fn set_defer_motion(&mut self, on: bool) {
        self.defer_motion = on;
    }

    /// Replace the motion (every replacement counts: an edit that made
    /// none left the motion as it was).
    pub(super) fn set_motion(&mut self, traj: Trajectory) {
        self.traj = traj;
        self.motions += 1;
    }

    /// The time the current motion is simulated to: the scene's duration,
    /// or a nudge's horizon while the rest waits for a pause.
    pub fn motion_until(&self) -> f64 {
        self.traj.duration
    }

    /// The status line as shown: while only a prefix of the motion is
    /// known and nothing else is going on, it says how far the traces reach
    /// (a held key's traces end there until the keys pause).
    pub(super) fn shown_status(&self) -> view::Status {
        let mut status = self.status.clone();
        if self.motion_due && status.busy.is_none() {
            status.busy = Some(format!(
                "motion drawn to {:.2} s of {:.2} s; the rest follows when keys pause",
                self.traj.duration, self.scene.duration
            ));
        }
        status
    }

    /// Whether `tr`, a trial simulated to the solver's horizon, can stand
    /// for the motion until the next pause: deferring is on, and it reaches
    /// past the selected time and every constraint's time, so the next
    /// nudge of the same drag linearises inside it.
    pub(super) fn prefix_suffices(&self, tr: &Trajectory) -> bool {
        self.defer_motion
            && tr.tangent
            && self.time < tr.duration
            && self
                .constraints
                .iter()
                .all(|c| c.time(tr).is_some_and(|t| t < tr.duration))
    }

    /// Keep `tr` (a prefix) as the motion until the next pause.
    pub(super) fn keep_prefix(&mut self, tr: Trajectory) {
        if !self.motion_due {
            // The state before the nudge that is being committed: the last
            // one whose motion was whole.
            self.whole_at = Some(self.undo.len());
        }
        self.set_motion(tr);
        self.motion_due = true;
    }

    /// Simulate the whole motion if only a prefix is known. `Ok(true)` when
    /// it did. When the simulator refuses the whole motion, the nudges since
    /// the motion was last whole are taken back and the error names it.
    pub(super) fn complete_motion(&mut self) -> Result<bool, EditError> {
        if !self.motion_due {
            return Ok(false);
        }
        let simulated = {
            let _span = crate::profile::span(crate::profile::Part::Resimulate);
            simulate_with_tangent(&self.scene, &self.controls)
        };
        self.motion_due = false;
        let back_to = self.whole_at.take();
        match simulated {
            Ok(traj) => {
                self.set_motion(traj);
                self.refresh_geometry();
                self.status.residual = self.residual();
                Ok(true)
            }
            Err(e) => {
                let taken = back_to.filter(|&k| k < self.undo.len()).map(|k| {
                    let n = self.undo.len() - k;
                    let s = self.undo[k].clone();
                    self.undo.truncate(k);
                    (n, s)
                });
                match taken {
                    Some((n, s)) => {
                        self.restore(s)?;
                        Err(EditError::MotionRefused {
                            nudges: n,
                            why: e.to_string(),
                        })
                    }
                    None => Err(e),
                }
            }
        }
    }
}
