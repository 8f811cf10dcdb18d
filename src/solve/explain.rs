//! Why a drag cannot be followed: which constraints, and which of their
//! quantities, stand in its way. Read off the linearised system the update
//! solves (`C δu = r`, docs/design.md §6): a constraint blocks the drag when
//! the system without its rows can meet the drag and the system with them
//! cannot. Every answer is checked by solving the smaller system, so what
//! the editor suggests is what the solver would do.

use super::constraint::{Constraint, Kind};
use super::update::{assemble, kkt};
use crate::scene::StateQuantity;
use crate::sim::Trajectory;
use nalgebra::{DMatrix, DVector};

/// A constraint standing in the way of a drag.
#[derive(Debug, Clone, PartialEq)]
pub struct Blocker {
    /// Index of the constraint among the persistent ones.
    pub constraint: usize,
    /// The quantities whose release alone lets the drag through; empty
    /// when only removing the whole constraint does.
    pub quantities: Vec<StateQuantity>,
}

/// A system that leaves less than this share of its residual unmet meets
/// the drag (the rest is what a second update removes).
const MET: f64 = 0.05;

/// The blockers of the drag `constraints.last()` among the constraints
/// before it, on `traj` (with tangents). Empty when the system meets the
/// drag already, or when no single constraint is to blame (then the free
/// controls, not the constraints, fall short).
pub fn blockers(
    traj: &Trajectory,
    constraints: &[Constraint],
    scales: &DVector<f64>,
    rank_tol: f64,
) -> Vec<Blocker> {
    let Some((drag, persistent)) = constraints.split_last() else {
        return Vec::new();
    };
    if !drag.drag || persistent.is_empty() {
        return Vec::new();
    }
    let Ok((r, Some(c))) = assemble(traj, constraints, true) else {
        return Vec::new();
    };
    let unmet = |keep: &dyn Fn(usize) -> bool| -> f64 {
        let rows: Vec<usize> = (0..r.len()).filter(|&i| keep(i)).collect();
        let c2 = DMatrix::from_fn(rows.len(), c.ncols(), |i, j| c[(rows[i], j)]);
        let r2 = DVector::from_fn(rows.len(), |i, _| r[rows[i]]);
        let d = DVector::zeros(c.ncols());
        let (du, _, _) = kkt(&c2, &r2, scales, &d, rank_tol);
        // What is left of the drag's own rows.
        let start = r.len() - drag.rows();
        (start..r.len())
            .map(|i| ((c.row(i) * &du)[0] - r[i]).powi(2))
            .sum::<f64>()
            .sqrt()
    };
    let all = unmet(&|_| true);
    let wanted = r.rows(r.len() - drag.rows(), drag.rows()).norm();
    if !(all.is_finite() && all > MET * wanted) {
        return Vec::new();
    }
    let mut out = Vec::new();
    let mut at = 0;
    for (k, cons) in persistent.iter().enumerate() {
        let rows = at..at + cons.rows();
        at += cons.rows();
        let meets = |skip: std::ops::Range<usize>| unmet(&|i| !skip.contains(&i)) <= MET * all;
        if let Kind::State { quantities, .. } = &cons.kind
            && quantities.len() > 1
        {
            let single: Vec<StateQuantity> = quantities
                .iter()
                .enumerate()
                .filter(|(q, _)| {
                    let from = rows.start + 3 * q;
                    meets(from..from + 3)
                })
                .map(|(_, q)| *q)
                .collect();
            if !single.is_empty() {
                out.push(Blocker {
                    constraint: k,
                    quantities: single,
                });
                continue;
            }
        }
        if meets(rows) {
            out.push(Blocker {
                constraint: k,
                quantities: Vec::new(),
            });
        }
    }
    out
}
