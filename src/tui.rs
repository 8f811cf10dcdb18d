//! The terminal UI: key map → action → [`crate::edit::Edit`] on a
//! [`crate::edit::Core`] → pure render of a [`crate::view::View`]
//! (docs/design.md §9). The headless runner ([`crate::script`]) drives the very same
//! [`App`], key map and widgets on a `TestBackend`.
//!
//! Front door: [`run`] for the real terminal, [`event_loop`] for any
//! backend, [`App`] for the UI state, [`Screen`] for the whole-screen widget
//! and [`KEYMAP`] for the key table.

mod app;
mod camera;
mod command;
mod format;
mod key;
mod keymap;
mod layout;
mod mouse;
mod popup;
mod run;
mod session;
mod theme;
mod widgets;

#[cfg(test)]
pub(crate) mod fixtures;

pub use app::{App, Input, Level, Message, Timer, block_is_free};
pub use camera::{Camera, ViewKind};
pub use command::{Command, CommandError, parse as parse_command};
pub use format::{NOT_A_NUMBER, num as format_number};
pub use key::{KEY_NAMES, Key, KeyCode, Mods};
pub use keymap::{Action, Binding, Context, Dir, KEYMAP, Sense, help_rows, hints, lookup};
pub use mouse::{MOUSE_NAMES, Mouse, MouseKind};
pub use run::{Event, EventSource, TerminalEvents, draw, event_loop, run};
pub use session::TERMINATING;
pub use theme::Theme;
pub use widgets::{MIN_HEIGHT, MIN_WIDTH, Screen, TooSmall, buffer_text};

/// The key map as Markdown: the README's "Keys" section.
pub fn keymap_markdown() -> String {
    keymap::markdown()
}
