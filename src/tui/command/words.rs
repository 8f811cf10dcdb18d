//! Words of a command line and the strict readers of numbers, quantities
//! and blocks that every command's parser shares.

use super::CommandError;
use crate::math::Vec3;
use crate::scene::{Block, StateQuantity};

/// A command line split at whitespace, with errors that quote the line up
/// to the offending word.
pub(super) struct Words<'a> {
    pub(super) words: Vec<&'a str>,
}

impl<'a> Words<'a> {
    /// Error at word `i` (inclusive).
    pub(super) fn err(&self, i: usize, problem: impl Into<String>) -> CommandError {
        let end = (i + 1).min(self.words.len());
        CommandError {
            at: self.words[..end].join(" "),
            problem: problem.into(),
        }
    }

    pub(super) fn get(&self, i: usize) -> Option<&'a str> {
        self.words.get(i).copied()
    }

    /// Word `i`, or an error naming what is missing.
    pub(super) fn need(&self, i: usize, what: &str) -> Result<&'a str, CommandError> {
        self.get(i)
            .ok_or_else(|| self.err(i, format!("missing {what}")))
    }

    pub(super) fn no_more(&self, i: usize) -> Result<(), CommandError> {
        match self.get(i) {
            Some(_) => Err(self.err(i, "unexpected extra argument")),
            None => Ok(()),
        }
    }

    pub(super) fn positive(&self, i: usize, what: &str) -> Result<f64, CommandError> {
        let w = self.need(i, what)?;
        match w.parse::<f64>() {
            Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
            _ => Err(self.err(i, "expected a finite positive number")),
        }
    }

    pub(super) fn non_negative(&self, i: usize, what: &str) -> Result<f64, CommandError> {
        let w = self.need(i, what)?;
        match w.parse::<f64>() {
            Ok(v) if v.is_finite() && v >= 0.0 => Ok(v),
            _ => Err(self.err(i, "expected a finite number ≥ 0")),
        }
    }

    pub(super) fn index(&self, i: usize, what: &str) -> Result<usize, CommandError> {
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
    pub(super) fn targets(
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

    pub(super) fn block(&self, i: usize) -> Result<Block, CommandError> {
        let w = self.need(i, "block")?;
        parse_block(w).ok_or_else(|| {
            self.err(i, "unknown block; expected position, orientation, velocity, angular_velocity, mass or inertia")
        })
    }
}

/// A quantity by name or short name.
pub(super) fn parse_quantity(word: &str) -> Option<StateQuantity> {
    Some(match word.to_ascii_lowercase().as_str() {
        "position" | "pos" | "x" => StateQuantity::Position,
        "orientation" | "rot" | "r" => StateQuantity::Orientation,
        "velocity" | "vel" | "v" => StateQuantity::Velocity,
        "angular_velocity" | "angvel" | "omega" | "w" => StateQuantity::AngularVelocity,
        _ => return None,
    })
}

/// A control block by name or short name.
fn parse_block(word: &str) -> Option<Block> {
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
