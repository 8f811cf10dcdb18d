//! The `:` command line: a pure parser from text to [`Command`]. Numbers are
//! parsed strictly: `NaN`, `inf` and garbage are refused with a message that
//! quotes the bad word and says what was expected.

use crate::edit::{Side, Vertical};
use crate::math::Vec3;
use crate::scene::{Block, ScaleKind, StateQuantity};
use std::path::PathBuf;

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

struct Words<'a> {
    words: Vec<&'a str>,
}

impl<'a> Words<'a> {
    /// Error at word `i` (inclusive).
    fn err(&self, i: usize, problem: impl Into<String>) -> CommandError {
        let end = (i + 1).min(self.words.len());
        CommandError {
            at: self.words[..end].join(" "),
            problem: problem.into(),
        }
    }

    fn get(&self, i: usize) -> Option<&'a str> {
        self.words.get(i).copied()
    }

    /// Word `i`, or an error naming what is missing.
    fn need(&self, i: usize, what: &str) -> Result<&'a str, CommandError> {
        self.get(i)
            .ok_or_else(|| self.err(i, format!("missing {what}")))
    }

    fn no_more(&self, i: usize) -> Result<(), CommandError> {
        match self.get(i) {
            Some(_) => Err(self.err(i, "unexpected extra argument")),
            None => Ok(()),
        }
    }

    fn positive(&self, i: usize, what: &str) -> Result<f64, CommandError> {
        let w = self.need(i, what)?;
        match w.parse::<f64>() {
            Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
            _ => Err(self.err(i, "expected a finite positive number")),
        }
    }

    fn non_negative(&self, i: usize, what: &str) -> Result<f64, CommandError> {
        let w = self.need(i, what)?;
        match w.parse::<f64>() {
            Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
            _ => Err(self.err(i, "expected a finite number ≥ 0")),
        }
    }

    fn index(&self, i: usize, what: &str) -> Result<usize, CommandError> {
        let w = self.need(i, what)?;
        w.parse::<usize>().map_err(|_| {
            self.err(
                i,
                format!("expected {what} as a whole number (0, 1, 2, ...)"),
            )
        })
    }

    /// `quantity [x y z]` pairs from word `from` on: the quantities (all
    /// four if none) and the values typed for some of them.
    #[allow(clippy::type_complexity)]
    fn targets(
        &self,
        from: usize,
    ) -> Result<(Vec<StateQuantity>, Vec<(StateQuantity, Vec3)>), CommandError> {
        let mut out = Vec::new();
        let mut exact = Vec::new();
        let mut i = from;
        while i < self.words.len() {
            let q = parse_quantity(self.words[i]).ok_or_else(|| {
                self.err(i, "unknown quantity; expected position, orientation, velocity or angular_velocity")
            })?;
            if out.contains(&q) {
                return Err(self.err(i, format!("{} is given twice", q.name())));
            }
            out.push(q);
            i += 1;
            let number = |w: &str| w.parse::<f64>().ok();
            if self.get(i).and_then(number).is_some() {
                let mut v = Vec3::zeros();
                for k in 0..3 {
                    let w = self.get(i + k).ok_or_else(|| {
                        self.err(
                            i + k - 1,
                            format!("expected three numbers x y z after {}", q.name()),
                        )
                    })?;
                    v[k] = match number(w) {
                        Some(x) if x.is_finite() => x,
                        _ => return Err(self.err(i + k, "expected a finite number")),
                    };
                }
                exact.push((q, v));
                i += 3;
            }
        }
        if out.is_empty() {
            out = StateQuantity::ALL.to_vec();
        }
        Ok((out, exact))
    }

    fn block(&self, i: usize) -> Result<Block, CommandError> {
        let w = self.need(i, "block")?;
        parse_block(w).ok_or_else(|| {
            self.err(i, "unknown block; expected position, orientation, velocity, angular_velocity, mass or inertia")
        })
    }
}

/// A quantity by name or short name.
pub fn parse_quantity(word: &str) -> Option<StateQuantity> {
    Some(match word.to_ascii_lowercase().as_str() {
        "position" | "pos" | "x" => StateQuantity::Position,
        "orientation" | "rot" | "r" => StateQuantity::Orientation,
        "velocity" | "vel" | "v" => StateQuantity::Velocity,
        "angular_velocity" | "angvel" | "omega" | "w" => StateQuantity::AngularVelocity,
        _ => return None,
    })
}

/// A control block by name or short name.
pub fn parse_block(word: &str) -> Option<Block> {
    let lower = word.to_ascii_lowercase();
    Block::parse(&lower).or(match lower.as_str() {
        "pos" | "x" => Some(Block::Position),
        "rot" | "r" => Some(Block::Orientation),
        "vel" | "v" => Some(Block::Velocity),
        "angvel" | "omega" | "w" => Some(Block::AngularVelocity),
        "m" => Some(Block::Mass),
        "i" => Some(Block::Inertia),
        _ => None,
    })
}

/// Parse a command line (without the leading `:`).
pub fn parse(line: &str) -> Result<Command, CommandError> {
    let line = line.trim();
    let w = Words {
        words: line.split_whitespace().collect(),
    };
    let Some(name) = w.get(0) else {
        return Err(CommandError {
            at: String::new(),
            problem: "empty command; try :help".into(),
        });
    };
    // Everything after the command word, spaces kept (for paths).
    let rest = line[name.len()..].trim();
    let path = (!rest.is_empty()).then(|| PathBuf::from(rest));
    let cmd = match name {
        "nail" => {
            let (quantities, exact) = w.targets(1)?;
            Command::Nail { quantities, exact }
        }
        "float" => {
            let side = match w.get(1) {
                Some("pre") => Some(Side::Pre),
                Some("post") => Some(Side::Post),
                _ => None,
            };
            let (quantities, exact) = w.targets(if side.is_some() { 2 } else { 1 })?;
            Command::Float {
                side,
                quantities,
                exact,
            }
        }
        word @ ("upright" | "steady") => {
            let goal = if word == "upright" {
                Vertical::Upright
            } else {
                Vertical::Steady
            };
            let side = match w.get(1) {
                None => None,
                Some("pre") => Some(Side::Pre),
                Some("post") => Some(Side::Post),
                Some(_) => return Err(w.err(1, "expected pre, post or nothing")),
            };
            w.no_more(2)?;
            Command::Vertical(goal, side)
        }
        "set" => {
            let what = w.need(1, "setting (tol, step, method, roottol, scale, nudge)")?;
            let cmd = match what {
                "tol" => Command::SetTol(w.positive(2, "tolerance")?),
                "step" => Command::SetStep(w.positive(2, "step")?),
                "roottol" => Command::SetRootTol(w.positive(2, "tolerance")?),
                "nudge" => Command::SetNudge(w.positive(2, "nudge step")?),
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
                        "unknown setting; expected tol, step, method, roottol, scale or nudge",
                    ));
                }
            };
            w.no_more(3)?;
            cmd
        }
        "free" | "fix"
            if w.get(1) == Some("event") && w.get(2).is_none_or(|k| k.parse::<usize>().is_ok()) =>
        {
            let event = match w.get(2) {
                Some(_) => Some(w.index(2, "event number")?),
                None => None,
            };
            w.no_more(3)?;
            Command::SetEventControls {
                event,
                free: name == "free",
            }
        }
        "free" | "fix" => {
            let body = w.need(1, "body (name or index)")?;
            let block = w.block(2)?;
            w.no_more(3)?;
            Command::SetBlock {
                body: body.to_string(),
                block,
                free: name == "free",
            }
        }
        "t" | "time" => {
            let t = w.non_negative(1, "time")?;
            w.no_more(2)?;
            Command::Time(t)
        }
        "event" => {
            let k = w.index(1, "event number")?;
            w.no_more(2)?;
            Command::Event(k)
        }
        "body" => {
            let b = w.need(1, "body (name or index)")?;
            w.no_more(2)?;
            Command::Body(b.to_string())
        }
        "delete" | "del" => {
            let k = w.index(1, "constraint row")?;
            w.no_more(2)?;
            Command::Delete(k)
        }
        "speed" => {
            let b = w.need(1, "other body (name or index)")?;
            w.no_more(2)?;
            Command::EqualSpeed(b.to_string())
        }
        "spin" => {
            let v = w.non_negative(1, "angular speed")?;
            w.no_more(2)?;
            Command::Spin(v)
        }
        "settle" => {
            let ms =
                match w.get(1) {
                    None => SETTLE_MS,
                    Some(s) => match s.parse::<u64>() {
                        Ok(ms @ 1..=MAX_SETTLE_MS) => ms,
                        _ => return Err(w.err(
                            1,
                            format!(
                                "expected milliseconds, a whole number from 1 to {MAX_SETTLE_MS}"
                            ),
                        )),
                    },
                };
            w.no_more(2)?;
            Command::Settle(ms)
        }
        "undo" | "u" => Command::Undo,
        "redo" => Command::Redo,
        "w" | "write" => Command::Write { path, force: false },
        "w!" | "write!" => Command::Write { path, force: true },
        "wq" | "x" => Command::WriteQuit { path, force: false },
        "wq!" | "x!" => Command::WriteQuit { path, force: true },
        "q" | "quit" => {
            w.no_more(1)?;
            Command::Quit
        }
        "q!" | "quit!" => Command::ForceQuit,
        "help" | "h" => Command::Help,
        _ => return Err(w.err(0, "unknown command; try :help")),
    };
    if matches!(
        cmd,
        Command::Undo | Command::Redo | Command::Help | Command::ForceQuit
    ) {
        w.no_more(1)?;
    }
    Ok(cmd)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(line: &str) -> String {
        match parse(line) {
            Ok(c) => panic!("{line} parsed as {c:?}"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn numbers_are_strict() {
        assert_eq!(
            err("set tol nan"),
            ":set tol nan: expected a finite positive number"
        );
        assert_eq!(
            err("set tol inf"),
            ":set tol inf: expected a finite positive number"
        );
        assert_eq!(
            err("set tol -1e-9"),
            ":set tol -1e-9: expected a finite positive number"
        );
        assert_eq!(
            err("set step 1e-3x"),
            ":set step 1e-3x: expected a finite positive number"
        );
        assert_eq!(
            err("set scale velocity NaN"),
            ":set scale velocity NaN: expected a finite positive number"
        );
        assert_eq!(
            err("t infinity"),
            ":t infinity: expected a finite number ≥ 0"
        );
        assert_eq!(
            err("settle 0"),
            ":settle 0: expected milliseconds, a whole number from 1 to 60000"
        );
        assert_eq!(
            err("event -1"),
            ":event -1: expected event number as a whole number (0, 1, 2, ...)"
        );
        assert_eq!(err("set tol"), ":set tol: missing tolerance");
        assert_eq!(
            err("nail pos 1 0"),
            ":nail pos 1 0: expected three numbers x y z after position"
        );
        assert_eq!(
            err("nail pos 1 nan 0"),
            ":nail pos 1 nan: expected a finite number"
        );
        assert_eq!(
            err("float pre vel 1 2 inf"),
            ":float pre vel 1 2 inf: expected a finite number"
        );
        assert_eq!(
            err("nail pos pos"),
            ":nail pos pos: position is given twice"
        );
        assert_eq!(
            err("nail pos 1 2 3 4"),
            ":nail pos 1 2 3 4: unknown quantity; expected position, orientation, velocity or angular_velocity"
        );
    }

    #[test]
    fn good_commands_parse() {
        use StateQuantity::*;
        assert_eq!(
            parse("nail"),
            Ok(Command::Nail {
                quantities: StateQuantity::ALL.to_vec(),
                exact: vec![]
            })
        );
        assert_eq!(
            parse("nail position velocity"),
            Ok(Command::Nail {
                quantities: vec![Position, Velocity],
                exact: vec![]
            })
        );
        assert_eq!(
            parse("nail pos 1 0 0.56 rot"),
            Ok(Command::Nail {
                quantities: vec![Position, Orientation],
                exact: vec![(Position, Vec3::new(1.0, 0.0, 0.56))]
            })
        );
        assert_eq!(
            parse("float post pos"),
            Ok(Command::Float {
                side: Some(Side::Post),
                quantities: vec![Position],
                exact: vec![]
            })
        );
        assert_eq!(
            parse("float post angvel 0 0 0 orientation -1e-3 2 0"),
            Ok(Command::Float {
                side: Some(Side::Post),
                quantities: vec![AngularVelocity, Orientation],
                exact: vec![
                    (AngularVelocity, Vec3::zeros()),
                    (Orientation, Vec3::new(-1e-3, 2.0, 0.0))
                ]
            })
        );
        assert_eq!(
            parse("float"),
            Ok(Command::Float {
                side: None,
                quantities: StateQuantity::ALL.to_vec(),
                exact: vec![]
            })
        );
        assert_eq!(
            parse("upright"),
            Ok(Command::Vertical(Vertical::Upright, None))
        );
        assert_eq!(
            parse("upright pre"),
            Ok(Command::Vertical(Vertical::Upright, Some(Side::Pre)))
        );
        assert_eq!(
            parse("steady post"),
            Ok(Command::Vertical(Vertical::Steady, Some(Side::Post)))
        );
        assert_eq!(parse("set tol 1e-9"), Ok(Command::SetTol(1e-9)));
        assert_eq!(parse("set step 1e-3"), Ok(Command::SetStep(1e-3)));
        assert_eq!(
            parse("set method adaptive"),
            Ok(Command::SetMethod(MethodName::Adaptive))
        );
        assert_eq!(
            parse("set scale velocity 2"),
            Ok(Command::SetScale {
                kind: ScaleKind::Velocity,
                value: 2.0
            })
        );
        assert_eq!(
            parse("free ball angular_velocity"),
            Ok(Command::SetBlock {
                body: "ball".into(),
                block: Block::AngularVelocity,
                free: true
            })
        );
        assert_eq!(
            parse("fix 0 mass"),
            Ok(Command::SetBlock {
                body: "0".into(),
                block: Block::Mass,
                free: false
            })
        );
        assert_eq!(
            parse("fix event"),
            Ok(Command::SetEventControls {
                event: None,
                free: false
            })
        );
        assert_eq!(
            parse("free event 3"),
            Ok(Command::SetEventControls {
                event: Some(3),
                free: true
            })
        );
        assert_eq!(
            err("fix event 3 4"),
            ":fix event 3 4: unexpected extra argument"
        );
        assert_eq!(parse("  t 1.25 "), Ok(Command::Time(1.25)));
        assert_eq!(parse("event 3"), Ok(Command::Event(3)));
        assert_eq!(parse("settle"), Ok(Command::Settle(SETTLE_MS)));
        assert_eq!(parse("settle 200"), Ok(Command::Settle(200)));
        assert_eq!(
            parse("w"),
            Ok(Command::Write {
                path: None,
                force: false
            })
        );
        assert_eq!(
            parse("w! ro.toml"),
            Ok(Command::Write {
                path: Some("ro.toml".into()),
                force: true
            })
        );
        assert_eq!(
            parse("wq!"),
            Ok(Command::WriteQuit {
                path: None,
                force: true
            })
        );
        assert_eq!(
            parse("w my scene.toml"),
            Ok(Command::Write {
                path: Some("my scene.toml".into()),
                force: false
            })
        );
        assert_eq!(
            parse("wq out.toml"),
            Ok(Command::WriteQuit {
                path: Some("out.toml".into()),
                force: false
            })
        );
        assert_eq!(parse("q"), Ok(Command::Quit));
        assert_eq!(parse("q!"), Ok(Command::ForceQuit));
        assert_eq!(parse("help"), Ok(Command::Help));
    }

    #[test]
    fn unknown_words_are_named() {
        assert_eq!(err("fly"), ":fly: unknown command; try :help");
        assert_eq!(err(""), "empty command; try :help");
        assert_eq!(
            err("nail position speed"),
            ":nail position speed: unknown quantity; expected position, orientation, velocity or angular_velocity"
        );
        assert_eq!(
            err("set method euler"),
            ":set method euler: unknown method; expected rk4 or adaptive"
        );
        assert_eq!(
            err("set tol 1e-9 1e-8"),
            ":set tol 1e-9 1e-8: unexpected extra argument"
        );
        assert!(
            err("set scale spin 2")
                .starts_with(":set scale spin: unknown kind; expected one of position")
        );
        assert!(err("free ball wings").starts_with(":free ball wings: unknown block"));
        assert_eq!(err("free"), ":free: missing body (name or index)");
        assert_eq!(
            err("upright later"),
            ":upright later: expected pre, post or nothing"
        );
    }
}
