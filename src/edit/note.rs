//! What an applied edit has to tell the user, as typed values: the solver's
//! diagnostics, the constraints that block a drag and the way past them, a
//! partial step, a clamped time, an accuracy warning. The user interfaces
//! render them (`Display`) at the edge: the status line, the log, a report.

use crate::scene::StateQuantity;
use crate::solve::Diagnostic;

/// One thing an edit reports.
#[derive(Debug, Clone, PartialEq)]
pub enum Note {
    /// From a differential update.
    Solver(Diagnostic),
    /// Constraints that keep the drag from being followed, each with the
    /// change that lets it through (checked on the linearised system).
    BlockedBy(Vec<BlockedBy>),
    /// The update took this fraction of the asked step: going further
    /// changes the collision sequence or raises the residual.
    PartialStep { fraction: f64 },
    /// `:t` beyond the motion: the time was clamped.
    TimeClamped { asked: f64, to: f64 },
    /// The motion's estimated integration error is above its threshold.
    Accuracy(String),
}

/// A constraint in a drag's way.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockedBy {
    /// Its row in the constraints panel.
    pub row: usize,
    /// `nail`, `floating`, ...
    pub kind: &'static str,
    pub body: String,
    /// `t=1.300` or `hit#2 post`.
    pub at: String,
    /// The quantities whose release lets the drag through (each alone);
    /// empty when only removing the constraint does.
    pub quantities: Vec<StateQuantity>,
}

impl std::fmt::Display for Note {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Note::Solver(d) => write!(f, "{d}"),
            Note::BlockedBy(list) => {
                let parts: Vec<String> = list.iter().map(ToString::to_string).collect();
                write!(f, "{}", parts.join("; "))
            }
            Note::PartialStep { fraction } => write!(
                f,
                "moved {}% of the nudge: further on, the collision sequence changes or the constraints stop holding",
                num(100.0 * fraction, 3)
            ),
            Note::TimeClamped { asked, to } => write!(
                f,
                "t={} is past the motion: clamped to its end, t={}",
                num(*asked, 8),
                num(*to, 8)
            ),
            Note::Accuracy(text) => f.write_str(text),
        }
    }
}

impl std::fmt::Display for BlockedBy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let what = format!(
            "{} of {} at {} (row {})",
            self.kind, self.body, self.at, self.row
        );
        match self.quantities.as_slice() {
            [] => write!(
                f,
                "blocked by the {what}: it holds what this drag changes; `:delete {}` lets the drag through",
                self.row
            ),
            qs => {
                let names: Vec<&str> = qs.iter().map(|q| q.name()).collect();
                write!(
                    f,
                    "blocked by the {what}, which holds its {}: `:release {} {}` lets the drag through",
                    names.join(" and "),
                    self.row,
                    names[0]
                )
            }
        }
    }
}

/// A number for a message: at most 4 decimals, trailing zeros dropped;
/// `—` for a non-finite one (which never reaches the screen as NaN).
fn num(v: f64, _width: usize) -> String {
    if !v.is_finite() {
        return "—".into();
    }
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_blocker_names_the_constraint_and_the_way_out() {
        let b = BlockedBy {
            row: 0,
            kind: "nail",
            body: "egg1".into(),
            at: "t=1.300".into(),
            quantities: vec![StateQuantity::Orientation],
        };
        assert_eq!(
            Note::BlockedBy(vec![b]).to_string(),
            "blocked by the nail of egg1 at t=1.300 (row 0), which holds its orientation: `:release 0 orientation` lets the drag through"
        );
        assert!(
            Note::PartialStep { fraction: 0.25 }
                .to_string()
                .starts_with("moved 25% of the nudge")
        );
    }
}
