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
            })
            .render(area, buf);
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
            grazing: false,
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
