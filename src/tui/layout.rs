//! Where things are on the screen: the areas of the main screen and of a
//! popup for a terminal of a given size. Both the App (mouse hits, popup
//! scrolling, camera fitting) and the widgets (drawing) read it, so neither
//! imports the other for geometry.
//!
//! Layout at 80×24 (the design size):
//!
//! ```text
//! ┌ scene · front ─────────────────────────────┐─ egg1 t=1.250 ─────────────
//! │ braille canvas: obstacles, paths, ghost,    │ pose readout (6 rows)
//! │ targets, bodies, events                     │─ controls ────────────────
//! │                                             │ ● egg1 vel.x  1.25  +0.01
//! │                                             │─ constraints ─────────────
//! └─────────────────────────────────────────────┘▸nail  egg1  t=1.25  3e-9
//!  1.250 ─────────┼──────●───────┼──────────── 3.000   ← timeline
//!  POS  ball  t=1.250  upd 3.1ms  r=3e-9 …                ← status
//!  hjkl nudge  [] time  …     (or the message / : command line)
//! ```

use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::widgets::Block;

/// Smallest terminal the editor draws in; below it a notice is shown.
pub const MIN_WIDTH: u16 = 60;
pub const MIN_HEIGHT: u16 = 16;

/// The screen's areas.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Areas {
    /// The scene canvas, border included.
    pub canvas: Rect,
    /// The side panel (readout, controls, constraints).
    pub side: Rect,
    pub timeline: Rect,
    pub status: Rect,
    /// Hints, messages, the command line or a prompt.
    pub bottom: Rect,
}

/// Split the terminal area. The side panel is 35% of the width, 24 to 44
/// columns (28 at 80 columns).
pub fn areas(area: Rect) -> Areas {
    let [main, timeline, status, bottom] = area.layout(&Layout::vertical([
        Constraint::Fill(1),
        Constraint::Length(1),
        Constraint::Length(1),
        Constraint::Length(1),
    ]));
    let side_w = (u32::from(area.width) * 35 / 100).clamp(24, 44) as u16;
    let [canvas, side] = main.layout(&Layout::horizontal([
        Constraint::Fill(1),
        Constraint::Length(side_w),
    ]));
    Areas {
        canvas,
        side,
        timeline,
        status,
        bottom,
    }
}

/// The side panel split into the pose readout, the controls and the
/// constraints (with `constraint_rows` rows).
pub fn side(side: Rect, constraint_rows: usize) -> [Rect; 3] {
    let readout = match side.height {
        18.. => 7,
        14..18 => 6,
        _ => 0,
    };
    let rows = constraint_rows.max(1) as u16;
    side.layout(&Layout::vertical([
        Constraint::Length(readout),
        Constraint::Fill(1),
        Constraint::Length((rows + 1).min(side.height / 3).max(2)),
    ]))
}

/// The drawable inside of the canvas for a terminal of `area`.
pub fn canvas_inner(area: Rect) -> Rect {
    Block::bordered().inner(areas(area).canvas)
}

/// Whether `area` is below the minimum size.
pub fn too_small(area: Rect) -> bool {
    area.width < MIN_WIDTH || area.height < MIN_HEIGHT
}

/// Where a popup sits on a screen of `area`, border included.
pub fn popup(area: Rect) -> Rect {
    let width = area.width.saturating_sub(4).min(100);
    let height = area.height.saturating_sub(2);
    Rect {
        x: area.x + (area.width - width) / 2,
        y: area.y + (area.height - height) / 2,
        width,
        height,
    }
}

/// The text area inside the popup.
pub fn popup_inner(area: Rect) -> Rect {
    Block::bordered().inner(popup(area))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn at_80x24_the_side_panel_is_28_columns_with_a_readout() {
        let a = areas(Rect::new(0, 0, 80, 24));
        assert_eq!(a.side.width, 28);
        assert_eq!(a.canvas, Rect::new(0, 0, 52, 21));
        assert_eq!((a.timeline.y, a.status.y, a.bottom.y), (21, 22, 23));
        let [readout, controls, constraints] = side(a.side, 2);
        assert_eq!(readout.height, 7);
        assert!(controls.height >= 8, "{controls:?}");
        assert_eq!(constraints.height, 3);
    }
}
