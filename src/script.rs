//! Headless key scripts: parse keystrokes written in vim notation and replay
//! them through the very same key map, [`App`](crate::tui::App) and widgets
//! as the terminal UI, on a ratatui `TestBackend`. This is how tests and
//! benchmarks drive an editing session (docs/design.md §1, §9).
//!
//! ```
//! use nudge::script::parse_keys;
//! let keys = parse_keys("5l <S-Left> :w<Space>out.toml<Enter>  # save", "demo.keys").unwrap();
//! assert_eq!(keys.len(), 2 + 1 + 12);
//! ```

mod keys;
mod runner;

pub use crate::tui::{Key, KeyCode, Mods};
pub use keys::{KeyScriptError, Step, known_names, parse_keys, parse_script};
pub use runner::{
    FRAME_SECONDS, Latency, Replay, RunResult, ScriptFailure, latency, run_script, run_script_with,
};
