//! The `:` command line: a pure parser from text to [`Command`], driven by
//! the table in [`table`]. Numbers are
//! parsed strictly: `NaN`, `inf` and garbage are refused with a message that
//! quotes the bad word and says what was expected.

use crate::edit::{Side, Vertical};
use crate::math::Vec3;
use crate::scene::{Block, ScaleKind, StateQuantity};
use std::path::PathBuf;

mod table;
mod words;

use table::lookup;
pub use table::{COMMAND_NOTES, usage_rows};

/// Integrator choice for `:set method`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MethodName {
    Rk4,
    Adaptive,
}

/// A parsed `:` command.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// `:nail [quantity [x y z]]...` (no quantity: all four); a quantity
    /// followed by three numbers is held at that value, else at its
    /// current one.
    Nail {
        quantities: Vec<StateQuantity>,
        exact: Vec<(StateQuantity, Vec3)>,
    },
    /// `:float [pre|post] [quantity [x y z]]...`; `side: None` lets the
    /// editor choose from where the current time lies relative to the
    /// collision.
    Float {
        side: Option<Side>,
        quantities: Vec<StateQuantity>,
        exact: Vec<(StateQuantity, Vec3)>,
    },
    /// `:upright [pre|post]` (the body's z axis straight up) or `:steady
    /// [pre|post]` (spin about the vertical only), now or at the nearest
    /// collision (floating).
    Vertical(Vertical, Option<Side>),
    /// `:set tol X`: adaptive integrator with tolerance X.
    SetTol(f64),
    /// `:set step H`: RK4 with step H (s).
    SetStep(f64),
    /// `:set method rk4|adaptive`.
    SetMethod(MethodName),
    /// `:set roottol X` (m).
    SetRootTol(f64),
    /// `:set scale KIND X`.
    SetScale {
        kind: ScaleKind,
        value: f64,
    },
    /// `:set nudge X`: nudge step of the current mode.
    SetNudge(f64),
    /// `:free BODY BLOCK` / `:fix BODY BLOCK`; the body is a name or index.
    SetBlock {
        body: String,
        block: Block,
        free: bool,
    },
    /// `:free event [K]` / `:fix event [K]`: the controls at collision
    /// event K (default: the selected body's nearest collision).
    SetEventControls {
        event: Option<usize>,
        free: bool,
    },
    /// `:t T` (s).
    Time(f64),
    /// `:event K`.
    Event(usize),
    /// `:body NAME|INDEX`.
    Body(String),
    /// `:delete K`: remove constraint row K.
    Delete(usize),
    /// `:release K qty...`: stop holding these quantities in row K.
    Release {
        row: usize,
        quantities: Vec<StateQuantity>,
    },
    /// `:messages`: every message so far.
    Messages,
    /// `:notes`: the scene's notes in full.
    Notes,
    /// `:jacobian`: how each free control moves the body now.
    Jacobian,
    /// `:accuracy`: measure the accuracy settings around the current one.
    Accuracy,
    /// `:explore [N]`: sample N worlds in the background.
    Explore(usize),
    /// `:export PATH.glb`: the motion as binary glTF.
    Export(PathBuf),
    /// `:set mouse on|off`.
    SetMouse(bool),
    /// `:speed OTHER`: equal speed with another body.
    EqualSpeed(String),
    /// `:spin W`: angular speed equals W (rad/s).
    Spin(f64),
    /// `:settle [ms]`.
    Settle(u64),
    Undo,
    Redo,
    /// `:w [path]`, or `:w! [path]` (`force`: a read-only file too).
    Write {
        path: Option<PathBuf>,
        force: bool,
    },
    /// `:wq [path]`, or `:wq! [path]`.
    WriteQuit {
        path: Option<PathBuf>,
        force: bool,
    },
    /// `:q`.
    Quit,
    /// `:q!`.
    ForceQuit,
    /// `:help`.
    Help,
}

/// A command that could not be parsed. Prints as `:<command up to the bad
/// word>: <what was expected>`, e.g. `:set tol nan: expected a finite
/// positive number`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CommandError {
    /// The command text up to and including the offending word.
    pub at: String,
    /// What was wrong and what would be accepted.
    pub problem: String,
}

impl std::fmt::Display for CommandError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.at.is_empty() {
            f.write_str(&self.problem)
        } else {
            write!(f, ":{}: {}", self.at, self.problem)
        }
    }
}

impl std::error::Error for CommandError {}

/// Default wall-time budget of `:settle` and `s`, ms.
pub const SETTLE_MS: u64 = 500;
/// Largest `:settle` budget, ms.
pub const MAX_SETTLE_MS: u64 = 60_000;

/// Parse a command line (without the leading `:`).
pub fn parse(line: &str) -> Result<Command, CommandError> {
    let line = line.trim();
    let w = words::Words {
        words: line.split_whitespace().collect(),
    };
    let Some(name) = w.get(0) else {
        return Err(CommandError {
            at: String::new(),
            problem: "empty command; try :help".into(),
        });
    };
    let Some(spec) = lookup(name) else {
        return Err(w.err(0, "unknown command; try :help"));
    };
    // Everything after the command word, spaces kept (for paths).
    let rest = line[name.len()..].trim();
    (spec.parse)(&w, name, rest)
}

#[cfg(test)]
mod tests;
