//! The editor as the user interfaces see it: `Core`.

use super::*;

impl Core for Editor {
    fn apply(&mut self, edit: Edit) -> Result<Outcome, EditError> {
        // Only another nudge of the same drag goes on from a prefix.
        let same_drag = matches!(edit, Edit::Nudge { .. }) && self.prefix_suffices(&self.traj);
        // A settle going on in the pauses stops where it is.
        self.stop_settling();
        if !same_drag && let Err(e) = self.complete_motion() {
            self.status.message = Some(e.to_string());
            return Err(e);
        }
        let before = self.snapshot();
        let (selected, time, revision) = (self.selected, self.time, self.revision);
        let undo_len = self.undo.len();
        match self.apply_inner(edit) {
            Ok(o) => Ok(o),
            Err(e) => {
                // Atomic: put everything back as it was.
                self.selected = selected;
                self.time = time;
                self.revision = revision;
                self.undo.truncate(undo_len);
                if self.scene.bodies.len() != before.scene.bodies.len()
                    || self.constraints != before.constraints
                    || self.controls.values(&self.scene) != self.controls.values(&before.scene)
                    || self.scene.event_controls != before.scene.event_controls
                {
                    let _ = self.restore(before);
                } else {
                    self.scene = before.scene;
                    self.constraints = before.constraints;
                    let _ = self.rebuild();
                }
                self.status.message = Some(e.to_string());
                Err(e)
            }
        }
    }

    fn view(&self) -> View {
        let _span = crate::profile::span(crate::profile::Part::View);
        let events = self
            .traj
            .events
            .iter()
            .map(|e| self.event_mark(e))
            .collect();
        let controls = self
            .controls
            .entries
            .iter()
            .enumerate()
            .map(|(i, e)| view::ControlRow {
                name: e.name.clone(),
                value: self.controls.get(&self.scene, i),
                delta: self.last_delta.get(i).copied().unwrap_or(0.0),
                free: e.free,
                scale: e.scale,
            })
            .collect();
        let targets = self.position_targets();
        let constraints = self.constraint_rows_with(&targets);
        let others = (0..self.scene.bodies.len())
            .filter(|&i| i != self.selected)
            .flat_map(|i| self.body_lines(i))
            .collect();
        View {
            scene: self.scene.name.clone(),
            notes: self.scene.notes.clone(),
            duration: self.scene.duration,
            time: self.time,
            bodies: self.scene.bodies.iter().map(|b| b.name.clone()).collect(),
            selected: self.selected,
            paths: self.paths.clone(),
            ghost: self.ghost.clone(),
            pose: self.pose(),
            targets: targets.into_iter().map(|(t, _)| t).collect(),
            obstacles: self.obstacle_lines.clone(),
            selected_outline: if self.scene.bodies.is_empty() {
                Vec::new()
            } else {
                self.body_lines(self.selected)
            },
            body_outlines: others,
            events,
            controls,
            constraints,
            status: self.shown_status(),
            dirty: self.dirty(),
            accuracy: self.scene.accuracy,
        }
    }

    fn save(&mut self, path: Option<&Path>, mode: WriteMode) -> Result<Saved, EditError> {
        let target = path
            .map(Path::to_path_buf)
            .or_else(|| self.path.clone())
            .ok_or_else(|| {
                EditError::Save(format!(
                    "this scene has no file yet: give one, e.g. :w {}.toml",
                    self.scene.name
                ))
            })?;
        // A relative mesh path names a file beside the scene: saving into
        // another folder would leave the new file without its meshes.
        let folder = |p: &Path| p.parent().map(Path::to_path_buf).unwrap_or_default();
        let new_dir = folder(&target);
        if self.path.as_deref().map(folder) != Some(new_dir.clone()) {
            let missing: Vec<String> = scene::mesh_files(&self.scene)
                .into_iter()
                .filter(|f| !Path::new(f).is_absolute() && !new_dir.join(f).is_file())
                .collect();
            if let Some(first) = missing.first() {
                return Err(EditError::Save(format!(
                    "{} would name the mesh {first} relative to its own folder, where there is none: save beside the scene, or copy its meshes there first",
                    target.display()
                )));
            }
        }
        let layout_lost =
            scene::save(&self.scene_to_save(), &target, mode).map_err(|e| match e {
                WriteError::ReadOnly { path } => EditError::ReadOnly(path),
                WriteError::NotRegular { path, kind } => EditError::NotRegular {
                    path,
                    kind,
                    suggest: format!("{}.toml", plain_name(&self.scene.name)),
                },
                other => EditError::Save(other.to_string()),
            })?;
        self.path = Some(target.clone());
        self.saved_revision = self.revision;
        Ok(Saved {
            path: target,
            layout_lost,
        })
    }

    fn dirty(&self) -> bool {
        self.revision != self.saved_revision
    }

    fn export_gltf(&self, path: &Path, fps: f64) -> Result<usize, EditError> {
        // A nudge's prefix is not the motion to export: the whole one is.
        let whole;
        let traj = if self.motion_due {
            whole = simulate_with_tangent(&self.scene, &self.controls)?;
            &whole
        } else {
            &self.traj
        };
        let bytes = crate::export::to_glb(&self.scene, traj, fps)
            .map_err(|e| EditError::Save(e.to_string()))?;
        std::fs::write(path, &bytes)
            .map_err(|e| EditError::Save(format!("{}: {e}", path.display())))?;
        Ok(bytes.len())
    }

    fn explore_start(&self) -> Option<crate::explore::Start> {
        Some(crate::explore::Start::from_editor(self))
    }

    fn idle(&mut self) -> bool {
        // First the rest of a nudged motion, then (at the next pause) its
        // error estimate: each is one frame's worth of waiting at most.
        match self.complete_motion() {
            Ok(true) => return true,
            Ok(false) => {}
            Err(e) => {
                self.estimate_due = false;
                self.status.message = Some(e.to_string());
                return true;
            }
        }
        if let Some(changed) = self.settle_in_pause() {
            return changed;
        }
        if !self.estimate_due {
            return false;
        }
        self.estimate_due = false;
        let note = self.estimate_error();
        if note.is_some() {
            self.status.message = note;
        }
        true
    }

    fn stop(&mut self) -> Option<String> {
        self.stop_settling()
    }

    fn sensitivity(&self) -> Result<view::Sensitivity, String> {
        let body = self
            .scene
            .bodies
            .get(self.selected)
            .ok_or("the scene has no bodies")?;
        if self.controls.m() == 0 {
            return Err(format!(
                "no free controls: free a block of {} first (b then p/o/v/w)",
                body.name
            ));
        }
        let j = self
            .traj
            .jacobian(self.selected, self.time, Side::Post)
            .map_err(|e| format!("no Jacobian for {} at this time: {e}", body.name))?;
        let mut rows: Vec<view::SensitivityRow> = self
            .controls
            .free
            .iter()
            .enumerate()
            .map(|(col, &entry)| view::SensitivityRow {
                control: self.controls.entries[entry].name.clone(),
                position: Vec3::new(j[(0, col)], j[(1, col)], j[(2, col)]),
                orientation: Vec3::new(j[(3, col)], j[(4, col)], j[(5, col)]),
            })
            .collect();
        // The controls that move the body at all first, the body's own
        // before the others' (a stable sort keeps the panel's order).
        let own = format!("{}.", body.name);
        rows.sort_by_key(|r| {
            let still = r.position.norm() == 0.0 && r.orientation.norm() == 0.0;
            (still, !r.control.starts_with(&own))
        });
        Ok(view::Sensitivity {
            body: body.name.clone(),
            t: self.time,
            rows,
        })
    }

    fn report(&self) -> serde_json::Value {
        let rows = self.constraint_rows();
        let mut v = report::summary(
            &self.scene,
            &self.controls,
            &self.traj,
            &rows,
            &self.status.message.iter().cloned().collect::<Vec<_>>(),
        );
        let mut times = self.update_ms.clone();
        times.sort_by(f64::total_cmp);
        let pick = |q: f64| {
            if times.is_empty() {
                0.0
            } else {
                times[((times.len() - 1) as f64 * q).round() as usize]
            }
        };
        if let Some(o) = v.as_object_mut() {
            o.insert("edits".into(), serde_json::json!(self.edits));
            o.insert("updates".into(), serde_json::json!(self.updates));
            o.insert("update_ms".into(), serde_json::json!({"median": report::num(pick(0.5)), "p95": report::num(pick(0.95)), "max": report::num(times.last().copied().unwrap_or(0.0))}));
            o.insert("residual".into(), report::num(self.residual()));
            if let Some(e) = self.status.integration_error {
                let [p, r, v, w] = e.map(report::num);
                o.insert(
                    "integration_error".into(),
                    serde_json::json!({"position": p, "orientation": r, "velocity": v, "angular_velocity": w}),
                );
            }
        }
        v
    }
}

/// `name` if it is plain enough to offer as a file name on the status
/// line (ASCII letters, digits, `-` and `_`), else "scene".
fn plain_name(name: &str) -> &str {
    let plain = |c: char| c.is_ascii_alphanumeric() || c == '-' || c == '_';
    if !name.is_empty() && name.chars().all(plain) {
        name
    } else {
        "scene"
    }
}
