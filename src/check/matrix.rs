//! The Jacobian as data: the `jacobian` object of `nudge check --jacobian
//! --json` and the CSV of `--csv` (docs/export.md §1).
//!
//! Columns are the free controls in the control vector's order; rows are
//! `body.quantity.component@t` for every body, the four state quantities
//! and each requested time. Orientation rows are derivatives of the
//! exponential-map vector `r` of the orientation (`|r| ≤ π`, what reports
//! and nails write): `δr = J_l(r)⁻¹ δθ` from the simulator's world-frame
//! rotation `δθ`. A body without a Jacobian at a time (a grazing contact
//! took it) has `null` rows and the reason; every number is finite.

use super::{FLOOR, QUANTITIES, Uncompared};
use crate::controls::Controls;
use crate::math::left_jacobian_inv;
use crate::scene::Scene;
use crate::sim::{Side, TangentError, Trajectory};
use crate::tangent::{ColumnKind, FiniteDifference};
use nalgebra::DMatrix;
use serde_json::{Value, json};

const AXES: [&str; 3] = ["x", "y", "z"];

/// A requested time that is not in the motion.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AtError {
    #[error(
        "--at {given}: not a finite time; give a time in s from 0 to {duration}, e.g. --at {duration}"
    )]
    NotFinite { given: f64, duration: f64 },
    #[error(
        "--at {given}: outside the motion; give a time in s from 0 to {duration}, e.g. --at {duration}"
    )]
    OutOfRange { given: f64, duration: f64 },
}

/// How one column (control) compares with central differences at the
/// requested times.
#[derive(Debug, Clone, PartialEq)]
pub enum ColumnCheck {
    /// `|J_c − D_c| / max(|D_c|, 1e-3)` over the column's available rows.
    Compared {
        disagreement: f64,
        /// How many rows were compared: a body without a Jacobian at a
        /// time (a grazing contact) has none to compare.
        rows: usize,
        /// A perturbed run was refused: first-order difference.
        one_sided: bool,
    },
    Uncompared(Uncompared),
}

/// The Jacobian at the requested times.
#[derive(Debug, Clone, PartialEq)]
pub struct JacobianMatrix {
    /// The free controls' names, one per column.
    pub controls: Vec<String>,
    pub times: Vec<f64>,
    /// `body.quantity.component@t`, one per row.
    pub rows: Vec<String>,
    /// Per row: one finite number per column, or why the row has none.
    pub values: Vec<Result<Vec<f64>, String>>,
    /// Per column, when central differences were run.
    pub columns: Vec<ColumnCheck>,
}

/// A row label: `egg1.orientation.z@1.5`.
pub fn row_label(body: &str, quantity: &str, axis: usize, t: f64) -> String {
    format!("{body}.{quantity}.{}@{t}", AXES[axis])
}

/// Check the requested times (the final time when none is given).
///
/// # Errors
/// A time that is not finite or outside `[0, duration]`.
pub fn times(at: &[f64], duration: f64) -> Result<Vec<f64>, AtError> {
    if at.is_empty() {
        return Ok(vec![duration]);
    }
    at.iter()
        .map(|&given| {
            if !given.is_finite() {
                Err(AtError::NotFinite { given, duration })
            } else if !(0.0..=duration).contains(&given) {
                Err(AtError::OutOfRange { given, duration })
            } else {
                Ok(given)
            }
        })
        .collect()
}

/// `body`'s 12 × m Jacobian at `t` with the orientation rows as
/// exponential-map derivatives, or why there is none.
fn exp_map_rows(traj: &Trajectory, body: usize, t: f64) -> Result<DMatrix<f64>, String> {
    let j = traj
        .jacobian(body, t, Side::Post)
        .map_err(|e| e.to_string())?;
    let out = to_exp_map(traj, body, t, j);
    if out.iter().all(|v| v.is_finite()) {
        Ok(out)
    } else {
        Err(TangentError::NonFinite { t }.to_string())
    }
}

/// Replace the tangent rows `δθ` (3..6) of a 12-row block by `J_l(r)⁻¹ δθ`,
/// `r` the body's orientation vector at `t`.
fn to_exp_map(traj: &Trajectory, body: usize, t: f64, mut j: DMatrix<f64>) -> DMatrix<f64> {
    let r = traj.state(body, t, Side::Post).orientation_vector();
    let inv = left_jacobian_inv(&r);
    let rot = inv * j.rows(3, 3);
    j.rows_mut(3, 3).copy_from(&rot);
    j
}

/// The Jacobian of every body at `times`; `fd` (central differences of the
/// same scene) adds the per-column check.
pub fn build(
    scene: &Scene,
    controls: &Controls,
    traj: &Trajectory,
    times: &[f64],
    fd: Option<&FiniteDifference>,
) -> JacobianMatrix {
    let m = controls.m();
    let mut rows = Vec::new();
    let mut values = Vec::new();
    // Per (time, body): the tangent block, for the column check.
    let mut blocks = Vec::new();
    for &t in times {
        for (b, body) in scene.bodies.iter().enumerate() {
            let block = exp_map_rows(traj, b, t);
            for (q, quantity) in QUANTITIES.iter().enumerate() {
                for axis in 0..3 {
                    rows.push(row_label(&body.name, quantity, axis, t));
                    values.push(match &block {
                        Ok(j) => Ok((0..m).map(|c| j[(3 * q + axis, c)]).collect()),
                        Err(why) => Err(why.clone()),
                    });
                }
            }
            blocks.push((t, b, block));
        }
    }
    let columns = fd.map_or_else(Vec::new, |fd| check_columns(traj, fd, times, &blocks));
    JacobianMatrix {
        controls: controls
            .free
            .iter()
            .map(|&i| controls.entries[i].name.clone())
            .collect(),
        times: times.to_vec(),
        rows,
        values,
        columns,
    }
}

type Block = (f64, usize, Result<DMatrix<f64>, String>);

/// Each column against the central differences over the available blocks.
fn check_columns(
    traj: &Trajectory,
    fd: &FiniteDifference,
    times: &[f64],
    blocks: &[Block],
) -> Vec<ColumnCheck> {
    let comparable: Vec<Vec<bool>> = times.iter().map(|&t| fd.comparable_until(t)).collect();
    let differences: Vec<Option<DMatrix<f64>>> = blocks
        .iter()
        .map(|(t, b, block)| {
            block
                .as_ref()
                .ok()
                .map(|_| to_exp_map(traj, *b, *t, fd.at(*b, *t, Side::Post)))
        })
        .collect();
    let grazing = traj
        .tangent_lost
        .iter()
        .flatten()
        .find_map(|(_, e)| match e {
            TangentError::Grazing { event, .. } => Some(*event),
            _ => None,
        });
    (0..fd.columns.len())
        .map(|c| {
            let one_sided = match &fd.columns[c] {
                ColumnKind::Refused(why) => {
                    return ColumnCheck::Uncompared(Uncompared::Refused(why.clone()));
                }
                ColumnKind::OneSided(_) => true,
                ColumnKind::AsScheme => false,
            };
            if comparable.iter().any(|per_column| !per_column[c]) {
                return ColumnCheck::Uncompared(Uncompared::EventsDiffer);
            }
            let (mut diff, mut reference, mut rows) = (0.0, 0.0, 0);
            for ((_, _, block), d) in blocks.iter().zip(&differences) {
                if let (Ok(j), Some(d)) = (block, d) {
                    diff += (j.column(c) - d.column(c)).norm_squared();
                    reference += d.column(c).norm_squared();
                    rows += j.nrows();
                }
            }
            let disagreement = diff.sqrt() / reference.sqrt().max(FLOOR);
            match (rows > 0, disagreement.is_finite()) {
                (true, true) => ColumnCheck::Compared {
                    disagreement,
                    rows,
                    one_sided,
                },
                (true, false) => ColumnCheck::Uncompared(Uncompared::EventsDiffer),
                (false, _) => ColumnCheck::Uncompared(
                    grazing.map_or(Uncompared::EventsDiffer, Uncompared::Grazing),
                ),
            }
        })
        .collect()
}

impl ColumnCheck {
    fn json(&self, control: &str) -> Value {
        match self {
            ColumnCheck::Compared {
                disagreement,
                rows,
                one_sided,
            } => json!({
                "control": control,
                "comparable": true,
                "disagreement": crate::report::num(*disagreement),
                "rows_compared": rows,
                "one_sided": one_sided,
            }),
            ColumnCheck::Uncompared(u) => json!({
                "control": control,
                "comparable": false,
                "disagreement": Value::Null,
                "label": u.label(),
                "reason": u.reason(),
            }),
        }
    }
}

impl JacobianMatrix {
    /// The `jacobian` object of `nudge check --jacobian --json`.
    pub fn json(&self) -> Value {
        let matrix: Vec<Value> = self
            .values
            .iter()
            .map(|row| match row {
                Ok(v) => Value::Array(v.iter().map(|x| crate::report::num(*x)).collect()),
                Err(_) => Value::Null,
            })
            .collect();
        let reasons: serde_json::Map<String, Value> = self
            .rows
            .iter()
            .zip(&self.values)
            .filter_map(|(label, row)| row.as_ref().err().map(|why| (label.clone(), json!(why))))
            .collect();
        let checks: Vec<Value> = self
            .columns
            .iter()
            .zip(&self.controls)
            .map(|(c, name)| c.json(name))
            .collect();
        json!({
            "controls": self.controls,
            "times": self.times.iter().map(|t| crate::report::num(*t)).collect::<Vec<_>>(),
            "rows": self.rows,
            "matrix": matrix,
            "reasons": Value::Object(reasons),
            "columns": checks,
        })
    }

    /// The matrix as CSV: a header `row,<control>,…`, then one line per
    /// row label; a row without a Jacobian has empty cells (read as NaN).
    pub fn csv(&self) -> String {
        let mut out = String::from("row");
        for c in &self.controls {
            out.push(',');
            out.push_str(&csv_field(c));
        }
        out.push('\n');
        for (label, row) in self.rows.iter().zip(&self.values) {
            out.push_str(&csv_field(label));
            match row {
                Ok(v) => {
                    for x in v {
                        // Shortest round-trip form: pandas reads back the same f64.
                        out.push_str(&format!(",{x:?}"));
                    }
                }
                Err(_) => out.push_str(&",".repeat(self.controls.len())),
            }
            out.push('\n');
        }
        out
    }
}

/// A CSV field, quoted when it holds a comma, a quote or a line break
/// (RFC 4180).
fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn times_default_to_the_end_and_refuse_what_is_outside() {
        assert_eq!(times(&[], 2.0), Ok(vec![2.0]));
        assert_eq!(times(&[0.0, 2.0], 2.0), Ok(vec![0.0, 2.0]));
        assert_eq!(
            times(&[2.5], 2.0).map_err(|e| e.to_string()),
            Err("--at 2.5: outside the motion; give a time in s from 0 to 2, e.g. --at 2".into())
        );
        assert!(matches!(
            times(&[f64::NAN], 2.0),
            Err(AtError::NotFinite { .. })
        ));
    }

    #[test]
    fn csv_fields_with_commas_or_quotes_are_quoted() {
        assert_eq!(csv_field("a.position.x@1"), "a.position.x@1");
        assert_eq!(csv_field("a,b"), "\"a,b\"");
        assert_eq!(csv_field("a\"b"), "\"a\"\"b\"");
    }
}
