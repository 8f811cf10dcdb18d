//! The scene canvas: obstacles, traced paths, body outlines at the current
//! time and collision events, projected by the camera onto a braille canvas.

use crate::math::Vec3;
use crate::tui::camera::Camera;
use crate::tui::theme::Theme;
use crate::view::View;
use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::Color;
use ratatui::symbols::Marker;
use ratatui::text::Span;
use ratatui::widgets::canvas::{Canvas, Context, Line, Points};
use ratatui::widgets::{Block, Widget};

/// The braille scene view, in a bordered block titled with the scene name,
/// a `[+]` when there are unsaved edits, and the view direction.
#[derive(Debug, Clone, Copy)]
pub struct SceneCanvas<'a> {
    pub view: &'a View,
    pub camera: &'a Camera,
    pub theme: Theme,
    pub playing: bool,
    /// Whether to draw the motion before the last edit.
    pub show_ghost: bool,
    /// The traces of the alternative being shown, if any.
    pub alternative: Option<&'a [crate::view::Path]>,
}

type Segment = (f64, f64, f64, f64);

/// One traced path ready to draw: colour, segments, and lone points.
struct ProjectedPath {
    color: Color,
    segments: Vec<Segment>,
    dots: Vec<(f64, f64)>,
}

impl SceneCanvas<'_> {
    fn segment(&self, a: &Vec3, b: &Vec3) -> Option<Segment> {
        let (x1, y1) = self.camera.project(a)?;
        let (x2, y2) = self.camera.project(b)?;
        Some((x1, y1, x2, y2))
    }

    fn segments(&self, segs: &[(Vec3, Vec3)]) -> Vec<Segment> {
        segs.iter()
            .filter_map(|(a, b)| self.segment(a, b))
            .collect()
    }

    fn title(&self) -> String {
        let v = self.view;
        let dirty = if v.dirty { " [+]" } else { "" };
        let playing = if self.playing { " · ▶" } else { "" };
        format!(
            " {}{dirty} · {}{playing} ",
            v.scene,
            self.camera.kind.name()
        )
    }
}

fn draw_all(ctx: &mut Context, segs: &[Segment], color: Color) {
    for &(x1, y1, x2, y2) in segs {
        ctx.draw(&Line {
            x1,
            y1,
            x2,
            y2,
            color,
        });
    }
}

impl Widget for SceneCanvas<'_> {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let theme = self.theme;
        let block = Block::bordered()
            .border_style(theme.border())
            .title(Span::styled(self.title(), theme.title()));
        let inner = block.inner(area);
        let (x_bounds, y_bounds) = self.camera.bounds(inner.width, inner.height);
        let obstacles = self.segments(&self.view.obstacles);
        let others = self.segments(&self.view.body_outlines);
        let selected = self.segments(&self.view.selected_outline);
        let mut paths: Vec<ProjectedPath> = Vec::new();
        for path in &self.view.paths {
            let color = theme.body(path.body);
            let segs: Vec<Segment> = path
                .points
                .windows(2)
                .filter_map(|w| self.segment(&w[0], &w[1]))
                .collect();
            // A path of one point (a body at rest) still shows as a dot.
            let dots = if path.points.len() == 1 {
                path.points
                    .iter()
                    .filter_map(|p| self.camera.project(p))
                    .collect()
            } else {
                Vec::new()
            };
            paths.push(ProjectedPath {
                color,
                segments: segs,
                dots,
            });
        }
        // The selected body's name beside its outline (top right), in the
        // selection style: findable without colour too.
        let label = selected
            .iter()
            .flat_map(|&(x1, y1, x2, y2)| [(x1, y1), (x2, y2)])
            .fold(None, |acc: Option<(f64, f64)>, (x, y)| {
                Some(acc.map_or((x, y), |(ax, ay)| (ax.max(x), ay.max(y))))
            });
        let name = self
            .view
            .bodies
            .get(self.view.selected)
            .cloned()
            .unwrap_or_default();
        // The motion before the last edit: every other sample as a dot, so
        // it reads as dotted beside the solid traces, with or without colour.
        let ghost: Vec<(f64, f64)> = if self.show_ghost {
            self.view
                .ghost
                .iter()
                .flat_map(|p| p.points.iter().step_by(2))
                .filter_map(|p| self.camera.project(p))
                .collect()
        } else {
            Vec::new()
        };
        // An explored alternative: every sample as a dot (denser than
        // the ghost), in the target colour.
        let alternative: Vec<(f64, f64)> = self
            .alternative
            .unwrap_or_default()
            .iter()
            .flat_map(|p| p.points.iter())
            .filter_map(|p| self.camera.project(p))
            .collect();
        let targets: Vec<(f64, f64)> = self
            .view
            .targets
            .iter()
            .filter_map(|t| self.camera.project(&t.point))
            .collect();
        let events: Vec<((f64, f64), bool)> = self
            .view
            .events
            .iter()
            .filter_map(|e| self.camera.project(&e.point).map(|p| (p, e.grazing)))
            .collect();
        Canvas::default()
            .block(block)
            .marker(Marker::Braille)
            .x_bounds(x_bounds)
            .y_bounds(y_bounds)
            .paint(|ctx| {
                draw_all(ctx, &obstacles, theme.obstacle());
                ctx.layer();
                if !ghost.is_empty() {
                    ctx.draw(&Points {
                        coords: &ghost,
                        color: theme.ghost(),
                    });
                    ctx.layer();
                }
                if !alternative.is_empty() {
                    ctx.draw(&Points {
                        coords: &alternative,
                        color: theme.alternative(),
                    });
                    ctx.layer();
                }
                for path in &paths {
                    draw_all(ctx, &path.segments, path.color);
                    if !path.dots.is_empty() {
                        ctx.draw(&Points {
                            coords: &path.dots,
                            color: path.color,
                        });
                    }
                }
                ctx.layer();
                draw_all(ctx, &others, theme.other_body());
                ctx.layer();
                draw_all(ctx, &selected, theme.selected_body());
                if let Some((x, y)) = label {
                    // One cell right of the outline, so it does not cover it.
                    let cell = (x_bounds[1] - x_bounds[0]) / f64::from(inner.width.max(1));
                    ctx.print(
                        x + cell,
                        y,
                        Span::styled(format!(" {name}"), theme.selected()),
                    );
                }
                for &((x, y), grazing) in &events {
                    ctx.print(
                        x,
                        y,
                        Span::styled(if grazing { "!" } else { "*" }, theme.event()),
                    );
                }
                for &(x, y) in &targets {
                    ctx.print(x, y, Span::styled("⊕", theme.target()));
                }
            })
            .render(area, buf);
        // The selected outline's cells, restyled after drawing.
        let cell = |x: f64, y: f64| -> Option<(u16, u16)> {
            let fx = (x - x_bounds[0]) / (x_bounds[1] - x_bounds[0]);
            let fy = (y_bounds[1] - y) / (y_bounds[1] - y_bounds[0]);
            if !((0.0..1.0).contains(&fx) && (0.0..1.0).contains(&fy)) {
                return None;
            }
            Some((
                inner.x + (fx * f64::from(inner.width)) as u16,
                inner.y + (fy * f64::from(inner.height)) as u16,
            ))
        };
        let (cw, ch) = (
            (x_bounds[1] - x_bounds[0]) / f64::from(inner.width.max(1)),
            (y_bounds[1] - y_bounds[0]) / f64::from(inner.height.max(1)),
        );
        for &(x1, y1, x2, y2) in &selected {
            let cells = ((x2 - x1) / cw).abs().max(((y2 - y1) / ch).abs());
            let n = if cells.is_finite() {
                (2.0 * cells).ceil().clamp(1.0, 4096.0) as usize
            } else {
                1
            };
            for k in 0..=n {
                let f = k as f64 / n as f64;
                if let Some(at) = cell(x1 + f * (x2 - x1), y1 + f * (y2 - y1)) {
                    buf[at].set_style(theme.selected_cells());
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tui::widgets::buffer_text;
    use crate::view::Path;

    fn horizontal_line_view() -> View {
        View {
            scene: "line".into(),
            paths: vec![Path {
                body: 0,
                points: vec![Vec3::new(-1.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0)],
                times: vec![0.0, 1.0],
            }],
            ..View::default()
        }
    }

    #[test]
    fn a_horizontal_path_is_a_row_of_braille() {
        let view = horizontal_line_view();
        let camera = Camera {
            half_height: 1.0,
            ..Camera::default()
        };
        // 10×3 inside a border: 8×1 cells, window x ∈ [−4, 4], y ∈ [−1, 1].
        let mut buf = Buffer::empty(Rect::new(0, 0, 10, 3));
        SceneCanvas {
            view: &view,
            camera: &camera,
            theme: Theme::PLAIN,
            playing: false,
            show_ghost: true,
            alternative: None,
        }
        .render(buf.area, &mut buf);
        let text = buffer_text(&buf);
        let middle = text.lines().nth(1).unwrap_or_default();
        // The line spans x ∈ [−1, 1]: a quarter of the width, centred.
        assert_eq!(middle, "│   ⠤⠤   │", "{text}");
        assert!(text.starts_with("┌ line · ┐"), "{text}");
    }

    #[test]
    fn canvas_renders_in_tiny_areas() {
        let view = horizontal_line_view();
        let camera = Camera::default();
        for (w, h) in [(0, 0), (1, 1), (2, 2), (3, 3)] {
            let mut buf = Buffer::empty(Rect::new(0, 0, w, h));
            SceneCanvas {
                view: &view,
                camera: &camera,
                theme: Theme::COLOR,
                playing: true,
                show_ghost: true,
                alternative: None,
            }
            .render(buf.area, &mut buf);
        }
    }

    #[test]
    fn events_are_marked_and_outlines_drawn() {
        let mut view = horizontal_line_view();
        view.events.push(crate::view::EventMark {
            index: 0,
            t: 0.5,
            point: Vec3::new(0.0, 0.0, -0.5),
            a: "ball".into(),
            b: "ground".into(),
            ..Default::default()
        });
        view.selected_outline = vec![(Vec3::new(-2.0, 0.0, 0.8), Vec3::new(2.0, 0.0, 0.8))];
        let camera = Camera {
            half_height: 1.0,
            ..Camera::default()
        };
        let mut buf = Buffer::empty(Rect::new(0, 0, 22, 7));
        SceneCanvas {
            view: &view,
            camera: &camera,
            theme: Theme::COLOR,
            playing: false,
            show_ghost: true,
            alternative: None,
        }
        .render(buf.area, &mut buf);
        let text = buffer_text(&buf);
        assert!(text.contains('*'), "{text}");
        let outline_row = text.lines().nth(1).unwrap_or_default();
        assert!(
            outline_row
                .chars()
                .filter(|c| ('\u{2801}'..='\u{28ff}').contains(c))
                .count()
                >= 8,
            "{text}"
        );
        // The selected outline is drawn in the selected colour.
        let cell = &buf[(10, 1)];
        assert_eq!(cell.fg, Color::White, "{text}");
    }
}
