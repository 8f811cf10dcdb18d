//! Test fixtures: a fixed synthetic [`View`] and a small fake [`Core`] that
//! records the edits it receives.

use super::app::App;
use super::theme::Theme;
use crate::edit::{Core, Edit, EditError, Outcome, Saved};
use crate::math::Vec3;
use crate::view::{
    ConstraintRow, ControlRow, EventMark, Neighbour, Path, Pose, Status, Target, View,
};
use ratatui::layout::Rect;
use std::path::{Path as FsPath, PathBuf};

fn square(c: Vec3, r: f64) -> Vec<(Vec3, Vec3)> {
    let p = [
        Vec3::new(c.x - r, c.y, c.z - r),
        Vec3::new(c.x + r, c.y, c.z - r),
        Vec3::new(c.x + r, c.y, c.z + r),
        Vec3::new(c.x - r, c.y, c.z + r),
    ];
    (0..4).map(|i| (p[i], p[(i + 1) % 4])).collect()
}

/// A ball bouncing once on a ground slab, and a box resting on it.
pub fn view() -> View {
    let ball: Vec<Vec3> = (0..=40)
        .map(|i| {
            let t = f64::from(i) / 20.0;
            let z = if t < 1.0 {
                1.0 - t * t
            } else {
                (t - 1.0) * (3.0 - t) * 0.8
            };
            Vec3::new(-1.0 + t, 0.0, z)
        })
        .collect();
    let boxp = vec![Vec3::new(1.2, 0.0, 0.15); 2];
    let mut obstacles = square(Vec3::new(0.0, 0.0, -0.1), 0.1);
    obstacles.extend([
        (Vec3::new(-1.5, 0.0, 0.0), Vec3::new(1.5, 0.0, 0.0)),
        (Vec3::new(-1.5, 0.0, -0.2), Vec3::new(1.5, 0.0, -0.2)),
    ]);
    let row = |name: &str, value: f64, delta: f64, free: bool| ControlRow {
        name: name.into(),
        value,
        delta,
        free,
        scale: 1.0,
    };
    View {
        scene: "bounce".into(),
        notes: String::new(),
        duration: 2.0,
        time: 0.8,
        bodies: vec!["ball".into(), "box".into()],
        selected: 0,
        paths: vec![
            Path {
                body: 0,
                times: times(ball.len()),
                points: ball,
            },
            Path {
                body: 1,
                times: times(boxp.len()),
                points: boxp,
            },
        ],
        obstacles,
        selected_outline: square(Vec3::new(-0.2, 0.0, 0.36), 0.08),
        body_outlines: square(Vec3::new(1.2, 0.0, 0.15), 0.15),
        events: vec![EventMark {
            index: 0,
            t: 1.0,
            point: Vec3::new(0.0, 0.0, 0.0),
            a: "ball".into(),
            b: "ground".into(),
            features: "ball on plane".into(),
            approach: 4.4,
            separation: 3.5,
            ..EventMark::default()
        }],
        ghost: Vec::new(),
        pose: Some(Pose {
            position: Vec3::new(-0.2, 0.0, 0.36),
            angle_deg: 0.0,
            axis: Vec3::z(),
            tilt_deg: 0.0,
            velocity: Vec3::new(1.0, 0.0, -2.0),
            angular_velocity: Vec3::zeros(),
            previous: None,
            next: Some(Neighbour {
                index: 0,
                t: 1.0,
                other: "ground".into(),
            }),
        }),
        targets: vec![Target {
            row: 0,
            body: 0,
            point: Vec3::new(0.7, 0.0, 0.5),
        }],
        controls: vec![
            row("ball.position.x", -0.5, 0.0, true),
            row("ball.position.z", 1.0, 0.01, true),
            row("box.mass", 2.0, 0.0, false),
            row("ball.velocity.x", 1.0, 0.0, true),
            row("ball.velocity.z", 0.0, -0.002, true),
            row("box.position.x", 1.2, 0.0, false),
        ],
        constraints: vec![ConstraintRow {
            kind: "nail".into(),
            body: "ball".into(),
            at: "t=1.500".into(),
            residual: 3.2e-9,
            gap: Some(3.2e-9),
        }],
        status: Status {
            update_ms: 3.1,
            residual: 3.2e-9,
            step: 1.0,
            pops: 0,
            blocks: 0,
            accuracy: "rk4 h=1e-3".into(),
            message: None,
            busy: None,
            integration_error: None,
        },
        dirty: false,
        accuracy: Default::default(),
    }
}

/// `n` times evenly over the fixture's 2 s.
fn times(n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| 2.0 * k as f64 / (n.max(2) - 1) as f64)
        .collect()
}

/// An App over `view` for a `w × h` terminal, plain theme, no render times.
pub fn app(view: &View, w: u16, h: u16) -> App {
    let mut app = App::new(view, Rect::new(0, 0, w, h), Theme::PLAIN);
    app.show_render_ms = false;
    app.timer = crate::tui::app::Timer::Stub;
    app
}

/// A fake core: keeps a [`View`], moves the selected body's path on
/// position nudges, and logs every edit it accepts.
#[derive(Debug, Clone)]
pub struct FakeCore {
    pub view: View,
    pub log: Vec<Edit>,
    pub dirty: bool,
    pub saved: Vec<Option<PathBuf>>,
}

pub fn core() -> FakeCore {
    FakeCore {
        view: view(),
        log: Vec::new(),
        dirty: false,
        saved: Vec::new(),
    }
}

impl Core for FakeCore {
    fn apply(&mut self, edit: Edit) -> Result<Outcome, EditError> {
        let v = &mut self.view;
        match &edit {
            Edit::SelectBody(i) if *i >= v.bodies.len() => {
                return Err(EditError::Invalid(format!("no body {i}")));
            }
            Edit::SelectBody(i) => v.selected = *i,
            Edit::SelectTime(t) => v.time = t.clamp(0.0, v.duration),
            Edit::SelectEvent(k) => match v.events.iter().find(|e| e.index == *k) {
                Some(e) => v.time = e.t,
                None => return Err(EditError::Invalid(format!("no event {k}"))),
            },
            Edit::Nudge { delta, .. } => {
                v.ghost = v.paths.clone();
                let body = v.selected;
                for p in v.paths.iter_mut().filter(|p| p.body == body) {
                    for q in &mut p.points {
                        *q += delta;
                    }
                }
                self.dirty = true;
            }
            Edit::Nail { .. } => {
                v.constraints.push(ConstraintRow {
                    kind: "nail".into(),
                    body: v.bodies[v.selected].clone(),
                    at: format!("t={:.3}", v.time),
                    residual: 0.0,
                    gap: None,
                });
                self.dirty = true;
            }
            Edit::RemoveConstraint(k) if *k >= v.constraints.len() => {
                return Err(EditError::Invalid(format!("no constraint {k}")));
            }
            Edit::RemoveConstraint(k) => {
                v.constraints.remove(*k);
                self.dirty = true;
            }
            _ => self.dirty = true,
        }
        self.log.push(edit);
        Ok(Outcome {
            updates: 1,
            elapsed_ms: 0.0,
            ..Outcome::default()
        })
    }

    fn view(&self) -> View {
        View {
            dirty: self.dirty,
            ..self.view.clone()
        }
    }

    fn save(
        &mut self,
        path: Option<&FsPath>,
        _mode: crate::files::WriteMode,
    ) -> Result<Saved, EditError> {
        self.saved.push(path.map(FsPath::to_path_buf));
        self.dirty = false;
        Ok(Saved {
            path: path.map_or_else(|| PathBuf::from("bounce.toml"), FsPath::to_path_buf),
            layout_lost: None,
        })
    }

    fn dirty(&self) -> bool {
        self.dirty
    }

    fn report(&self) -> serde_json::Value {
        serde_json::json!({ "edits": self.log.len() })
    }
}
