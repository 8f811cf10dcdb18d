//! One edit applied: the arm of each `Edit`, then the commit, the
//! integration error estimate and the outcome.

use super::*;

impl Editor {
    pub(super) fn apply_inner(&mut self, edit: Edit) -> Result<Outcome, EditError> {
        let started = Instant::now();
        let updates0 = self.updates;
        let before = self.snapshot();
        let old_values = self.values();
        let mut changed = true;
        let mut notes: Vec<Note> = Vec::new();
        let mut anchored = None;
        let mut reverted = None;
        let label = self.describe(&edit);
        let (revision0, motions0) = (self.revision, self.motions);
        // The drawn motion before an edit that may change it, for the ghost
        // (not copied for the selections a scrub or playback makes).
        let selects = matches!(
            edit,
            Edit::SelectBody(_) | Edit::SelectTime(_) | Edit::SelectEvent(_)
        );
        let paths0 = (!selects).then(|| self.paths.clone());
        let is_nudge = matches!(edit, Edit::Nudge { .. });
        let is_accept = matches!(edit, Edit::SetControls(_));
        // A blocked drag stays the pending goal while the user looks around
        // or nudges again; any other edit retires it.
        let retires_drag = !matches!(
            edit,
            Edit::SelectBody(_) | Edit::SelectTime(_) | Edit::SelectEvent(_) | Edit::Nudge { .. }
        );
        let adds_constraint = matches!(
            edit,
            Edit::Nail { .. } | Edit::Float { .. } | Edit::Expression(_) | Edit::Vertical { .. }
        );
        match edit {
            Edit::SelectBody(i) => {
                if i >= self.scene.bodies.len() {
                    return Err(invalid(format!(
                        "no body {i}: the scene has {} bodies",
                        self.scene.bodies.len()
                    )));
                }
                self.selected = i;
                changed = false;
            }
            Edit::SelectTime(t) => {
                if !t.is_finite() {
                    return Err(invalid(format!(
                        "time must be a finite number of seconds, got {t}"
                    )));
                }
                self.time = t.clamp(0.0, self.scene.duration);
                if t > self.scene.duration {
                    notes.push(Note::TimeClamped {
                        asked: t,
                        to: self.time,
                    });
                }
                changed = false;
            }
            Edit::SelectEvent(k) => {
                let e = self.traj.events.get(k).ok_or_else(|| {
                    invalid(format!(
                        "no event {k}: the motion has {} events",
                        self.traj.events.len()
                    ))
                })?;
                self.time = e.t;
                changed = false;
            }
            Edit::Nudge { quantity, delta } => {
                notes.extend(self.nudge(quantity, delta)?);
                changed = self.updates > updates0 && self.values() != old_values;
            }
            Edit::Nail { quantities, exact } => {
                let quantities = if quantities.is_empty() {
                    StateQuantity::ALL.to_vec()
                } else {
                    quantities
                };
                let s = self.traj.state(self.selected, self.time, Side::Post);
                let target = targets(&s, &quantities, &exact)?;
                self.constraints.push(Constraint {
                    body: self.selected,
                    anchor: Anchor::Time(self.time),
                    kind: Kind::State { quantities, target },
                    drag: false,
                });
                anchored = Some(Anchored::Time(self.time));
            }
            Edit::Float {
                quantities,
                exact,
                side,
            } => {
                let quantities = if quantities.is_empty() {
                    StateQuantity::ALL.to_vec()
                } else {
                    quantities
                };
                let (k, global) = self.nearest_collision().ok_or_else(|| {
                    invalid(format!(
                        "{} has no collision to float a constraint on",
                        self.scene.bodies[self.selected].name
                    ))
                })?;
                let e = &self.traj.events[global];
                let side = side.unwrap_or(if e.t > self.time {
                    Side::Pre
                } else {
                    Side::Post
                });
                let s = self.traj.state(self.selected, e.t, side);
                let target = targets(&s, &quantities, &exact)?;
                self.constraints.push(Constraint {
                    body: self.selected,
                    anchor: Anchor::Event { collision: k, side },
                    kind: Kind::State { quantities, target },
                    drag: false,
                });
                anchored = Some(Anchored::Collision {
                    collision: k,
                    event: e.index,
                    side,
                });
            }
            Edit::Expression(x) => {
                let n = self.scene.bodies.len();
                let kind = match x {
                    Expression::EqualSpeed { other } if other < n => Kind::EqualSpeed { other },
                    Expression::AngularSpeed { value } if value.is_finite() && value >= 0.0 => {
                        Kind::AngularSpeed { value }
                    }
                    Expression::PointOnPlane {
                        point,
                        normal,
                        offset,
                    } if normal.norm() > 0.0 && offset.is_finite() => {
                        finite3(&point, "the point")?;
                        finite3(&normal, "the plane normal")?;
                        Kind::PointOnPlane {
                            point,
                            normal,
                            offset,
                        }
                    }
                    Expression::Distance {
                        other,
                        point,
                        other_point,
                        value,
                    } if other < n && value.is_finite() && value >= 0.0 => {
                        finite3(&point, "the point")?;
                        finite3(&other_point, "the other point")?;
                        Kind::Distance {
                            other,
                            point,
                            other_point,
                            value,
                        }
                    }
                    other => {
                        return Err(invalid(format!(
                            "invalid expression constraint {other:?}: bodies must exist and values be finite and non-negative"
                        )));
                    }
                };
                self.constraints.push(Constraint {
                    body: self.selected,
                    anchor: Anchor::Time(self.time),
                    kind,
                    drag: false,
                });
            }
            Edit::Vertical { goal, side } => {
                let anchor = match side {
                    None => {
                        anchored = Some(Anchored::Time(self.time));
                        Anchor::Time(self.time)
                    }
                    Some(side) => {
                        let (collision, event) = self.nearest_collision().ok_or_else(|| {
                            invalid(format!(
                                "{} has no collision to hold it {} at",
                                self.scene.bodies[self.selected].name,
                                goal.word()
                            ))
                        })?;
                        anchored = Some(Anchored::Collision {
                            collision,
                            event: self.traj.events[event].index,
                            side,
                        });
                        Anchor::Event { collision, side }
                    }
                };
                // Upright: the shape's z axis (the body frame is the
                // shape's, moved to the centre of mass). Steady: the world's.
                let kind = match goal {
                    Vertical::Upright => Kind::Upright { axis: Vec3::z() },
                    Vertical::Steady => Kind::Steady { axis: Vec3::z() },
                };
                self.constraints.push(Constraint {
                    body: self.selected,
                    anchor,
                    kind,
                    drag: false,
                });
            }
            Edit::RemoveConstraint(i) => {
                if i >= self.constraints.len() {
                    return Err(invalid(format!(
                        "no constraint {i}: there are {}",
                        self.constraints.len()
                    )));
                }
                self.constraints.remove(i);
            }
            Edit::Release { row, quantities } => self.release(row, &quantities)?,
            Edit::SetBlock { body, block, free } => {
                let b = self
                    .scene
                    .bodies
                    .get_mut(body)
                    .ok_or_else(|| invalid(format!("no body {body}")))?;
                b.free.retain(|x| *x != block);
                if free {
                    b.free.push(block);
                    b.free.sort();
                }
                self.rebuild()?;
            }
            Edit::AddEventControls {
                normal,
                restitution,
            } => {
                let (_, global) = self.nearest_collision().ok_or_else(|| {
                    invalid(format!(
                        "{} has no collision to add controls at",
                        self.scene.bodies[self.selected].name
                    ))
                })?;
                let e_used = self.traj.events[global].restitution;
                let c = match self
                    .scene
                    .event_controls
                    .iter_mut()
                    .find(|c| c.event == global)
                {
                    Some(c) => c,
                    None => {
                        self.scene.event_controls.push(EventControl {
                            event: global,
                            normal: None,
                            restitution: None,
                            fixed: false,
                        });
                        self.scene
                            .event_controls
                            .last_mut()
                            .ok_or_else(|| invalid("internal: event control"))?
                    }
                };
                if normal && c.normal.is_none() {
                    c.normal = Some([0.0, 0.0]);
                }
                if restitution && c.restitution.is_none() {
                    c.restitution = Some(e_used);
                }
                self.rebuild()?;
            }
            Edit::SetEventControls { event, free } => {
                let event = match event {
                    Some(k) => k,
                    None => {
                        self.nearest_collision()
                            .ok_or_else(|| {
                                invalid(format!(
                                    "{} has no collision whose controls to fix or free",
                                    self.scene.bodies[self.selected].name
                                ))
                            })?
                            .1
                    }
                };
                let c = self
                    .scene
                    .event_controls
                    .iter_mut()
                    .find(|c| c.event == event)
                    .ok_or_else(|| {
                        invalid(format!(
                            "event {event} has no controls: press e at it (or :event {event} then e) to add them"
                        ))
                    })?;
                c.fixed = match free {
                    Some(f) => !f,
                    None => !c.fixed,
                };
                self.rebuild()?;
            }
            Edit::SetScale { kind, value } => {
                if !(value.is_finite() && value > 0.0) {
                    return Err(invalid(format!(
                        "scale must be a finite number > 0, got {value}"
                    )));
                }
                self.scene.scales.set(kind, value);
                self.rebuild()?;
            }
            Edit::SetAccuracy(acc) => {
                if let Some((problem, fix)) = acc.problem(self.scene.duration) {
                    return Err(invalid(format!("{problem}: {fix}")));
                }
                self.scene.accuracy = acc;
                self.rebuild()?;
                self.status.accuracy = acc.label();
            }
            Edit::SetControls(u) => {
                self.set_controls(&u)?;
                changed = self.values() != old_values;
            }
            Edit::Settle { budget_ms } => {
                let d = self.settle(budget_ms)?;
                notes.extend(d.into_iter().map(Note::Solver));
                changed = self.values() != old_values;
            }
            Edit::Undo => {
                let s = self.undo.pop().ok_or_else(|| invalid("nothing to undo"))?;
                let mut now = self.snapshot();
                now.label = s.label.clone();
                reverted = Some(s.label.clone());
                if let Err(e) = self.restore(s.clone()) {
                    self.undo.push(s);
                    return Err(e);
                }
                self.redo.push(now);
                self.last_delta = self.deltas(&old_values);
                changed = false;
            }
            Edit::Redo => {
                let s = self.redo.pop().ok_or_else(|| invalid("nothing to redo"))?;
                let mut now = self.snapshot();
                now.label = s.label.clone();
                reverted = Some(s.label.clone());
                if let Err(e) = self.restore(s.clone()) {
                    self.redo.push(s);
                    return Err(e);
                }
                self.undo.push(now);
                self.last_delta = self.deltas(&old_values);
                changed = false;
            }
        }
        if adds_constraint && !self.residual().is_finite() {
            // `:nail position 1e308 1e308 1e308` or `:spin 1e308`: a target
            // so far away that its distance overflows could never be shown
            // or reached. The caller restores the state.
            return Err(EditError::TargetOutOfRange);
        }
        if changed {
            self.commit(Snapshot { label, ..before }, old_values);
            self.refresh_geometry();
        }
        if let Some(paths0) = paths0
            && self.revision != revision0
            && self.paths != paths0
        {
            // The motion before this edit stays drawn until the next edit
            // that changes it.
            self.ghost = paths0;
        }
        if self.motions != motions0 || self.estimate_due {
            // The motion changed (not only a constraint on it): so may its
            // accuracy. During a drag the estimate waits until the user
            // pauses.
            if is_nudge || self.settling.is_some() {
                self.estimate_due = true;
            } else {
                self.estimate_due = false;
                notes.extend(self.estimate_error().map(Note::Accuracy));
            }
        }
        self.status.residual = self.residual();
        self.status.message = notes.last().map(ToString::to_string);
        self.edits += 1;
        if retires_drag {
            self.pending_drag = None;
            self.held = is_accept;
        }
        Ok(Outcome {
            updates: self.updates - updates0,
            elapsed_ms: started.elapsed().as_secs_f64() * 1e3,
            notes,
            anchored,
            reverted,
        })
    }
}
