//! The `:` commands as one table: each entry's names drive the parser, its
//! usage rows drive `:help`, `?` and the README, so a command cannot exist
//! in one and be missing from the others.

use super::words::Words;
use super::{Command, CommandError, MAX_SETTLE_MS, MethodName, SETTLE_MS};
use crate::edit::{Side, Vertical};
use crate::scene::ScaleKind;
use std::path::PathBuf;

/// One command: the words that name it, what it looks like and does, and
/// its parser.
pub struct CommandSpec {
    /// The command word and its aliases; the first is the one shown.
    pub names: &'static [&'static str],
    /// `(usage, what it does)` rows for the help and the README.
    pub usage: &'static [(&'static str, &'static str)],
    /// Parses the words after the command word. `rest` is the line after
    /// the command word with its spaces kept (for paths).
    pub(super) parse: fn(&Words, &str, &str) -> Result<Command, CommandError>,
}

/// Every `:` command.
pub const COMMANDS: &[CommandSpec] = &[
    CommandSpec {
        names: &["nail"],
        usage: &[(
            ":nail [qty [x y z]]...",
            "nail the body now (default: all four)",
        )],
        parse: |w, _, _| {
            let (quantities, exact) = w.targets(1)?;
            Ok(Command::Nail { quantities, exact })
        },
    },
    CommandSpec {
        names: &["float"],
        usage: &[(
            ":float [pre|post] [qty..]",
            "floating constraint at nearest collision",
        )],
        parse: |w, _, _| {
            let side = match w.get(1) {
                Some("pre") => Some(Side::Pre),
                Some("post") => Some(Side::Post),
                _ => None,
            };
            let (quantities, exact) = w.targets(if side.is_some() { 2 } else { 1 })?;
            Ok(Command::Float {
                side,
                quantities,
                exact,
            })
        },
    },
    CommandSpec {
        names: &["upright"],
        usage: &[(
            ":upright [pre|post]",
            "z axis up now (or at nearest collision)",
        )],
        parse: |w, _, _| vertical(w, Vertical::Upright),
    },
    CommandSpec {
        names: &["steady"],
        usage: &[(
            ":steady [pre|post]",
            "spin about the vertical only: no tipping",
        )],
        parse: |w, _, _| vertical(w, Vertical::Steady),
    },
    CommandSpec {
        names: &["set"],
        usage: &[
            (":set tol 1e-9", "adaptive integrator with this tolerance"),
            (":set step 1e-3", "fixed-step RK4 with this step (s)"),
            (
                ":set method rk4|adaptive",
                "switch integrator, keeping its setting",
            ),
            (":set roottol 1e-12", "collision-time tolerance (m)"),
            (
                ":set scale velocity 2",
                "scale (diagonal of M) of a control kind",
            ),
            (":set nudge 0.01", "nudge step of the current mode"),
            (
                ":set mouse on|off",
                "mouse editing; off: the terminal selects",
            ),
        ],
        parse: |w, _, _| set(w),
    },
    CommandSpec {
        names: &["free"],
        usage: &[
            (
                ":free body block",
                "free a control block (body: name or index)",
            ),
            (":free event [k]", "free the controls at event k"),
        ],
        parse: |w, _, _| free_or_fix(w, true),
    },
    CommandSpec {
        names: &["fix"],
        usage: &[
            (":fix body block", "fix a control block"),
            (":fix event [k]", "fix the controls at event k (or nearest)"),
        ],
        parse: |w, _, _| free_or_fix(w, false),
    },
    CommandSpec {
        names: &["t", "time"],
        usage: &[(":t 1.25", "go to time (s)")],
        parse: |w, _, _| {
            let t = w.non_negative(1, "time")?;
            w.no_more(2)?;
            Ok(Command::Time(t))
        },
    },
    CommandSpec {
        names: &["event"],
        usage: &[(":event 3", "go to collision event 3")],
        parse: |w, _, _| {
            let k = w.index(1, "event number")?;
            w.no_more(2)?;
            Ok(Command::Event(k))
        },
    },
    CommandSpec {
        names: &["body"],
        usage: &[(":body name", "select a body (name or index)")],
        parse: |w, _, _| {
            let b = w.need(1, "body (name or index)")?;
            w.no_more(2)?;
            Ok(Command::Body(b.to_string()))
        },
    },
    CommandSpec {
        names: &["delete", "del"],
        usage: &[(":delete 2", "delete constraint row 2")],
        parse: |w, _, _| {
            let k = w.index(1, "constraint row")?;
            w.no_more(2)?;
            Ok(Command::Delete(k))
        },
    },
    CommandSpec {
        names: &["release"],
        usage: &[(":release 2 qty..", "stop holding qty in constraint row 2")],
        parse: |w, _, _| {
            let row = w.index(1, "constraint row")?;
            if w.get(2).is_none() {
                return Err(w.err(1, "missing quantity: which to release, e.g. orientation"));
            }
            let (quantities, exact) = w.targets(2)?;
            if !exact.is_empty() {
                return Err(w.err(2, "release takes quantities only, no values"));
            }
            Ok(Command::Release { row, quantities })
        },
    },
    CommandSpec {
        names: &["messages", "mes"],
        usage: &[(":messages", "every message so far (M)")],
        parse: |w, _, _| w.no_more(1).map(|()| Command::Messages),
    },
    CommandSpec {
        names: &["jacobian", "jac"],
        usage: &[(":jacobian", "how each free control moves the body (I)")],
        parse: |w, _, _| w.no_more(1).map(|()| Command::Jacobian),
    },
    CommandSpec {
        names: &["explore"],
        usage: &[(
            ":explore [n]",
            "sample n worlds (2048) for alternatives (X)",
        )],
        parse: |w, _, _| {
            let n = match w.get(1) {
                None => crate::tui::app::EXPLORE_SAMPLES,
                Some(_) => match w.index(1, "number of worlds")? {
                    n @ 1..=MAX_EXPLORE => n,
                    _ => {
                        return Err(w.err(
                            1,
                            format!("expected a number of worlds from 1 to {MAX_EXPLORE}"),
                        ));
                    }
                },
            };
            w.no_more(2)?;
            Ok(Command::Explore(n))
        },
    },
    CommandSpec {
        names: &["accuracy", "acc"],
        usage: &[(":accuracy", "cost and error of nearby accuracies (A)")],
        parse: |w, _, _| w.no_more(1).map(|()| Command::Accuracy),
    },
    CommandSpec {
        names: &["export"],
        usage: &[(":export out.glb", "the motion as glTF (y up) for Blender")],
        parse: |w, _, rest| match path(rest) {
            Some(p) => Ok(Command::Export(p)),
            None => Err(w.err(0, "missing file: e.g. :export motion.glb")),
        },
    },
    CommandSpec {
        names: &["notes"],
        usage: &[(":notes", "the scene's notes in full")],
        parse: |w, _, _| w.no_more(1).map(|()| Command::Notes),
    },
    CommandSpec {
        names: &["speed"],
        usage: &[(":speed other", "expression: same speed as another body")],
        parse: |w, _, _| {
            let b = w.need(1, "other body (name or index)")?;
            w.no_more(2)?;
            Ok(Command::EqualSpeed(b.to_string()))
        },
    },
    CommandSpec {
        names: &["spin"],
        usage: &[(":spin 3.0", "expression: angular speed 3 rad/s")],
        parse: |w, _, _| {
            let v = w.non_negative(1, "angular speed")?;
            w.no_more(2)?;
            Ok(Command::Spin(v))
        },
    },
    CommandSpec {
        names: &["settle"],
        usage: &[(":settle [ms]", "settle (default budget 500 ms)")],
        parse: |w, _, _| {
            let ms = match w.get(1) {
                None => SETTLE_MS,
                Some(s) => match s.parse::<u64>() {
                    Ok(ms @ 1..=MAX_SETTLE_MS) => ms,
                    _ => {
                        return Err(w.err(
                            1,
                            format!(
                                "expected milliseconds, a whole number from 1 to {MAX_SETTLE_MS}"
                            ),
                        ));
                    }
                },
            };
            w.no_more(2)?;
            Ok(Command::Settle(ms))
        },
    },
    CommandSpec {
        names: &["undo", "u"],
        usage: &[(":undo", "undo the last edit")],
        parse: |w, _, _| w.no_more(1).map(|()| Command::Undo),
    },
    CommandSpec {
        names: &["redo"],
        usage: &[(":redo", "redo the last undone edit")],
        parse: |w, _, _| w.no_more(1).map(|()| Command::Redo),
    },
    CommandSpec {
        names: &["w", "write"],
        usage: &[(":w [path]", "save (to path)")],
        parse: |_, _, rest| {
            Ok(Command::Write {
                path: path(rest),
                force: false,
            })
        },
    },
    CommandSpec {
        names: &["w!", "write!"],
        usage: &[(":w! [path]", "save, even over a read-only file")],
        parse: |_, _, rest| {
            Ok(Command::Write {
                path: path(rest),
                force: true,
            })
        },
    },
    CommandSpec {
        names: &["wq", "x"],
        usage: &[(":wq [path]", "save, then quit")],
        parse: |_, _, rest| {
            Ok(Command::WriteQuit {
                path: path(rest),
                force: false,
            })
        },
    },
    CommandSpec {
        names: &["wq!", "x!"],
        usage: &[(":wq! [path]", "save (as :w!), then quit")],
        parse: |_, _, rest| {
            Ok(Command::WriteQuit {
                path: path(rest),
                force: true,
            })
        },
    },
    CommandSpec {
        names: &["q", "quit"],
        usage: &[(":q", "quit (refused with unsaved edits)")],
        parse: |w, _, _| w.no_more(1).map(|()| Command::Quit),
    },
    CommandSpec {
        names: &["q!", "quit!"],
        usage: &[(":q!", "quit, discarding unsaved edits")],
        parse: |w, _, _| w.no_more(1).map(|()| Command::ForceQuit),
    },
    CommandSpec {
        names: &["help", "h"],
        usage: &[(":help", "this help")],
        parse: |w, _, _| w.no_more(1).map(|()| Command::Help),
    },
];

/// Most worlds `:explore` samples.
const MAX_EXPLORE: usize = 1_000_000;

/// What the command arguments may be, for the help and the README.
pub const COMMAND_NOTES: &[&str] = &[
    "qty: position orientation velocity angular_velocity (pos rot vel angvel)",
    "x y z after a qty: hold it there, not at its current value; s settles",
    "block: position orientation velocity angular_velocity mass inertia",
];

/// The table entry named by `word`, if any.
pub fn lookup(word: &str) -> Option<&'static CommandSpec> {
    COMMANDS.iter().find(|c| c.names.contains(&word))
}

/// Every usage row, in table order.
pub fn usage_rows() -> impl Iterator<Item = (&'static str, &'static str)> {
    COMMANDS.iter().flat_map(|c| c.usage.iter().copied())
}

fn path(rest: &str) -> Option<PathBuf> {
    (!rest.is_empty()).then(|| PathBuf::from(rest))
}

fn vertical(w: &Words, goal: Vertical) -> Result<Command, CommandError> {
    let side = match w.get(1) {
        None => None,
        Some("pre") => Some(Side::Pre),
        Some("post") => Some(Side::Post),
        Some(_) => return Err(w.err(1, "expected pre, post or nothing")),
    };
    w.no_more(2)?;
    Ok(Command::Vertical(goal, side))
}

fn free_or_fix(w: &Words, free: bool) -> Result<Command, CommandError> {
    let is_event = w.get(1) == Some("event") && w.get(2).is_none_or(|k| k.parse::<usize>().is_ok());
    if is_event {
        let event = match w.get(2) {
            Some(_) => Some(w.index(2, "event number")?),
            None => None,
        };
        w.no_more(3)?;
        return Ok(Command::SetEventControls { event, free });
    }
    let body = w.need(1, "body (name or index)")?;
    let block = w.block(2)?;
    w.no_more(3)?;
    Ok(Command::SetBlock {
        body: body.to_string(),
        block,
        free,
    })
}

fn set(w: &Words) -> Result<Command, CommandError> {
    let what = w.need(
        1,
        "setting (tol, step, method, roottol, scale, nudge, mouse)",
    )?;
    let cmd = match what {
        "tol" => Command::SetTol(w.positive(2, "tolerance")?),
        "step" => Command::SetStep(w.positive(2, "step")?),
        "roottol" => Command::SetRootTol(w.positive(2, "tolerance")?),
        "nudge" => Command::SetNudge(w.positive(2, "nudge step")?),
        "mouse" => match w.need(2, "on or off")? {
            "on" => Command::SetMouse(true),
            "off" => Command::SetMouse(false),
            _ => return Err(w.err(2, "expected on or off")),
        },
        "method" => match w.need(2, "method (rk4 or adaptive)")? {
            "rk4" => Command::SetMethod(MethodName::Rk4),
            "adaptive" | "dopri5" => Command::SetMethod(MethodName::Adaptive),
            _ => return Err(w.err(2, "unknown method; expected rk4 or adaptive")),
        },
        "scale" => {
            let word = w.need(2, "kind of control")?;
            let Some(kind) = ScaleKind::parse(word) else {
                let names = ScaleKind::ALL.map(ScaleKind::name);
                return Err(w.err(
                    2,
                    format!("unknown kind; expected one of {}", names.join(", ")),
                ));
            };
            let value = w.positive(3, "scale")?;
            w.no_more(4)?;
            return Ok(Command::SetScale { kind, value });
        }
        _ => {
            return Err(w.err(
                1,
                "unknown setting; expected tol, step, method, roottol, scale, nudge or mouse",
            ));
        }
    };
    w.no_more(3)?;
    Ok(cmd)
}
