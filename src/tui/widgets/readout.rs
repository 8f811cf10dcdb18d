//! The pose readout: the selected body at the current time (position,
//! velocity, angular velocity, rotation and tilt), its collisions on either
//! side, and how far it is from the selected constraint's target.

use crate::tui::format::{num, truncate};
use crate::tui::theme::Theme;
use crate::view::{Neighbour, View};
use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::text::{Line, Span};
use ratatui::widgets::{Block, Borders, Widget};

/// The readout panel.
#[derive(Debug, Clone, Copy)]
pub struct Readout<'a> {
    pub view: &'a View,
    pub theme: Theme,
    /// The selected constraint row.
    pub selected: usize,
}

/// `y`, `-z`, or the axis's components when it is not along one.
fn axis_name(a: &crate::math::Vec3, width: usize) -> String {
    for (k, name) in ["x", "y", "z"].iter().enumerate() {
        if a[k] > 1.0 - 1e-6 {
            return (*name).to_string();
        }
        if a[k] < -(1.0 - 1e-6) {
            return format!("-{name}");
        }
    }
    let w = width.clamp(4, 6);
    format!("({} {} {})", num(a.x, w), num(a.y, w), num(a.z, w))
}

impl Readout<'_> {
    /// The readout's lines for a panel `width` wide.
    pub fn lines(&self, width: usize) -> Vec<Line<'static>> {
        let theme = self.theme;
        let Some(p) = &self.view.pose else {
            return vec![Line::styled("no state to show", theme.dim())];
        };
        let w = ((width.saturating_sub(4)) / 3).clamp(5, 10);
        let vec3 = |label: &str, v: &crate::math::Vec3, unit: &str| {
            // Components at round-off of the largest read 0 (a throw in
            // the x-z plane has y = 3e-50, not worth a column).
            let big = v.amax();
            let v = v.map(|c| if c.abs() <= 1e-12 * big { 0.0 } else { c });
            let mut text = format!("{} {} {}", num(v.x, w), num(v.y, w), num(v.z, w));
            if text.chars().count() + label.chars().count() + 1 + unit.len() < width {
                text.push(' ');
                text.push_str(unit);
            }
            Line::from(vec![
                Span::styled(format!("{label:<4}"), theme.dim()),
                Span::raw(text),
            ])
        };
        let neighbour = |mark: &str, n: &Option<Neighbour>| match n {
            Some(n) => format!("{mark}{} {}", num(n.t, 5), truncate(&n.other, 9)),
            None => format!("{mark}none"),
        };
        let room = width.saturating_sub(4);
        let (angle, axis, tilt) = (
            num(p.angle_deg, 5),
            axis_name(&p.axis, w),
            num(p.tilt_deg, 4),
        );
        let long = format!("{angle}° about {axis}, tilt {tilt}°");
        let rot = if long.chars().count() <= room {
            long
        } else {
            format!("{angle}°@{axis} tilt {tilt}°")
        };
        let mut lines = vec![
            vec3("pos", &p.position, "m"),
            vec3("vel", &p.velocity, "m/s"),
            vec3("ω", &p.angular_velocity, "rad/s"),
            Line::from(vec![
                Span::styled("rot ", theme.dim()),
                Span::raw(truncate(&rot, width.saturating_sub(4))),
            ]),
            // The collisions either side: ◂ before, ▸ after.
            Line::raw(truncate(
                &format!(
                    "{} {}",
                    neighbour("◂", &p.previous),
                    neighbour("▸", &p.next)
                ),
                width,
            )),
        ];
        let row = self.view.constraints.get(self.selected);
        if let Some((row, gap)) = row.and_then(|r| r.gap.map(|g| (r, g))) {
            lines.push(Line::from(vec![
                Span::styled("gap ", theme.dim()),
                Span::raw(truncate(
                    &format!("{} m to {}", num(gap, 7), row.kind),
                    width.saturating_sub(4),
                )),
            ]));
        }
        lines
    }
}

impl Widget for &Readout<'_> {
    fn render(self, area: Rect, buf: &mut Buffer) {
        if area.is_empty() {
            return;
        }
        let v = self.view;
        let body = v.bodies.get(v.selected).map_or("—", String::as_str);
        let title = format!(" {} t={} ", truncate(body, 12), num(v.time, 6));
        let block = Block::new()
            .borders(Borders::TOP)
            .border_style(self.theme.border())
            .title(Span::styled(title, self.theme.selected()));
        let inner = block.inner(area);
        block.render(area, buf);
        for (k, line) in self
            .lines(inner.width as usize)
            .into_iter()
            .take(inner.height as usize)
            .enumerate()
        {
            line.render(
                Rect {
                    y: inner.y + k as u16,
                    height: 1,
                    ..inner
                },
                buf,
            );
        }
    }
}
