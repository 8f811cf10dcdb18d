//! The status line (mode, body, time, timings, residual, step, pops/blocks,
//! accuracy) and the bottom line (hints from the key map, the latest
//! message, the `:` command line or a prompt).

use crate::scene::StateQuantity;
use crate::tui::app::{App, Input, Level};
use crate::tui::format::{ms, num, scrub, truncate};
use crate::tui::keymap::{self, Context};
use crate::tui::popup::PopupKind;
use crate::view::View;
use ratatui::buffer::Buffer;
use ratatui::layout::Rect;
use ratatui::style::{Modifier, Style};
use ratatui::text::{Line, Span};
use ratatui::widgets::Widget;

/// ` POS  ball t=1.250 upd 3.1ms r=3e-9 ε=1 δ=0.01 pop 0 blk 0 rk4 h=1e-3`
#[derive(Debug, Clone, Copy)]
pub struct StatusLine<'a> {
    pub view: &'a View,
    pub app: &'a App,
}

/// The badge text of a nudge mode.
pub fn mode_label(q: StateQuantity) -> &'static str {
    match q {
        StateQuantity::Position => "POS",
        StateQuantity::Orientation => "ORI",
        StateQuantity::Velocity => "VEL",
        StateQuantity::AngularVelocity => "ANG",
    }
}

impl Widget for &StatusLine<'_> {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let (v, app) = (self.view, self.app);
        let theme = app.theme;
        let dim = theme.dim();
        let body = v.bodies.get(v.selected).map_or("—", String::as_str);
        // Segments in display order with a priority (0 = always shown):
        // on a narrow screen the least important go first, the render time
        // before the accuracy setting before the nudge step.
        let field =
            |label: &'static str, value: String| vec![Span::styled(label, dim), Span::raw(value)];
        let mut segments: Vec<(u8, Vec<Span>)> = vec![
            (
                0,
                vec![Span::styled(
                    format!(" {} ", mode_label(app.mode)),
                    theme.selected().add_modifier(Modifier::BOLD),
                )],
            ),
            (
                0,
                vec![Span::styled(
                    format!(" {}", truncate(body, 12)),
                    theme.title(),
                )],
            ),
            (0, field(" t=", num(v.time, 7))),
            (1, field(" upd ", format!("{}ms", ms(v.status.update_ms)))),
        ];
        if let (true, Some(r)) = (app.show_render_ms, app.render_ms) {
            segments.push((6, field(" draw ", format!("{}ms", ms(r)))));
        }
        segments.extend([
            (1, field(" r=", num(v.status.residual, 7))),
            (3, field(" ε=", num(v.status.step, 5))),
            (4, field(" δ=", num(app.step(), 6))),
            (
                2,
                vec![
                    Span::styled(" pop ", dim),
                    Span::raw(v.status.pops.to_string()),
                    Span::styled(" blk ", dim),
                    Span::raw(v.status.blocks.to_string()),
                ],
            ),
            (
                5,
                vec![Span::raw(format!(" {}", scrub(&v.status.accuracy)))],
            ),
        ]);
        if let Some(n) = app.count {
            segments.push((0, vec![Span::styled(format!(" {n}…"), theme.changed())]));
        }
        let width = |segs: &[(u8, Vec<Span>)]| -> usize {
            segs.iter()
                .flat_map(|(_, s)| s.iter())
                .map(|s| s.content.chars().count())
                .sum()
        };
        while width(&segments) > area.width as usize {
            let Some((k, _)) = segments
                .iter()
                .enumerate()
                .filter(|(_, (p, _))| *p > 0)
                .max_by_key(|(k, (p, _))| (*p, *k))
            else {
                break;
            };
            segments.remove(k);
        }
        Line::from(
            segments
                .into_iter()
                .flat_map(|(_, s)| s)
                .collect::<Vec<_>>(),
        )
        .render(area, buf);
    }
}

/// The bottom line.
#[derive(Debug, Clone, Copy)]
pub struct BottomLine<'a> {
    pub view: &'a View,
    pub app: &'a App,
}

impl BottomLine<'_> {
    fn hints(&self, context: Context, prefix: &str, width: usize) -> Line<'static> {
        let theme = self.app.theme;
        let room = width.saturating_sub(prefix.chars().count() + 1);
        let text = keymap::hints(context, room);
        // Style the keys of each `keys label` pair.
        let mut spans = vec![Span::raw(format!(" {prefix}"))];
        for (i, item) in text.split("  ").enumerate() {
            if i > 0 {
                spans.push(Span::raw("  "));
            }
            match item.split_once(' ') {
                Some((keys, label)) => {
                    spans.push(Span::styled(keys.to_string(), theme.key()));
                    spans.push(Span::styled(format!(" {label}"), theme.dim()));
                }
                None => spans.push(Span::raw(item.to_string())),
            }
        }
        Line::from(spans)
    }
}

impl Widget for &BottomLine<'_> {
    fn render(self, area: Rect, buf: &mut Buffer) {
        let (v, app) = (self.view, self.app);
        let theme = app.theme;
        let width = area.width as usize;
        let line = match &app.input {
            Input::Command(text) => {
                // Keep the end of a long command (where the cursor is) visible.
                let room = width.saturating_sub(2);
                let skip = text.chars().count().saturating_sub(room);
                let shown: String = text.chars().skip(skip).collect();
                Line::from(vec![
                    Span::raw(format!(":{shown}")),
                    Span::styled(" ", Style::new().add_modifier(Modifier::REVERSED)),
                ])
            }
            Input::Prompt => self.hints(Context::Prompt, "unsaved edits, quit anyway?  ", width),
            Input::Block => {
                let body = v.bodies.get(v.selected).map_or("—", String::as_str);
                self.hints(
                    Context::Block,
                    &format!("free/fix which block of {body}?  "),
                    width,
                )
            }
            Input::Popup {
                kind: PopupKind::Accuracy,
                ..
            } => self.hints(Context::Help, "Enter picks (u undoes)  ", width),
            Input::Popup { .. } => self.hints(Context::Help, "", width),
            Input::Normal => {
                let core_message = v
                    .status
                    .message
                    .as_ref()
                    .map(|m| (m.as_str(), Level::Warning));
                let busy = v.status.busy.as_deref().map(|m| (m, Level::Info));
                match busy
                    .or(app.message.as_ref().map(|m| (m.text.as_str(), m.level)))
                    .or(core_message)
                {
                    Some((text, level)) => {
                        let style = match level {
                            Level::Info => theme.info(),
                            Level::Warning => theme.changed(),
                            Level::Error => theme.error(),
                        };
                        let room = width.saturating_sub(1);
                        if text.chars().count() <= room {
                            Line::styled(format!(" {text}"), style)
                        } else {
                            // The whole message is in the log.
                            let more = " M: more";
                            let cut = truncate(text, room.saturating_sub(more.len()));
                            Line::from(vec![
                                Span::styled(format!(" {cut}"), style),
                                Span::styled(more, theme.key()),
                            ])
                        }
                    }
                    None => self.hints(app.context(), "", width),
                }
            }
        };
        line.render(area, buf);
    }
}
